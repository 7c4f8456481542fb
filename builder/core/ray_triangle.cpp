#include "core/ray_triangle.h"

#include <Eigen/Geometry>
#include <cmath>

namespace afmb {

bool ray_triangle(const Eigen::Vector3d &o, const Eigen::Vector3d &d, const Eigen::Vector3d &a,
                  const Eigen::Vector3d &b, const Eigen::Vector3d &c, double *t) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return false;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = o - a;
  const double u = s.dot(p) * inv;
  if (u < -1e-9 || u > 1 + 1e-9) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < -1e-9 || u + v > 1 + 1e-9) return false;
  *t = e2.dot(q) * inv;
  return true;
}

}  // namespace afmb
