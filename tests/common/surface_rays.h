// Which points lie outside a surface, seen along the face's depth axis: an
// independent check of skin-teeth clearance for the tests (the builder's
// own, fap/teeth_clearance.h, works on a depth map of the teeth instead).
#pragma once

#include <Eigen/Core>

namespace afmtest {

struct OutsideSurface {
  int count = 0;        // points outside
  double deepest = 0;   // the farthest of them in front of the surface, model units
};

// Points P (#P x 3) outside the surface (V #V x 3, F #F x 3, counter-clockwise
// from outside): from each point a ray runs back (-z, into the face), and
// the first triangle it meets faces forward (its normal's z > 0), i.e. the
// ray enters the surface there. A point inside (in the mouth, behind the
// lip) first meets the surface from within, or nothing.
OutsideSurface outside_surface(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F, const Eigen::MatrixXd &P);

}  // namespace afmtest
