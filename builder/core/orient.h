// The MPEG-4 neutral frame: +y up, gaze +z, the face's own left at +x.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// A signed axis permutation mapping input coordinates to the MPEG-4 frame.
// Spec text: three signed input axes giving the new x, y and z, e.g. "x,y,z"
// (identity), "-x,y,-z" (turn 180 degrees about y), "x,z,-y" (z-up input).
struct Orientation {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // new = R * old
  std::string spec() const;                         // "x,z,-y"
};
Expected<Orientation> parse_orientation(std::string_view spec);

// Checks the bound FDPs against the neutral frame: the eyes above the mouth
// and the mouth above the chin (+y up), the nose tip in front of the eyes
// (+z forward), the left eye at larger x than the right (+x left). The error
// names the failed check and the --orient value that fixes it, when one does.
Status check_orientation(const FdpSet &bound);

// The signed permutation that best satisfies those checks.
Expected<Orientation> detect_orientation(const FdpSet &bound);

// Rotates every part and FDP position in place.
void apply_orientation(const Orientation &o, Scene &scene, FdpSet &fdps);

}  // namespace afmb
