#include "refhead/inner_parts.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace afmb::refhead {

namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

// Surface of revolution-like mesh: a front pole, rings at the polar angles
// `alphas` (0 < a < pi, ascending), a back pole; `at(alpha, beta)` places
// a point. Counter-clockwise seen from outside when `at` is a deformed
// sphere around +z.
PartMesh lathe(int segments, const std::vector<double> &alphas,
               const std::function<Vec3(double, double)> &at,
               const std::function<Vec3(double, double)> &colour) {
  const int rings = (int)alphas.size();
  const int nv = 2 + rings * segments;
  PartMesh m;
  m.V.resize(nv, 3);
  m.C.resize(nv, 3);
  m.V.row(0) = at(0.0, 0.0).transpose();
  m.C.row(0) = colour(0.0, 0.0).transpose();
  for (int j = 0; j < rings; ++j) {
    for (int k = 0; k < segments; ++k) {
      const double beta = 2 * kPi * k / segments;
      m.V.row(1 + j * segments + k) = at(alphas[j], beta).transpose();
      m.C.row(1 + j * segments + k) = colour(alphas[j], beta).transpose();
    }
  }
  m.V.row(nv - 1) = at(kPi, 0.0).transpose();
  m.C.row(nv - 1) = colour(kPi, 0.0).transpose();
  std::vector<Eigen::Vector3i> f;
  auto ring = [&](int j, int k) { return 1 + j * segments + (k % segments); };
  for (int k = 0; k < segments; ++k) f.emplace_back(0, ring(0, k), ring(0, k + 1));
  for (int j = 0; j + 1 < rings; ++j) {
    for (int k = 0; k < segments; ++k) {
      f.emplace_back(ring(j, k), ring(j + 1, k), ring(j + 1, k + 1));
      f.emplace_back(ring(j, k), ring(j + 1, k + 1), ring(j, k + 1));
    }
  }
  for (int k = 0; k < segments; ++k) f.emplace_back(ring(rings - 1, k + 1), ring(rings - 1, k), nv - 1);
  m.F.resize((int)f.size(), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row((int)i) = f[i].transpose();
  return m;
}

// Flips every triangle if the mesh encloses negative volume, so the result
// faces outward whatever order the builder used.
void orient_outward(PartMesh &m) {
  double vol = 0;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Vec3 a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    vol += a.dot(b.cross(c));
  }
  if (vol < 0)
    for (int f = 0; f < m.F.rows(); ++f) std::swap(m.F(f, 1), m.F(f, 2));
}

}  // namespace

PartMesh make_eyeball(const Vec3 &centre, double radius, double iris, double pupil, int detail) {
  const int segments = std::max(16, detail / 4 * 4);
  const double a_p = std::asin(pupil / radius), a_i = std::asin(iris / radius);
  // Rings doubled at the colour edges so pupil, iris and limbus stay crisp.
  std::vector<double> alphas{0.5 * a_p, a_p, a_p * 1.06, 0.5 * (a_p + a_i), 0.93 * a_i, a_i,
                             a_i * 1.05};
  const int back = std::max(6, detail / 2);
  for (int j = 1; j < back; ++j) alphas.push_back(a_i * 1.05 + (kPi - a_i * 1.05) * j / back);
  const Vec3 pupil_c(0.02, 0.02, 0.025), iris_in(0.42, 0.29, 0.16), iris_out(0.24, 0.15, 0.08),
      limbus(0.16, 0.11, 0.08), sclera(0.94, 0.92, 0.88);
  auto at = [&](double a, double b) -> Vec3 {
    return Vec3(centre + radius * Vec3(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b),
                                       std::cos(a)));
  };
  auto colour = [&](double a, double b) -> Vec3 {
    if (a <= a_p * 1.001) return pupil_c;
    if (a <= 0.94 * a_i) {
      // Radial streaks so the iris reads as one.
      const double streak = 0.08 * std::cos(b * 18.0);
      const double t = (a - a_p) / (0.94 * a_i - a_p);
      return (iris_in + t * (iris_out - iris_in)) * (1.0 + streak);
    }
    if (a <= a_i * 1.001) return limbus;
    return sclera;
  };
  PartMesh m = lathe(segments, alphas, at, colour);
  m.key[0] = 0;
  return m;
}

