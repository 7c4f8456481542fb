#include "anatomy/skin_binding.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace afmb {

Eigen::Vector3d nearest_on_triangle(const Eigen::Vector3d &p, const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                                    const Eigen::Vector3d &c) {
  // Minimise |a + s (b - a) + t (c - a) - p|^2 over the triangle: the
  // interior's stationary point when it lies inside, else the best of the
  // three edges (the minimum of a convex function over a triangle is on its
  // border when not inside).
  const Eigen::Vector3d e0 = b - a, e1 = c - a, d = a - p;
  const double A = e0.dot(e0), B = e0.dot(e1), C = e1.dot(e1), D = e0.dot(d), E = e1.dot(d);
  const double det = A * C - B * B;
  if (det > 1e-12 * A * C) {
    const double s = (B * E - C * D) / det, t = (B * D - A * E) / det;
    if (s >= 0 && t >= 0 && s + t <= 1) return Eigen::Vector3d(1 - s - t, s, t);
  }
  // On segment (u, v): weight on v.
  auto seg = [&p](const Eigen::Vector3d &u, const Eigen::Vector3d &v) {
    const Eigen::Vector3d e = v - u;
    const double len2 = e.squaredNorm();
    return len2 > 0 ? std::clamp((p - u).dot(e) / len2, 0.0, 1.0) : 0.0;
  };
  const Eigen::Vector3d w[3] = {
      [&] { double x = seg(a, b); return Eigen::Vector3d(1 - x, x, 0); }(),
      [&] { double x = seg(b, c); return Eigen::Vector3d(0, 1 - x, x); }(),
      [&] { double x = seg(c, a); return Eigen::Vector3d(x, 0, 1 - x); }()};
  int best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double dist = (w[k][0] * a + w[k][1] * b + w[k][2] * c - p).squaredNorm();
    if (dist < best_d) best_d = dist, best = k;
  }
  return w[best];
}

double nearest_on_face(const Eigen::Vector3d &p, const Eigen::MatrixXd &V, const Eigen::MatrixXi &F, Eigen::Index f,
                       Eigen::Vector3d *weight) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  *weight = nearest_on_triangle(p, a, b, c);
  return ((*weight)[0] * a + (*weight)[1] * b + (*weight)[2] * c - p).squaredNorm();
}

std::vector<SkinBinding> bind_to_skin(const Scene &scene, int skin, PartKind kind) {
  std::vector<SkinBinding> out;
  if (skin < 0 || skin >= static_cast<int>(scene.parts.size())) return out;
  const Part &s = scene.parts[static_cast<size_t>(skin)];
  if (s.F.rows() == 0) return out;
  for (size_t pi = 0; pi < scene.parts.size(); ++pi) {
    const Part &p = scene.parts[pi];
    if (static_cast<int>(pi) == skin || p.kind != kind) continue;
    SkinBinding b;
    b.part = static_cast<int>(pi);
    b.corner.resize(p.V.rows(), 3);
    b.weight.resize(p.V.rows(), 3);
    // Brute force: carried parts are small (lashes: a few hundred vertices).
    for (Eigen::Index v = 0; v < p.V.rows(); ++v) {
      const Eigen::Vector3d x = p.V.row(v).transpose();
      double best = std::numeric_limits<double>::infinity();
      for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
        const Eigen::Vector3d a = s.V.row(s.F(f, 0)), bb = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
        // A triangle whose bounding sphere lies farther than the best so far
        // cannot hold a nearer point.
        const Eigen::Vector3d mid = (a + bb + c) / 3;
        const double r = std::sqrt(std::max({(a - mid).squaredNorm(), (bb - mid).squaredNorm(), (c - mid).squaredNorm()}));
        const double far = (x - mid).norm() - r;
        if (far > 0 && far * far >= best) continue;
        Eigen::Vector3d w;
        const double d = nearest_on_face(x, s.V, s.F, f, &w);
        if (d < best) {
          best = d;
          b.corner.row(v) = s.F.row(f);
          b.weight.row(v) = w.transpose();
        }
      }
    }
    out.push_back(std::move(b));
  }
  return out;
}

Eigen::MatrixXd carried_displacement(const SkinBinding &binding, const Eigen::MatrixXd &D) {
  Eigen::MatrixXd out(binding.corner.rows(), 3);
  for (Eigen::Index v = 0; v < binding.corner.rows(); ++v)
    out.row(v) = binding.weight(v, 0) * D.row(binding.corner(v, 0)) + binding.weight(v, 1) * D.row(binding.corner(v, 1)) +
                 binding.weight(v, 2) * D.row(binding.corner(v, 2));
  return out;
}

}  // namespace afmb
