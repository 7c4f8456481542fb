#include "anatomy/tongue.h"

#include <afm/mpeg4.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace afmb {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAngleUnit = 1e-5;  // AU, radians

double place(const Tongue &t, const Eigen::Vector3d &p) {
  return std::clamp((p.z() - t.root_z) / t.length, 0.0, 1.0);
}

// The tip-loaded cantilever's deflection, 0 at the clamped root (with zero
// slope) and 1 at the tip.
double cantilever(double s) { return s * s * (3 - s) / 2; }

// 1 at s_b, 0 with zero slope at 0 and 1.
double bump(double s, double s_b) {
  const double a = s <= s_b ? std::sin(kPi / 2 * s / s_b) : std::cos(kPi / 2 * (s - s_b) / (1 - s_b));
  return a * a;
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

// The roll of point p by `angle` (radians at the borders).
Eigen::Vector3d rolled(const Tongue &t, const Eigen::Vector3d &p, double angle) {
  const double a = p.x() - t.tip.x(), b = p.y() - t.hinge_y;  // across (toward the face's left) and up
  const double half = a >= 0 ? t.half_left : t.half_right;
  const double phi = (a >= 0 ? 1.0 : -1.0) * angle * std::min(1.0, std::abs(a) / half) *
                     smoothstep(place(t, p) / t.border_s);
  // Turning +x toward +y lifts the left half; the right half turns the other way.
  const double c = std::cos(phi), s = std::sin(phi);
  return {t.tip.x() + a * c - b * s, t.hinge_y + a * s + b * c, p.z()};
}

// FAP `fap`'s distance per unit value: its FAPU / 1024 (radians for 47).
double unit_of(const Fapu &fapu, int fap) {
  const afm_fap_info *info = afm_fap(fap);
  return info->unit == AFM_FAPU_AU ? kAngleUnit : fapu_distance(fapu, info->unit) / 1024.0;
}

}  // namespace

Expected<Tongue> find_tongue(const Scene &scene, const FdpSet &fdps) {
  Tongue t;
  t.part = scene.find_kind(PartKind::Tongue);
  if (t.part < 0) return Status::error(scene.source + ": no tongue part");
  const Part &part = scene.parts[static_cast<size_t>(t.part)];
  if (part.V.rows() == 0) return Status::error(scene.source + ": the tongue part " + part.name + " has no vertices");
  Eigen::Vector3d *key[4] = {&t.tip, &t.body, &t.left, &t.right};
  for (int i = 0; i < 4; ++i) {
    const FdpId id{6, i + 1};
    const FdpPoint *p = fdps.find(id, t.part);
    if (!p || p->part != t.part || p->vertex < 0)
      return Status::error(scene.source + ": FDP " + id.str() + " is not on the tongue part " + part.name);
    *key[i] = p->pos;
  }
  t.root_z = part.V.col(2).minCoeff();
  t.length = t.tip.z() - t.root_z;
  if (!(t.length > 1e-9 * (1 + std::abs(t.root_z))))
    return Status::error(scene.source + ": FDP 6.1, the tongue's tip, is not ahead of its rearmost point");
  t.body_s = place(t, t.body);
  if (!(t.body_s > 0.05 && t.body_s < 0.95))
    return Status::error(scene.source + ": FDP 6.2 is not between the tongue's root and its tip (at " +
                         std::to_string(t.body_s) + " of the way)");
  t.border_s = std::min(place(t, t.left), place(t, t.right));  // both borders turn in full
  if (!(t.border_s > 0.05))
    return Status::error(scene.source + ": FDPs 6.3 and 6.4 lie at the tongue's root");
  t.hinge_y = 0.5 * (t.left.y() + t.right.y());
  t.half_left = t.left.x() - t.tip.x();
  t.half_right = t.tip.x() - t.right.x();
  if (!(t.half_left > 0 && t.half_right > 0))
    return Status::error(scene.source + ": FDPs 6.3 and 6.4, the tongue's left and right borders, are not on " +
                         "either side of 6.1");
  return t;
}

bool is_tongue_fap(int fap) { return fap >= 43 && fap <= 47; }

bool tongue_negative_target(int fap) { return fap == 45; }

Eigen::MatrixXd tongue_displacement(const Tongue &t, const Eigen::MatrixXd &V, const Fapu &fapu, int fap,
                                    double value) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(V.rows(), 3);
  if (!is_tongue_fap(fap)) return D;
  const double amount = value * unit_of(fapu, fap);
  const Eigen::Vector3d dir = fap_direction(afm_fap(fap));
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d p = V.row(v).transpose();
    const double s = place(t, p);
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    switch (fap) {
      case 43:
      case 44: d = amount * cantilever(s) * dir; break;
      case 45: {
        const double strain = amount / t.length, shrink = 1 / std::sqrt(1 + strain);
        const Eigen::Vector3d across(p.x() - t.tip.x(), p.y() - t.tip.y(), 0);
        d = amount * s * Eigen::Vector3d::UnitZ() + (shrink - 1) * across;
        break;
      }
      case 46: d = amount * bump(s, t.body_s) * dir; break;
      case 47: d = rolled(t, p, amount) - p; break;
    }
    D.row(v) = d.transpose();
  }
  return D;
}

Eigen::Vector3d tongue_fdp_motion(const Tongue &t, const Fapu &fapu, int fap, double value) {
  const double amount = value * unit_of(fapu, fap);
  if (fap == 47) return rolled(t, t.left, amount) - t.left;
  if (is_tongue_fap(fap)) return amount * fap_direction(afm_fap(fap));
  return Eigen::Vector3d::Zero();
}

}  // namespace afmb
