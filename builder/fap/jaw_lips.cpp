#include "fap/jaw_lips.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/QR>

#include "anatomy/muscles.h"
#include "core/edge_paths.h"

namespace afmb {

JawLipHold jaw_lip_hold(const FaceModel &model) {
  JawLipHold out;
  const SkinModel &skin = model.tissue;
  const FdpPoint *chin = model.fdps.find(FdpId{2, 1}, model.skin);
  if (!chin || chin->part != model.skin || chin->vertex < 0) return out;
  // The outer lower lip line: the least-squares parabola in x through its
  // FDPs (a polyline through them held the lip in a V at 8.2, and the chin
  // creased along it).
  std::vector<Eigen::Vector2d> pts;
  for (int index : {3, 7, 2, 8, 4})
    if (const FdpPoint *p = model.fdps.find(FdpId{8, index}, model.skin)) pts.emplace_back(p->pos.x(), p->pos.y());
  if (pts.size() < 3) return out;
  Eigen::MatrixXd A(static_cast<Eigen::Index>(pts.size()), 3);
  Eigen::VectorXd b(A.rows());
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const double x = pts[static_cast<size_t>(i)].x();
    A.row(i) << 1, x, x * x;
    b(i) = pts[static_cast<size_t>(i)].y();
  }
  const Eigen::Vector3d c = A.colPivHouseholderQr().solve(b);
  double lo = pts[0].x(), hi = lo;
  for (const Eigen::Vector2d &q : pts) lo = std::min(lo, q.x()), hi = std::max(hi, q.x());
  auto line_y = [&](double x) {
    x = std::clamp(x, lo, hi);
    return c(0) + x * (c(1) + x * c(2));
  };
  const FdpPoint *inner = model.fdps.find(FdpId{2, 3}, model.skin), *outer = model.fdps.find(FdpId{8, 2}, model.skin);
  const double margin = inner && outer ? kJawLipMargin * std::abs(inner->pos.y() - outer->pos.y()) : 0.0;
  Expected<MouthLips> lips = mouth_lips(skin, model.fdps);
  if (!lips) return out;
  for (int v : lips->lower)
    if (skin.X0(v, 1) >= line_y(skin.X0(v, 0)) - margin) out.lip.push_back(v);
  if (out.lip.empty()) return out;
  const std::vector<double> d = edge_path_distances(skin.X0, skin.neighbours, out.lip);
  const double band = kJawLipBand * d[static_cast<size_t>(chin->vertex)];
  if (!(band > 0) || !std::isfinite(band)) {
    out.lip.clear();
    return out;
  }
  out.share.resize(skin.n);
  for (int v = 0; v < skin.n; ++v) {
    const double t = std::min(d[static_cast<size_t>(v)] / band, 1.0);
    out.share(v) = t * t * (3 - 2 * t);
  }
  return out;
}

void keep_lip_height(const JawLipHold &hold, Eigen::MatrixXd &D) {
  if (hold.share.size() != D.rows()) return;
  D.col(1).array() *= hold.share.array();
}

}  // namespace afmb
