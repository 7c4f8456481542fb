// The rigid parts every AFM builder shares: the eyeballs (FAPs 23-28) and the
// head (FAPs 48-50), as RigidPart controls (afm_export.h).
#pragma once

#include <vector>

#include "afm/afm_export.h"
#include "core/fdp.h"
#include "core/scene.h"

namespace afmb {

// Eyes: each eye part (PartKind::EyeLeft / EyeRight) turns about its
// vertices' centroid, yaw and pitch by the FAP's axis and sign (AU), thrust
// along z (ES units); a scene without eye parts gets none. Head: every part
// turns about the top of the spine (FDP 7.1), else half ES0 below the skin's
// centroid. `fdps` bound to `scene`; `skin` its skin part.
std::vector<RigidPart> eye_and_head_rigids(const Scene &scene, const FdpSet &fdps, const Fapu &fapu, int skin);

// A rigid motion known at a value of a FAP (the positive side's target or
// one of its in-betweens): `motion` (AU or model units) at `value` (FAP
// units, 0 < value < 2^15).
struct RigidSample {
  int fap = 0;
  afm_dof dof = AFM_DOF_ROTATE_X;
  int value = 0;
  double motion = 0;
};

// The controls (afm_control's knots, formats/afm.md RIGD) that make each
// FAP's and dof's motion piecewise linear through its samples and 0 at 0, as
// the player blends a side's in-between targets: the nearest sample's slope
// at knot 0, then at each farther sample's nearer neighbour the change of
// slope. Past the farthest sample the last segment goes on; negative values
// take the first slope (as a FAP without negative targets takes its first
// target's weight). Controls at knot 0 come first, in the order (FAP, dof)
// first appear in `samples`; then the knots, in the same order and
// outward. Samples with value <= 0 are left out; of two at the same FAP,
// dof and value, the first counts.
std::vector<RigidPart::Control> piecewise_controls(const std::vector<RigidSample> &samples);

}  // namespace afmb
