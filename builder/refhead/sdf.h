// A small signed-distance toolkit for the reference head.
//
// Functions of a point p (metres) returning a signed distance-like value:
// negative inside, positive outside, zero on the surface. Ellipsoids and
// smooth blends are not exact distances but bound them closely enough for
// ray marching (the caller steps by a fraction of the value). Everything is
// inline: the head shape evaluates these millions of times.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace afmb::sdf {

using Vec3 = Eigen::Vector3d;

inline double sphere(const Vec3 &p, const Vec3 &c, double r) { return (p - c).norm() - r; }

// Axis-aligned ellipsoid with centre c and semi-axes r (Quilez's first-order
// bound: exact on the surface, good near it).
inline double ellipsoid(const Vec3 &p, const Vec3 &c, const Vec3 &r) {
  Vec3 q = (p - c).cwiseQuotient(r);
  double k0 = q.norm();
  double k1 = (p - c).cwiseQuotient(r.cwiseProduct(r)).norm();
  if (k1 < 1e-12) return -r.minCoeff();
  return k0 * (k0 - 1.0) / k1;
}

// Segment a-b swept by a radius varying linearly from ra (at a) to rb (at b).
// Exact for ra == rb; for a slow taper a close bound.
inline double capsule(const Vec3 &p, const Vec3 &a, const Vec3 &b, double ra, double rb) {
  Vec3 ab = b - a;
  double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm() - (ra + t * (rb - ra));
}

// Polynomial smooth minimum (union) with blend width k: equals min(a, b)
// when |a - b| >= k and rounds the crease otherwise.
inline double smin(double a, double b, double k) {
  if (k <= 0) return std::min(a, b);
  double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}
inline double smax(double a, double b, double k) { return -smin(-a, -b, k); }
// Smooth subtraction: a with b carved out.
inline double ssub(double a, double b, double k) { return smax(a, -b, k); }

// 0 below e0, 1 above e1, smooth (C1) in between.
inline double smoothstep(double e0, double e1, double x) {
  double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace afmb::sdf
