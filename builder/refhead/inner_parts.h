// The reference head's parts other than the skin: eyeballs, teeth, tongue.
//
// Each is a closed, consistently oriented triangle mesh (counter-clockwise
// seen from outside) with per-vertex colours, in metres in the neutral frame.
// `detail` scales the tessellation (about 16 at the lowest resolution).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace afmb::refhead {

struct PartMesh {
  Eigen::MatrixXd V;  // #V x 3
  Eigen::MatrixXi F;  // #F x 3
  Eigen::MatrixXd C;  // #V x 3 RGB
  int key[4] = {-1, -1, -1, -1};  // part-specific landmark vertices (below)
};

// A sphere of `radius` around `centre` looking along +z, coloured as an eye:
// pupil (radius `pupil`, on the sphere's front), iris (`iris`), limbus and
// sclera. key[0] is the pupil centre (the front pole).
PartMesh make_eyeball(const Eigen::Vector3d &centre, double radius, double iris, double pupil,
                      int detail);

// Dental arch: front surface of the incisors at z = front_z on the midline,
// the incisal edge at y = edge_y; upper teeth rise from it, lower teeth hang
// below it, so the two rows touch. key[0] is the front middle of the edge,
// key[1] the front middle of the far (gum) side.
PartMesh make_teeth(bool upper, double edge_y, double front_z, int detail);

// Tongue resting in the lower arch behind the lower incisors. key[0] tip,
// key[1] middle of the upper surface, key[2] left border (x > 0), key[3]
// right border.
PartMesh make_tongue(double top_y, double tip_z, int detail);

}  // namespace afmb::refhead
