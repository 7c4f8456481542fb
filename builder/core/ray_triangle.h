// Ray against triangle (Moeller-Trumbore), for the jaw mapping and pictures.
#pragma once

#include <Eigen/Core>

namespace afmb {

// Whether the line o + t d meets triangle (a, b, c), edges included to within
// 1e-9 of the barycentric range, and where: *t (any sign; callers bound it).
// False for a triangle parallel to d or degenerate.
bool ray_triangle(const Eigen::Vector3d &o, const Eigen::Vector3d &d, const Eigen::Vector3d &a,
                  const Eigen::Vector3d &b, const Eigen::Vector3d &c, double *t);

}  // namespace afmb
