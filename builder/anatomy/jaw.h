// The lower jaw (method paper section 3.2.3): a jaw mesh estimated from the
// FDPs, the skin vertices it carries, and its motion.
//
// Jaw mesh (our reading of the paper's Figure 6, which is not reproduced): a
// band of 7 x 2 points, from the face's left to its right,
//   upper row  (2.13 at the height of 2.4), 2.4, 2.8, 2.3, 2.9, 2.5, (2.14 at the height of 2.5)
//   lower row  2.13, 2.11, (2.11 + 2.1) / 2, 2.1, (2.1 + 2.12) / 2, 2.12, 2.14
// i.e. the lower lip's inner contour above, the jaw line below, split into 12
// triangles, then pushed onto the skull surface (scaled around the skin's
// centre of gravity like the skull layer).
//
// Mapping (after Kaehler et al.): a segment is traced from every skin vertex
// inward along its normal, 2.5 tissue thicknesses long; the vertices whose
// segment meets the jaw mesh are the jaw's. Then the breadth-first fix: the
// mouth-window search from 2.2 removes upper-lip vertices, the one from 2.3
// adds the lower lip, the chin and its underside: down to 2.1, below it the
// chin's front (skin facing forward more than down: files place 2.1, the
// chin's lowest point, higher), then the underside (facing within 30
// degrees of straight down), not the neck.
//
// Followers: the skin below the jaw line next to the jaw's vertices (the
// underside of the chin and the throat, over the floor of the mouth, whose
// soft tissue spans from the mandible to the hyoid) takes a share of the
// jaw's motion, falling smoothly from 1 at the jaw's vertices to 0 at
// kJawFollowBand x MW0 along the skin: 0.5 (1 + cos(pi d / band)) at
// distance d. Without them the bone under the skin turned with the jaw up to
// its last vertex and stayed put from the next on: an opening jaw folded the
// skin under the chin into spikes along that line (the 2,000-vertex head's
// demo). "Below the jaw line": under the polyline of the jaw mesh's lower
// row through the FDPs, in x and y; never the upper lip.
// Beside the jaw too: above the jaw line, farther from the face's middle
// than the mouth corners by kJawSideMargin x MW0, within kJawSideBand x MW0
// of the jaw's vertices along the skin. There the share is harmonic, each
// vertex's the mean of its neighbours' weighted by the inverse edge length,
// held to 1 on the jaw's vertices, to the followers' below and to 0 beyond
// the band: it falls smoothly around the jaw mesh's upper corners, where a
// distance's cosine leaves steps. Without it the skin carried whole met
// skin tied to the skull across one edge in front of the jaw's corners,
// and the jaw wide open turned slabs of tissue through themselves there
// (the generated 1,000-vertex head: 5 slabs, 4 triangles; the 10k head's
// whole skin: 13 and 6; none now). Nearer the corners a share drew the
// upper lip's corner down with the jaw (Song at open_jaw 1024).
//
// Motion: rotation about the condyles' axis, +x through the pivot
//   pivot = (0, mean of 5.3.y and 5.4.y, mean of 2.13.z and 2.14.z),
// the cheekbones' height and the jaw corners' depth; positive angles open
// the mouth (the chin goes down and back). 100 % opening is 20 degrees, with
// a forward glide of the condyles in proportion (`open_glide` at 100 %: the
// chin's backward motion at 20 degrees, so the chin drops straight down at
// full opening, as MPEG-4's open_jaw says). 100 % thrust is MW0 / 5 forward
// (+z), 100 % shift is MW0 / 5 toward the face's left (+x). The motion is
//   p' = R (p - pivot) + pivot + t,  t = (shift, 0, thrust + glide),
// as the player composes a rigid part's rotation and translation.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "anatomy/muscles.h"
#include "anatomy/skin_model.h"
#include "core/fapu.h"
#include "core/fdp.h"

namespace afmb {

struct Jaw {
  Eigen::MatrixXd V;                // 14 x 3 jaw mesh, on the skull surface
  Eigen::MatrixXi F;                // 12 x 3
  std::vector<int> ray_hits;        // skin vertices whose inward segment meets the mesh, sorted
  std::vector<int> vertices;        // after the breadth-first fix, sorted
  int added = 0, removed = 0;       // by the fix
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  double max_open = 0;              // radians at 100 %
  double max_thrust = 0, max_shift = 0;  // model units at 100 %
  double open_glide = 0;            // forward translation at 100 % opening, model units
  // Vertices below the jaw line and beside the jaw that take a share of
  // its motion (see "Followers" above): (vertex, share), 0 < share < 1,
  // sorted by vertex, none of them in `vertices`.
  std::vector<std::pair<int, double>> followers;
  int beside = 0;                   // of the followers, those beside the jaw (above its line)
  std::vector<int> dynamic;         // V_d of a full opening, sorted (a partial one starts on less: face_model.h)
  // The calibrated pose of a full opening, from the rest carried by the
  // jaw (face_model.h: a first guess for poses that open it).
  NodeDisplacement open_response;
};

// FDPs the jaw needs: 2.1-2.5, 2.8, 2.9, 2.11-2.14, 5.3, 5.4. Fails naming
// the missing ones. `lips` are the mouth-window searches (mouth_lips()).
Expected<Jaw> build_jaw(const SkinModel &skin, const FdpSet &fdps, const Fapu &fapu, const MouthLips &lips);

// The rigid motion for opening, thrust and shift in percent (open >= 0).
Eigen::Affine3d jaw_motion(const Jaw &jaw, double open_pct, double thrust_pct, double shift_pct);

// Per skin vertex (n of them), the share of the jaw's motion it takes: 1 on
// the jaw's vertices, a follower's share, else 0.
std::vector<double> jaw_shares(const Jaw &jaw, int n);

// How far the followers reach along the skin, in mouth widths (MW0):
// below the jaw line, and beside the jaw.
constexpr double kJawFollowBand = 1.0;
constexpr double kJawSideBand = 0.5;
// How much farther from the face's middle than the mouth corners the skin
// beside the jaw starts, in MW0.
constexpr double kJawSideMargin = 0.25;

// The share `share` (0..1) of a jaw motion made by jaw_motion(): the same
// axis and pivot, the angle and the translation times `share`.
Eigen::Affine3d jaw_share(const Jaw &jaw, const Eigen::Affine3d &motion, double share);

// The points V (#V x 3, model units) moved by `motion`: #V x 3.
Eigen::MatrixXd moved_points(const Eigen::Affine3d &motion, const Eigen::MatrixXd &V);

}  // namespace afmb
