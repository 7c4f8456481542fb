// Lip-lip contact: the upper and the lower lip kept from passing into each
// other (not in the method paper, whose lips have nothing between them).
//
// Pairs (lip_pairs): each epidermal vertex of one lip (mouth_lips(): the
// mouth-window searches of section 3.2.1) with the nearest vertex of the
// other, where they lie within `band` of each other at rest, one above the
// other rather than side by side (the rest offset's horizontal part at most
// kLipPairSlant times its height, or within the margin), and the upper lip's
// vertex not below the lower's. The vertices that face each other across the
// mouth: on a mesh whose lips were cut apart the seam's coincident pairs, on a
// lip that curls into the mouth the two curls' facing sides.
//
// Per pair, with s = (x_upper - x_lower) . up the height of the upper
// vertex over the lower one (up: +y, the MPEG-4 frame's), contact begins
// at s_on (lip_pairs: 0, where the upper vertex comes down to the lower
// one's height; lips apart at rest close fully, and pressed they overlap by
// a fraction of a margin, hidden where they meet) and
//   E = k margin u^3 / 3,   u = (s_on - s) / margin,   for u > 0 (0 otherwise),
//   force on the upper vertex  k u^2 up (the lower: the opposite),
//   Hessian                    2 k u / margin [up; -up] [up; -up]^T,
// k = modulus x the two vertices' area shares (a contact pressure of
// `modulus` at a crossing of one margin, 4 times it at two). C2 at u = 0
// like the collapse floor, positive semi-definite everywhere, and zero at
// rest: the rest state and its factorisation are unchanged. The pair's
// direction is the face's up, not the rest offset's, so the lips still slide
// over each other front to back and side to side.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace afmb {

struct SkinModel;

// The widest a pair's rest offset may be for its height (see above).
constexpr double kLipPairSlant = 1.0;
// build_face_model's band and margin, in MNS0 (the mouth-nose separation).
constexpr double kLipBand = 0.1;
constexpr double kLipMargin = 0.02;

struct LipPair {
  int upper = -1, lower = -1;  // epidermal nodes (global node indices)
  double on = 0;               // s_on, model units (<= the rest height; lip_pairs: 0)
  double margin = 0;           // model units, > 0
  double stiffness = 0;        // k, force units
};

// The energy of a pair at height s over its lower vertex, and its first two
// derivatives in s (d1 <= 0 <= d2).
struct LipContactValue {
  double e = 0, d1 = 0, d2 = 0;
};
LipContactValue lip_contact_energy(const LipPair &p, double s);

// The pairs of `upper` and `lower` (skin vertex sets, sorted; a vertex both
// hold is never paired with itself) on the rest state of `m`, with contact
// modulus `modulus` (> 0), `band` and `margin` in model units (> 0). A vertex
// in several pairs shares its area among them. Ordered by upper vertex, then
// lower.
std::vector<LipPair> lip_pairs(const SkinModel &m, const std::vector<int> &upper, const std::vector<int> &lower,
                               double modulus, double band, double margin);

// How many of m.lip_pairs have their upper vertex more than `depth` model
// units below s_on in X (4n x 3): lips passing into each other.
int crossed_lip_pairs(const SkinModel &m, const Eigen::MatrixXd &X, double depth);

}  // namespace afmb
