#include "surface_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace afmtest {

OutsideSurface outside_surface(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F, const Eigen::MatrixXd &P) {
  OutsideSurface out;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    double nearest = std::numeric_limits<double>::infinity();
    bool front = false;
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      const Eigen::Vector3d a = V.row(F(f, 0)).transpose(), b = V.row(F(f, 1)).transpose(),
                            c = V.row(F(f, 2)).transpose();
      // The ray p - t z, t > 0: where (x, y) falls in the triangle's
      // projection, by 2D edge functions.
      const double w0 = (b.x() - p.x()) * (c.y() - p.y()) - (c.x() - p.x()) * (b.y() - p.y());
      const double w1 = (c.x() - p.x()) * (a.y() - p.y()) - (a.x() - p.x()) * (c.y() - p.y());
      const double w2 = (a.x() - p.x()) * (b.y() - p.y()) - (b.x() - p.x()) * (a.y() - p.y());
      const double area = w0 + w1 + w2;
      if (area == 0 || !((w0 >= 0 && w1 >= 0 && w2 >= 0) || (w0 <= 0 && w1 <= 0 && w2 <= 0))) continue;
      const double z = (w0 * a.z() + w1 * b.z() + w2 * c.z()) / area;
      const double t = p.z() - z;
      if (t <= 0 || t >= nearest) continue;
      nearest = t;
      front = area > 0;  // counter-clockwise seen from +z: the normal's z is positive
    }
    if (front) {
      ++out.count;
      out.deepest = std::max(out.deepest, nearest);
    }
  }
  return out;
}

}  // namespace afmtest
