// The reference head's skin mesh: a graded (longitude, height) grid of rays
// cast onto head_sdf(), with a mouth slit and two eye openings.
//
// Rows run around the head bottom to top (the neck's open end first, a
// single vertex on top), so the vertex order is spatially coherent. The
// mouth slit is one row whose vertices between the mouth corners exist
// twice: the upper lip's copy and the lower lip's, at the same place. Each
// eye opening is a slit of the same kind on the pupils' row, opened into an
// almond by moving the rows above and below it apart in the parameter
// domain, the lids tangent to the iris. The rows over the upper lids are at
// most 4.4 mm apart (at coarse resolutions 0.45 of the face's spacing), so
// that a closing lid's triangles stay out of the eyeball. The grid's
// resolution is solved for so the vertex count meets the target within
// about 2 %.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/status.h"

namespace afmb::refhead {

struct SkinMesh {
  Eigen::MatrixXd V;    // #V x 3 metres
  Eigen::MatrixXi F;    // #F x 3, counter-clockwise seen from outside
  Eigen::MatrixXd TC;   // #TC x 2 cylindrical map, seam at the back
  Eigen::MatrixXi FTC;  // #F x 3
  Eigen::MatrixXd C;    // #V x 3 RGB

  // Feature vertices. Contours run from the face's right (x < 0) to its
  // left (x > 0) and include their end corners, which both copies share.
  std::vector<int> mouth_upper;  // upper lip's copy of the slit
  std::vector<int> mouth_lower;  // lower lip's copy
  // [0] the left eye (x > 0), [1] the right eye. Inner corner to outer corner.
  std::array<std::vector<int>, 2> eye_upper, eye_lower;
  std::vector<int> midline;        // x = 0 in front (z > axis), bottom to top
  std::vector<int> neck_boundary;  // the open bottom row
  int top = -1;                    // the single vertex on top of the head
  int subnasale = -1;              // on the midline at HeadDesign::subnasale_y
};

// target_vertices: 1000..100000 (checked by the caller).
Expected<SkinMesh> build_skin(int target_vertices);

}  // namespace afmb::refhead
