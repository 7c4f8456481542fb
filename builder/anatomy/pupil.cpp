#include "anatomy/pupil.h"

#include <afm/mpeg4.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

namespace afmb {

namespace {

// Below this luminance a vertex is pupil, above kPale sclera (the generated
// eyes: pupil 0.02, iris 0.08-0.45, limbus 0.11, sclera 0.92).
constexpr double kDark = 0.06, kPale = 0.6;
// The pupil lies within this polar angle of the pole.
constexpr double kCap = 1.0;  // radians

double luminance(const Eigen::RowVector3d &c) { return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z(); }

double polar(const Pupil &p, const Eigen::Vector3d &x) {
  const Eigen::Vector3d u = x - p.centre;
  return std::atan2(u.cross(p.axis).norm(), u.dot(p.axis));
}

// The pupil's edge angle at `value` IRISD units (NaN when it leaves (0, iris)).
double dilated(const Pupil &p, const Fapu &fapu, double value) {
  const double r = p.radius * std::sin(p.pupil) + value * fapu.irisd0 / 2048;
  const double a = r > 0 && r < p.radius * std::sin(p.iris) ? std::asin(r / p.radius) : NAN;
  return a;
}

}  // namespace

Expected<Pupil> find_pupil(const Scene &scene, const FdpSet &fdps, const std::vector<EyeSphere> &eyes, int fap) {
  Pupil p;
  const afm_fap_info *info = afm_fap(fap);
  if (!info || info->motion != AFM_MOTION_DILATE) return Status::error("FAP " + std::to_string(fap) + " is no pupil's");
  const FdpId id{info->fdp_group, info->fdp_index};
  const FdpPoint *f = nullptr;
  const EyeSphere *eye = nullptr;
  for (const EyeSphere &e : eyes)
    if (const FdpPoint *q = fdps.find(id, e.part); q && q->part == e.part && q->vertex >= 0) f = q, eye = &e;
  if (!f) return Status::error(scene.source + ": FDP " + id.str() + " is not on an eyeball");
  const Part &part = scene.parts[static_cast<size_t>(eye->part)];
  p.part = eye->part;
  p.centre = eye->centre;
  p.radius = eye->radius;
  const Eigen::Vector3d out = f->pos - p.centre;
  if (!(out.norm() > 0.5 * p.radius))
    return Status::error(scene.source + ": FDP " + id.str() + " lies inside its eyeball");
  p.axis = out.normalized();
  const std::string what = scene.source + ": the eye part " + part.name;
  if (part.C.rows() != part.V.rows())
    return Status::error(what + " has no pupil geometry: no vertex colours (a texture draws its pupil)");
  if (luminance(part.C.row(f->vertex)) >= kDark)
    return Status::error(what + " has no pupil geometry: its pole, FDP " + id.str() + ", is not dark");
  double pupil = 0, iris = kCap;
  for (Eigen::Index v = 0; v < part.V.rows(); ++v) {
    const double t = polar(p, part.V.row(v).transpose()), l = luminance(part.C.row(v));
    if (t < kCap && l < kDark) pupil = std::max(pupil, t);
    if (l > kPale) iris = std::min(iris, t);
  }
  if (!(pupil > 0 && pupil < iris && iris < kCap))
    return Status::error(what + " has no pupil geometry: no dark disc about FDP " + id.str() +
                         " inside an iris and a pale sclera");
  p.pupil = pupil;
  p.iris = iris;
  return p;
}

bool pupil_value_fits(const Pupil &pupil, const Fapu &fapu, double value) {
  return !std::isnan(dilated(pupil, fapu, value));
}

Eigen::MatrixXd pupil_displacement(const Pupil &p, const Eigen::MatrixXd &V, const Fapu &fapu, double value) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(V.rows(), 3);
  const double edge = dilated(p, fapu, value);
  if (std::isnan(edge)) return D;
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v).transpose(), u = x - p.centre;
    const Eigen::Vector3d k = p.axis.cross(u);
    const double t = polar(p, x);
    if (t >= p.iris || k.norm() <= 1e-12 * u.norm()) continue;  // beyond the iris, or on the axis
    const double to = t <= p.pupil ? t * edge / p.pupil : edge + (t - p.pupil) * (p.iris - edge) / (p.iris - p.pupil);
    D.row(v) = (Eigen::AngleAxisd(to - t, k.normalized()) * u - u).transpose();
  }
  return D;
}

double pupil_diameter(const Pupil &p, const Eigen::MatrixXd &rest, const Eigen::MatrixXd &V) {
  double sum = 0;
  int n = 0;
  for (Eigen::Index v = 0; v < rest.rows(); ++v)
    if (std::abs(polar(p, rest.row(v).transpose()) - p.pupil) < 1e-9) {
      const Eigen::Vector3d u = V.row(v).transpose() - p.centre;
      sum += (u - u.dot(p.axis) * p.axis).norm();
      ++n;
    }
  return n ? 2 * sum / n : 0;
}

}  // namespace afmb
