// Parts the skin carries. Lashes and lid or brow strips (PartKind::Eyelid)
// are not simulated; they ride on the skin around the eyes, as the lower
// teeth ride on the jaw.
//
// Each vertex of such a part is bound at rest to the nearest point of the
// skin surface: a skin triangle and barycentric weights. A skin displacement
// moves it by the same blend of that triangle's corner displacements, so the
// part keeps its place on the skin as lids close and brows rise (its small
// offset from the skin is carried along, not turned).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/scene.h"

namespace afmb {

struct SkinBinding {
  int part = -1;            // the carried part (scene part index)
  Eigen::MatrixXi corner;   // #V x 3 skin vertex indices (the triangle's corners)
  Eigen::MatrixXd weight;   // #V x 3 barycentric weights, each row >= 0 summing to 1
};

// The nearest point of triangle (a, b, c) to p, as barycentric weights
// (each >= 0, summing to 1). A degenerate triangle gives the nearest point
// of its longest edge.
Eigen::Vector3d nearest_on_triangle(const Eigen::Vector3d &p, const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                                    const Eigen::Vector3d &c);

// The nearest point to p of triangle f of (V, F): its squared distance,
// and the barycentric weights in *weight.
double nearest_on_face(const Eigen::Vector3d &p, const Eigen::MatrixXd &V, const Eigen::MatrixXi &F, Eigen::Index f,
                       Eigen::Vector3d *weight);

// Bindings of every part of `kind` in the scene to part `skin` (its
// triangles; nothing when it has none). In part order.
std::vector<SkinBinding> bind_to_skin(const Scene &scene, int skin, PartKind kind);

// The displacement of a bound part (#V x 3) for a skin displacement D
// (#skin V x 3), model units.
Eigen::MatrixXd carried_displacement(const SkinBinding &binding, const Eigen::MatrixXd &D);

}  // namespace afmb
