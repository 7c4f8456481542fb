// The tongue (issue 5: FAPs 43-47, when the face has a tongue part). The
// method paper does not model it, and it is not part of the mass-spring skin:
// the tongue is a muscular hydrostat (Kier and Smith, 1985), a body of muscle
// that keeps its volume and moves by changing its shape. Here its motions are
// kinematic, one smooth displacement field per FAP, each exact at its FDP:
//
// Frame. The MPEG-4 axes (x toward the face's left, y up, z forward), the
// tongue's rearmost point (least z over the part: the root, which stays put),
// the tip 6.1, the top of its body 6.2 and its left and right borders 6.3 and
// 6.4. A vertex's place along the tongue is s = (z - z_root) / L in [0, 1]
// (clamped), L = z(6.1) - z_root.
//
// - 43 shift_tongue_tip (right, MW) and 44 raise_tongue_tip (up, MNS): the
//   tongue bends as a beam clamped at the root with a load at its tip
//   (Euler-Bernoulli): every vertex moves along the FAP's direction by
//   A c(s), c(s) = s^2 (3 - s) / 2, so 6.1 (c = 1) moves by A = value x FAPU.
// - 45 thrust_tongue_tip (forward, MW): the tongue stretches evenly from its
//   root, z by A s (strain e = A / L), and keeps its volume: its section
//   shrinks by 1 / sqrt(1 + e) about the line through 6.1 along z, so 6.1
//   moves by A straight forward. A negative value shortens and thickens it;
//   that side is not the positive one mirrored, so it has a target of its own
//   (tongue_negative_target).
// - 46 raise_tongue (up, MNS): the body rises in a bump b(s) that is 1 at
//   6.2's place s_b, sin^2(pi s / (2 s_b)) behind it and cos^2(pi (s - s_b) /
//   (2 (1 - s_b))) ahead of it: root and tip stay, as for a /k/.
// - 47 tongue_roll (concave upward, AU): each half of the tongue turns about
//   the hinge line (x of 6.1, the mean height of 6.3 and 6.4, along z) so
//   that its border goes up, by value x 1e-5 rad at the border and in
//   proportion to the distance from the midline inside it (the middle stays
//   flat and the section curls into a trough). The roll fades in from the
//   root to the borders' place (smoothstep), so 6.3 and 6.4 turn by exactly
//   the FAP's angle.
//
// No contact: the tongue passes through teeth and palate if a stream sends
// it there. The jaw carries the tongue as a rigid part (the AFM's RIGD
// chunk): these targets are in the neutral frame, under the jaw's motion.
#pragma once

#include <Eigen/Core>

#include "core/fapu.h"
#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct Tongue {
  int part = -1;                                   // the scene's tongue part
  Eigen::Vector3d tip, body, left, right;          // FDPs 6.1, 6.2, 6.3, 6.4, model units
  double root_z = 0, length = 0;                   // model units; length > 0
  double body_s = 0, border_s = 0;                 // s of 6.2 and of the borders, in (0, 1)
  double hinge_y = 0;                              // the roll's hinge height
  double half_left = 0, half_right = 0;            // |x| of 6.3 and 6.4 from 6.1's x, > 0
};

// The scene's tongue (PartKind::Tongue) and its FDPs 6.1-6.4 (bound to
// `scene`). Errors name what is missing or wrong: no tongue part; an FDP not
// given, or not on the tongue; 6.1 not ahead of the tongue's rearmost point;
// 6.2 not between root and tip; 6.3 and 6.4 not on either side of 6.1.
Expected<Tongue> find_tongue(const Scene &scene, const FdpSet &fdps);

// True for the FAPs this model makes: 43-47.
bool is_tongue_fap(int fap);

// Whether FAP `fap`'s negative side needs a target of its own (the player
// extrapolates the positive one, which is exact for a motion odd in the
// value): 45 only, whose thinning is not.
bool tongue_negative_target(int fap);

// The displacement of the tongue part's vertices (`V`: #V x 3, rest, model
// units) at `value` units of FAP `fap` (43-47; 0 elsewhere): #V x 3, model
// units. FAP 47 takes AU (1e-5 rad), the others their table's FAPU.
Eigen::MatrixXd tongue_displacement(const Tongue &tongue, const Eigen::MatrixXd &V, const Fapu &fapu, int fap,
                                    double value);

// Where FAP `fap` moves its FDP (6.1, 6.2; 6.3 for 47) at `value`, model
// units, by the rule above: the prescribed motion the report compares with.
Eigen::Vector3d tongue_fdp_motion(const Tongue &tongue, const Fapu &fapu, int fap, double value);

}  // namespace afmb
