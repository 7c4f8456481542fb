// The skin kept in front of the lower teeth as the jaw opens under a held
// lip.
//
// FAP 3's targets keep the lower lip's height (jaw_lips.h), and the lower
// teeth turn down with the bone. Where the hold fades, the skin over the lip
// and chin follows the bone only in part, and nothing in the model stopped
// the teeth there: on the generated heads the crowns came out through the
// skin under the lip at 640 and 1024 (by up to 0.38 MNS0 on the
// 1,000-vertex head), where a real lip is stretched over them. So each
// FAP 3 target's skin is pushed forward (+z, the face's gaze; the lip keeps
// its height) until it clears the moved teeth.
//
// The teeth's front is a depth map: the largest z of the lower teeth's
// forward-facing triangles (unit normal's z > kFacing: a flank seen from
// the front faces the cheek, not the skin in front) over a grid in (x, y),
// cell kTeethCell x MW0, draped
//
//     E(q) = max over p of  Z(p) - |q - p|^2 / (2 rho),   rho = kTeethDrape x MNS0,
//
// (a parabolic dilation, separable in x and y, reaching 2 rho) so that the
// skin bends over the crowns' edges rather than stepping off them. A vertex
// v of the fine skin, z_v its depth, is kept in front when at rest the jaw
// carries it (share >= 1/2, jaw.h: the lower lip, the chin), it faces
// forward (unit normal's z > kFacing), and it lies in front of the rest
// teeth's draped front E0: not inside the mouth, not off the teeth's reach.
// Its clearance is what it has at rest, capped (a thin lip does not thicken
// as it stretches):
//
//     c(v) = min(z_v - E0(x_v, y_v), kTeethClearance x MNS0).
//
// A target's skin then must satisfy z'_v >= E(x'_v, y'_v) + c(v), E the
// moved teeth's draped front, primes the target's positions. At rest every
// kept vertex does. The least z that does it: on a simulation mesh
// (sim_mesh.h), where the fine vertices move as blends of coarse ones, by
// cyclic projection of the coarse vertices' z onto each unmet constraint
// (the smallest change per constraint), until the lifted skin meets all of
// them within a thousandth of the cap. Then each pushed vertex u takes the
// skin around it along, by push(u) w(d / (kTeethSpread push(u))), w(t) =
// (1 - t^2)^2 (t < 1), d along the model mesh's edges, the largest such per
// vertex (only more push, so every constraint stays met): alone, the pushed
// vertices stood out of their neighbours, and once untangling (untangle.h)
// had flattened the triangles they turned, two tooth vertices of the
// 2,000-vertex head's target at 1024 were 0.045 MNS0 out again.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "anatomy/face_model.h"
#include "anatomy/sim_mesh.h"
#include "core/scene.h"

namespace afmb {

// The depth map's cell, in mouth widths (MW0).
constexpr double kTeethCell = 1.0 / 160;
// The drape's radius of curvature, in mouth-nose separations (MNS0).
constexpr double kTeethDrape = 0.5;
// The largest clearance the skin keeps over the teeth, in MNS0.
constexpr double kTeethClearance = 0.1;
// The least z of a unit normal facing forward (cos 60 degrees): the teeth's
// triangles in the depth map, the skin's vertices kept in front.
constexpr double kFacing = 0.5;
// How far along the skin a push takes the skin with it, in multiples of
// the push.
constexpr double kTeethSpread = 4;

// A depth map over a grid of cells: the largest z per cell centre, -infinity
// where nothing covers it.
struct DepthMap {
  double x0 = 0, y0 = 0;  // the centre of cell (0, 0), model units
  double cell = 1;        // model units, > 0
  int nx = 0, ny = 0;
  std::vector<double> z;  // nx x ny, x fastest
  // Bilinear between the four nearest cell centres where all of them are
  // covered, else the largest covered one; -infinity off the map or where
  // none is covered.
  double at(double x, double y) const;
};

// The front (largest z) of the triangles F (#F x 3, counter-clockwise from
// outside) of V (#V x 3) facing forward (kFacing) over a grid of `cell`
// covering the vertices' (x, y) extent widened by `margin`.
DepthMap front_depth(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F, double cell, double margin);

// `map` draped with radius of curvature `rho` (> 0): E above. Reaches
// 2 rho beyond the covered cells (the map must have that margin).
void drape(DepthMap &map, double rho);

struct TeethClearance {
  Eigen::MatrixXd teeth_V;     // #T x 3 the lower teeth's rest vertices (every TeethLower part's)
  Eigen::MatrixXi teeth_F;     // #Tf x 3 into teeth_V
  DepthMap rest;               // their draped front at rest, E0
  std::vector<int> vertices;   // fine skin vertices kept in front, sorted
  Eigen::VectorXd clearance;   // per entry of `vertices`, c(v), model units
  Eigen::MatrixXd skin_V;      // #V x 3 the fine skin at rest
  const SimMesh *sim = nullptr;  // the lift from coarse to fine; null: the fine skin is the model's
  const SkinModel *skin = nullptr;  // the model's (coarse) skin, over which the push spreads
  double rho = 0, cap = 0;     // kTeethDrape and kTeethClearance x MNS0, model units
};

// Empty (no vertices) when the scene has no lower teeth. `scene` is the one
// `model` is built on; `sim` its simulation mesh, if any. The result points
// into `model` and `sim`, which must outlive it.
TeethClearance teeth_clearance(const Scene &scene, const FaceModel &model, const SimMesh *sim);

struct TeethPush {
  int pushed = 0;          // fine vertices that had to move
  double deepest = 0;      // the largest shortfall before, model units
  double left = 0;         // the largest shortfall left (0 without a lift, or within a thousandth of the cap)
  Eigen::VectorXd push;    // #n: the z added to each coarse (model) vertex
};

// D: #n x 3 displacement of the model's skin (coarse when `c.sim` is
// decimated) at the jaw's rigid motion `jaw` (jaw_motion()); its z column
// raised so the lifted skin clears the moved teeth.
TeethPush keep_before_teeth(const TeethClearance &c, const Eigen::Affine3d &jaw, Eigen::MatrixXd &D);

}  // namespace afmb
