#include "anatomy/fdp_completion.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "anatomy/muscle_table.h"
#include "refhead/refhead.h"

namespace afmb {

namespace {
// The local fit's reach on the reference head (metres), and the weight every
// shared FDP keeps however far (the global fit underneath). Leave-one-out on
// Song's 39 skin FDPs: mean error 4.6 (global fit) -> 3.5 model units.
constexpr double kSigma = 0.03;
constexpr double kFloor = 0.02;
}  // namespace

std::vector<FdpId> anatomy_fdps() {
  std::vector<FdpId> out;
  auto add = [&](const FdpId &id) {
    if (std::find(out.begin(), out.end(), id) == out.end()) out.push_back(id);
  };
  for (const MuscleDef &d : muscle_table())
    for (const char *text : {d.attachment_or_major, d.insertion_or_minor, d.epicentre, d.corner_outer, d.corner_inner}) {
      if (!text) continue;
      Expected<Keypoint> k = parse_keypoint(text);
      if (k)
        for (const auto &t : k->terms) add(t.first);
    }
  for (const char *id : {"2.1", "2.2", "2.3", "2.4", "2.5", "2.8", "2.9", "2.11", "2.12", "2.13", "2.14",
                         "5.3", "5.4", "9.15"})
    add(*FdpId::parse(id));
  std::sort(out.begin(), out.end());
  return out;
}

Expected<std::vector<FdpId>> complete_fdps(const Scene &scene, int skin, FdpSet &fdps,
                                           const std::vector<FdpId> &wanted,
                                           std::vector<std::string> *notes) {
  std::vector<FdpId> missing;
  for (const FdpId &id : wanted)
    if (!fdps.find(id)) missing.push_back(id);
  if (missing.empty()) return missing;
  if (skin < 0 || skin >= static_cast<int>(scene.parts.size()))
    return Status::error("FDP estimates: no skin part");

  RefHeadOptions ro;
  ro.skin_vertices = 1000;
  Expected<RefHead> ref = make_reference_head(ro);
  if (!ref) return ref.status();
  // Shared FDPs, first point of each; 7.1 and 11.5 are not surface points.
  std::vector<Eigen::Vector3d> from, to;
  for (const FdpPoint &p : ref->fdps.points) {
    if ((p.id.group == 7) || (p.id.group == 11 && p.id.index == 5)) continue;
    const FdpPoint *q = fdps.find(p.id);
    if (!q || (q->part >= 0 && q->vertex < 0)) continue;
    if (ref->fdps.find(p.id) != &p) continue;  // first point only
    from.push_back(p.pos);
    to.push_back(q->pos);
  }
  if (from.size() < 8)
    return Status::error("FDP estimates need at least 8 FDPs shared with the reference head, the file has " +
                         std::to_string(from.size()));
  const Eigen::Index nf = static_cast<Eigen::Index>(from.size());
  Eigen::MatrixXd A(nf, 4), B(nf, 3);
  for (Eigen::Index i = 0; i < nf; ++i) {
    A.row(i) << from[static_cast<size_t>(i)].transpose(), 1.0;
    B.row(i) = to[static_cast<size_t>(i)].transpose();
  }
  // The affine map near `at` (a reference-head point): each shared FDP
  // weighted by a Gaussian of its distance from there, plus a small constant
  // that keeps the fit determined where few FDPs are near.
  auto fit = [&](const Eigen::Vector3d &at, double *rms) {
    Eigen::VectorXd w(nf);
    for (Eigen::Index i = 0; i < nf; ++i) {
      const double d = (from[static_cast<size_t>(i)] - at).norm() / kSigma;
      w[i] = std::sqrt(std::exp(-d * d) + kFloor);
    }
    const Eigen::MatrixXd M = (w.asDiagonal() * A).colPivHouseholderQr().solve(w.asDiagonal() * B);  // 4 x 3
    *rms = std::sqrt((w.asDiagonal() * (A * M - B)).squaredNorm() / w.squaredNorm());
    return M;
  };

  const Part &part = scene.parts[static_cast<size_t>(skin)];
  std::vector<uint8_t> used(static_cast<size_t>(part.V.rows()), 0);
  for (int f = 0; f < part.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) used[static_cast<size_t>(part.F(f, k))] = 1;
  for (const FdpId &id : missing) {
    const FdpPoint *r = ref->fdps.find(id);
    if (!r) return Status::error("FDP estimates: the reference head lacks FDP " + id.str());
    Eigen::RowVector4d h;
    h << r->pos.transpose(), 1.0;
    double rms = 0;
    const Eigen::Vector3d est = (h * fit(r->pos, &rms)).transpose();
    int best = -1;
    double bd = 0;
    for (int v = 0; v < part.V.rows(); ++v) {
      if (!used[static_cast<size_t>(v)]) continue;
      const double d = (part.V.row(v).transpose() - est).squaredNorm();
      if (best < 0 || d < bd) best = v, bd = d;
    }
    if (best < 0) return Status::error("FDP estimates: the skin has no triangles");
    FdpPoint p;
    p.id = id;
    p.part_name = part.name;
    p.part = skin;
    p.vertex = best;
    p.pos = part.V.row(best).transpose();
    fdps.points.push_back(p);
    if (notes) {
      char line[256];
      std::snprintf(line, sizeof line,
                    "FDP %s absent: estimated from the reference head (local affine fit to %zu FDPs, rms %.3g): "
                    "skin vertex %d",
                    id.str().c_str(), from.size(), rms, best);
      notes->push_back(line);
    }
  }
  return missing;
}

}  // namespace afmb
