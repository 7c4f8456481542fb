// The MPEG-4 neutral frame: +y up, gaze +z, the face's own left at +x.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// A signed axis permutation mapping input coordinates to the MPEG-4 frame.
// Spec text: three signed input axes giving the new x, y and z, e.g. "x,y,z"
// (identity), "-x,y,-z" (turn 180 degrees about y), "x,z,-y" (z-up input).
// Spaces around the axes, '+' signs and upper case are accepted. Mirrors
// (determinant -1, e.g. "-x,y,z") parse too: they are for inputs that really
// are mirrored, and are never chosen by detect_orientation().
struct Orientation {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // new = R * old
  std::string spec() const;                         // "x,z,-y"
};
// Errors quote the spec and say what is wrong: not three axes, an unknown
// axis, an axis used twice.
Expected<Orientation> parse_orientation(std::string_view spec);

// Checks the bound FDPs against the neutral frame. Landmarks, each the mean
// of the first group of FDPs present (an FDP on several parts counts once,
// its first usable point; vertex points must be bound):
//   eyes   3.5 3.6, else 3.1-3.4, else 3.7-3.14, else brows 4.1-4.6
//   mouth  2.2 2.3 8.1 8.2, else the other lip points 2.4-2.9, 8.3-8.8
//   chin   2.1, else 2.10, else 2.11 2.12
//   nose   9.3, else 9.12, else 9.15
//   sides  the first (left, right) pair present: 3.5/3.6, 3.1/3.2, 3.3/3.4,
//          eye corners, 4.1/4.2 ..., 5.x, 8.3/8.4, 2.4/2.5, nostrils, jaw
// and the checks, in this order:
//   upright           chin (else mouth) to eyes (else mouth) is mostly +y
//   eyes above mouth  and mouth above chin (+y)
//   sides             the face's left minus its right is mostly +x
//   nose              the nose tip is in front of the eyes (+z)
// ("mostly": the largest component). Two of the three directions (up,
// sides, forward) must be measurable; otherwise the error lists what is
// missing. A failure names the failed check with the vectors measured and
// the --orient value detect_orientation() finds, or why there is none.
Status check_orientation(const FdpSet &bound);

// After check_orientation: the pairs of FDPs that MPEG-4's neutral face
// puts in an order, one above the other (the chin boss 2.10 above the
// bottom of the chin 2.1, the upper lip's points above the lower's, the
// upper lids above the lower, the brows above the lids) or one on the face's
// left of the other (each left point of its right twin, the brows' and the
// lips' points from the outer corner in), that the bound set has the other
// way round by more than a hundredth of the FDPs' extent along that axis.
// One line per such pair, naming both FDPs with their MPEG-4 descriptions
// and how far (model units): "FDP 2.10 (Chin boss) lies 2.37 below 2.1
// (Bottom of the chin); MPEG-4 puts it above: the file may have them
// swapped or misplaced". Empty when every pair present is in order. Each
// FDP's first usable point counts (as above). A note, not an error: the
// mesh is built as the file says, but a FAP moves its misplaced FDP's skin
// (on Song, FAP 18 raises 2.10 and carries 2.1 up with it, against the
// jaw's FAP 3).
//
// The lips' midpoints 2.6, 2.8, 8.5 and 8.7 are on the face's left, where
// the FAP table names them (FAPs 8, 10, 55 and 57 move the left middle of
// their lip contour) and where Candide-3 and Song place them, although the
// FDP list's wording ("midpoint between 2.2 and 2.5", the right corner) has
// them on the right.
std::vector<std::string> fdp_order_notes(const FdpSet &bound);

// The signed permutation that passes every check, preferring proper
// rotations (the best score when several pass). When only a mirror passes,
// this fails naming it: a mirror swaps the face's left and right, which is
// the wrong fix when the FDPs' left/right labels are swapped and the right
// one only for a mirrored mesh, which the user must confirm by passing it to
// --orient. Also fails when no permutation passes (a head tilted by more
// than about 45 degrees, misplaced FDPs).
Expected<Orientation> detect_orientation(const FdpSet &bound);

// Rotates every part and FDP position in place (new = R * old). A mirror
// also swaps two corners of every triangle (F and FTC) so the triangles stay
// counter-clockwise seen from outside.
void apply_orientation(const Orientation &o, Scene &scene, FdpSet &fdps);

}  // namespace afmb