PartMesh make_teeth(bool upper, double edge_y, double front_z, int detail) {
  // Arch centreline: x = A sin(psi), z = zc + B cos(psi), psi in +-psi_max.
  const double A = 0.0245, B = 0.0400, psi_max = 1.72;
  const double zc = front_z - 0.0035 - B;  // the labial face is 3.5 mm in front of the centreline
  const int half = std::max(12, detail);
  const int along = 2 * half + 1;  // odd: one sample on the midline
  // Cross-section (radial offset r, height h above the edge), going around.
  struct Pt {
    double r, h;
    bool gum;
  };
  std::vector<double> psi(along), arc(along, 0.0);
  for (int i = 0; i < along; ++i) psi[i] = psi_max * (i - half) / half;
  auto centre = [&](double p) { return Vec3(A * std::sin(p), 0.0, zc + B * std::cos(p)); };
  for (int i = half + 1; i < along; ++i) arc[i] = arc[i - 1] + (centre(psi[i]) - centre(psi[i - 1])).norm();
  for (int i = half - 1; i >= 0; --i) arc[i] = arc[i + 1] + (centre(psi[i]) - centre(psi[i + 1])).norm();
  // Tooth boundaries by arc length from the midline: incisors, canine,
  // premolars, molars.
  // (The midline boundary gets a shade line but no notch, so the incisal
  // edges meet there, where FDPs 9.10 and 9.11 sit.)
  const double bounds[] = {0.0085, 0.0152, 0.0228, 0.0298, 0.0366, 0.0466, 0.0566};
  auto gap = [&](double s) {
    double g = 0;
    for (double bd : bounds) g = std::max(g, std::exp(-std::pow((s - bd) / 0.0009, 2)));
    return g;
  };
  auto line = [&](double s) {
    return std::max(gap(s), std::exp(-std::pow(s / 0.0007, 2)));
  };

  const int sec = 10;
  const int nv = along * sec + 2;
  PartMesh m;
  m.V.resize(nv, 3);
  m.C.resize(nv, 3);
  const Vec3 enamel(0.93, 0.91, 0.84), shade(0.70, 0.66, 0.58), gum(0.80, 0.42, 0.44);
  int front_edge = -1, front_root = -1;
  for (int i = 0; i < along; ++i) {
    const double p = psi[i];
    const double t = std::abs(p) / psi_max;                 // 0 front, 1 back
    const double th = 0.0062 + 0.0035 * t;                  // crown thickness
    const double H = (upper ? 0.0108 : 0.0098) - 0.0028 * t; // crown + gum height
    const double edge = 0.28 + 0.5 * t;                     // edge thickness fraction
    const double notch = 0.0009 * gap(arc[i]);
    const std::vector<Pt> cs{{0.5 * th * edge, notch, false}, {0.5 * th, 0.35 * H, false},
                             {0.5 * th, 0.72 * H, false},     {0.5 * th * 1.05, H - 0.0028, true},
                             {0.5 * th * 0.95, H, true},      {0.0, H + 0.0006, true},
                             {-0.5 * th * 0.95, H, true},     {-0.5 * th * 1.05, H - 0.0028, true},
                             {-0.5 * th, 0.5 * H, false},     {-0.5 * th * edge, notch, false}};
    const Vec3 c = centre(p);
    const Vec3 n = Vec3(std::sin(p) * B, 0.0, std::cos(p) * A).normalized();  // outward
    for (int j = 0; j < sec; ++j) {
      const double h = upper ? cs[j].h : -cs[j].h;
      const Vec3 pos = c + cs[j].r * n + Vec3(0.0, edge_y + h, 0.0);
      m.V.row(i * sec + j) = pos.transpose();
      Vec3 col = cs[j].gum ? gum : enamel + 0.6 * line(arc[i]) * (shade - enamel);
      m.C.row(i * sec + j) = col.transpose();
    }
    if (i == half) {
      front_edge = i * sec + 0;
      front_root = i * sec + 4;
    }
  }
  // End caps: the centroid of each end section.
  for (int e = 0; e < 2; ++e) {
    const int i = e == 0 ? 0 : along - 1;
    Vec3 c = Vec3::Zero();
    for (int j = 0; j < sec; ++j) c += m.V.row(i * sec + j).transpose();
    m.V.row(along * sec + e) = (c / sec).transpose();
    m.C.row(along * sec + e) = gum.transpose();
  }
  std::vector<Eigen::Vector3i> f;
  for (int i = 0; i + 1 < along; ++i) {
    for (int j = 0; j < sec; ++j) {
      const int a = i * sec + j, b = i * sec + (j + 1) % sec;
      const int c = (i + 1) * sec + j, d = (i + 1) * sec + (j + 1) % sec;
      f.emplace_back(a, c, d);
      f.emplace_back(a, d, b);
    }
  }
  for (int j = 0; j < sec; ++j) {
    f.emplace_back(along * sec, j, (j + 1) % sec);
    f.emplace_back(along * sec + 1, (along - 1) * sec + (j + 1) % sec, (along - 1) * sec + j);
  }
  m.F.resize((int)f.size(), 3);
  for (size_t i = 0; i < f.size(); ++i) m.F.row((int)i) = f[i].transpose();
  orient_outward(m);
  m.key[0] = front_edge;
  m.key[1] = front_root;
  return m;
}

PartMesh make_tongue(double top_y, double tip_z, int detail) {
  const Vec3 radii(0.0185, 0.0072, 0.030);
  const Vec3 c(0.0, top_y - radii.y(), tip_z - radii.z());
  const int segments = std::max(16, detail / 4 * 4);  // multiple of 4: a column on top and each side
  const int rings = std::max(8, detail / 2) | 1;       // odd: a ring at mid-length
  std::vector<double> alphas;
  for (int j = 1; j <= rings; ++j) alphas.push_back(kPi * j / (rings + 1));
  auto at = [&](double a, double b) -> Vec3 {
    // Sphere around +z (the tip), flattened; a shallow groove along the top.
    Vec3 u(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a));
    Vec3 p = c + u.cwiseProduct(radii);
    if (u.y() > 0) p.y() -= 0.0012 * std::exp(-std::pow(u.x() / 0.25, 2)) * std::sin(a);
    return p;
  };
  auto colour = [&](double a, double b) -> Vec3 {
    const double s = std::sin(a) * std::sin(b);  // -1 underside .. 1 top
    return Vec3(0.80, 0.42, 0.45) + (s < 0 ? -0.12 * s : 0.0) * Vec3(-0.1, 0.05, 0.05);
  };
  PartMesh m = lathe(segments, alphas, at, colour);
  const int mid = rings / 2;
  auto ring = [&](int j, int k) { return 1 + j * segments + k; };
  m.key[0] = 0;
  m.key[1] = ring(mid, segments / 4);      // beta = 90 degrees: top
  m.key[2] = ring(mid, 0);                 // beta = 0: +x
  m.key[3] = ring(mid, segments / 2);      // beta = 180 degrees: -x
  return m;
}

}  // namespace afmb::refhead
