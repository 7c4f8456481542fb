// Pupil dilation (issue 5: FAPs 29 and 30, when pupil geometry exists). Not
// in the paper. An eye part has pupil geometry when it draws its pupil with
// its vertices: per-vertex colours, a dark disc about the eye's front pole
// (the pupil's FDP, 3.5 left or 3.6 right, on the eye part) bounded by a ring
// of vertices, inside an iris, inside the pale sclera. The generated heads'
// eyes are made so (rings doubled at each colour edge); an eye that paints
// its pupil with a texture (Song's) has none: a morph target moves vertices,
// not texture coordinates.
//
// The motion: the iris is a ring of muscle about the pupil, fixed at its outer
// edge. On the eyeball's sphere (centre c, radius R; axis a from c to the
// pole), a vertex at polar angle t from a turns about the axis' perpendicular
// through c, staying on the sphere, to
//   t' = t p' / p                                  inside the pupil (t <= p),
//   t' = p' + (t - p) (i - p') / (i - p)            across the iris (p < t < i),
// and stays beyond the iris' edge i (the smallest polar angle of a sclera
// vertex). p is the pupil's edge (the largest polar angle of a dark vertex)
// and p' = asin((R sin p + value x IRISD / 2048) / R): MPEG-4's "growing" by
// value x IRISD taken as the pupil's diameter, so its radius grows by half of
// it. The FDP (the pole) stays. A negative value constricts; the player
// extrapolates the positive target, which is nearly odd in the value.
#pragma once

#include <Eigen/Core>

#include "anatomy/skin_model.h"
#include "core/fapu.h"
#include "core/fdp.h"
#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct Pupil {
  int part = -1;                                   // the eye part
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the eyeball's, model units
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // unit, centre to the pole (the FDP)
  double radius = 0;                               // the eyeball's, model units
  double pupil = 0, iris = 0;                      // polar angles of their edges, radians, 0 < pupil < iris
};

// The pupil FAP `fap` (29: the left eye, 30: the right) dilates: its FDP
// (3.5 or 3.6) on an eye part in `eyes` (the fitted eyeballs, skin_model.h),
// and that part's pupil geometry. Errors say what is missing: the FDP, the
// eyeball, per-vertex colours, a dark disc about the FDP, a pale sclera
// beyond it.
Expected<Pupil> find_pupil(const Scene &scene, const FdpSet &fdps, const std::vector<EyeSphere> &eyes, int fap);

// The pupil part's vertices' displacement (`V`: #V x 3, rest) at `value`
// IRISD units: #V x 3, model units. `value` must keep the pupil's radius
// between 0 and the iris': pupil_value_fits.
Eigen::MatrixXd pupil_displacement(const Pupil &pupil, const Eigen::MatrixXd &V, const Fapu &fapu, double value);
bool pupil_value_fits(const Pupil &pupil, const Fapu &fapu, double value);

// The pupil's diameter (chord across its edge ring) in `V` (#V x 3), model
// units: twice the mean distance from the axis of the vertices on the edge.
double pupil_diameter(const Pupil &pupil, const Eigen::MatrixXd &rest, const Eigen::MatrixXd &V);

}  // namespace afmb
