#include "anatomy/jaw.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>

#include "anatomy/muscles.h"
#include "core/edge_paths.h"
#include "core/ray_triangle.h"

namespace afmb {

Expected<Jaw> build_jaw(const SkinModel &skin, const FdpSet &fdps, const Fapu &fapu, const MouthLips &lips) {
  const char *need[] = {"2.1", "2.2", "2.3", "2.4", "2.5", "2.8", "2.9", "2.11", "2.12", "2.13", "2.14", "5.3", "5.4"};
  std::string absent;
  for (const char *id : need)
    if (!fdps.find(*FdpId::parse(id))) absent += std::string(absent.empty() ? "" : ", ") + id;
  if (!absent.empty()) return Status::error("jaw needs FDPs " + absent);
  auto P = [&](const char *id) -> Eigen::Vector3d { return fdps.find(*FdpId::parse(id))->pos; };

  Jaw jaw;
  Eigen::Vector3d top_l = P("2.13"), top_r = P("2.14");
  top_l.y() = P("2.4").y();
  top_r.y() = P("2.5").y();
  const Eigen::Vector3d top[7] = {top_l, P("2.4"), P("2.8"), P("2.3"), P("2.9"), P("2.5"), top_r};
  const Eigen::Vector3d bottom[7] = {P("2.13"), P("2.11"), (P("2.11") + P("2.1")) / 2, P("2.1"),
                                     (P("2.1") + P("2.12")) / 2, P("2.12"), P("2.14")};
  jaw.V.resize(14, 3);
  const double s = skin.params.skull_scale;
  for (int j = 0; j < 7; ++j) {
    jaw.V.row(j) = (skin.centre + s * (top[j] - skin.centre)).transpose();
    jaw.V.row(7 + j) = (skin.centre + s * (bottom[j] - skin.centre)).transpose();
  }
  jaw.F.resize(12, 3);
  for (int j = 0; j < 6; ++j) {
    jaw.F.row(2 * j) << j, 7 + j, 7 + j + 1;
    jaw.F.row(2 * j + 1) << j, 7 + j + 1, j + 1;
  }

  for (int v = 0; v < skin.n; ++v) {
    if (!skin.in_mesh[static_cast<size_t>(v)]) continue;
    const Eigen::Vector3d o = skin.X0.row(v);
    const Eigen::Vector3d d = -2.5 * skin.thickness[v] * skin.normal.row(v).transpose();
    for (int f = 0; f < jaw.F.rows(); ++f)
      if (double t; ray_triangle(o, d, jaw.V.row(jaw.F(f, 0)), jaw.V.row(jaw.F(f, 1)), jaw.V.row(jaw.F(f, 2)), &t) &&
                    t >= 0 && t <= 1) {
        jaw.ray_hits.push_back(v);
        break;
      }
  }

  // The breadth-first fix of section 3.2.3.
  const std::vector<int> &upper = lips.upper, &lower = lips.lower;
  std::vector<int> set;
  for (int v : jaw.ray_hits)
    if (!std::binary_search(upper.begin(), upper.end(), v)) set.push_back(v);
  jaw.removed = static_cast<int>(jaw.ray_hits.size() - set.size());
  // The lower lip the rays miss, the chin and its underside. The window
  // reaches below the chin, onto its underside and at times down the neck,
  // which the jaw does not carry. So: the window's vertices at or above 2.1;
  // below it, those joined to them through skin that faces forward more
  // than down (the chin's front: files place 2.1, the chin's lowest point,
  // higher, Song's 9 mm above where its chin turns under), then through
  // skin that faces down (the underside, over the floor of the mouth, which
  // the opening jaw draws down), not on to the neck. Cut at 2.1, the skin
  // below stayed on the skull and Song's opening jaw pushed 2.1 down past
  // it; cut at the chin's front, its edge turned sharp.
  std::vector<char> in_window(static_cast<size_t>(skin.n), 0);
  for (int v : lower) in_window[static_cast<size_t>(v)] = 1;
  auto fronts = [&](int v) { return skin.normal(v, 2) > -skin.normal(v, 1); };
  std::vector<int> lip, queue;
  std::vector<char> taken(static_cast<size_t>(skin.n), 0);
  for (int v : lower)
    if (skin.X0(v, 1) >= P("2.1").y()) taken[static_cast<size_t>(v)] = 1, queue.push_back(v);
  // Within 30 degrees of straight down: an underside, not a throat that
  // slopes down to the neck (the generated heads').
  auto under = [&](int v) { return -skin.normal(v, 1) > std::cos(30.0 * 3.14159265358979323846 / 180.0); };
  for (bool front : {true, false})
    for (size_t k = 0; k < queue.size(); ++k)
      for (int u : skin.neighbours[static_cast<size_t>(queue[k])])
        if (in_window[static_cast<size_t>(u)] && !taken[static_cast<size_t>(u)] && (front ? fronts(u) : under(u)))
          taken[static_cast<size_t>(u)] = 1, queue.push_back(u);
  for (int v : lower)
    if (taken[static_cast<size_t>(v)]) lip.push_back(v);
  std::vector<int> merged;
  std::set_union(set.begin(), set.end(), lip.begin(), lip.end(), std::back_inserter(merged));
  jaw.added = static_cast<int>(merged.size() - set.size());
  jaw.vertices = std::move(merged);
  if (jaw.vertices.empty()) return Status::error("jaw: no skin vertex maps to the jaw");

  // The followers: Dijkstra along the skin's edges from the jaw's vertices,
  // through skin below the jaw line only.
  std::vector<std::pair<double, double>> line;  // the lower row's (x, y), ascending in x
  for (const Eigen::Vector3d &b : bottom) line.emplace_back(b.x(), b.y());
  std::sort(line.begin(), line.end());
  auto line_y = [&](double x) {
    if (x <= line.front().first) return line.front().second;
    if (x >= line.back().first) return line.back().second;
    size_t k = 1;
    while (line[k].first < x) ++k;
    const auto &[x0, y0] = line[k - 1];
    const auto &[x1, y1] = line[k];
    return x1 > x0 ? y0 + (y1 - y0) * (x - x0) / (x1 - x0) : std::min(y0, y1);
  };
  // Skin a follower may be: on the mesh, not the upper lip.
  auto may_follow = [&](int u) {
    return skin.in_mesh[static_cast<size_t>(u)] && !std::binary_search(upper.begin(), upper.end(), u);
  };
  const double band = kJawFollowBand * fapu.mw0;
  const std::vector<double> dist = edge_path_distances(skin.X0, skin.neighbours, jaw.vertices, band, [&](int u) {
    return may_follow(u) && skin.X0(u, 1) < line_y(skin.X0(u, 0));
  });
  std::vector<double> fixed(static_cast<size_t>(skin.n), 0.0);  // the shares the side's field is held to
  for (int v : jaw.vertices) fixed[static_cast<size_t>(v)] = 1;
  for (int v = 0; v < skin.n; ++v) {
    const double d = dist[static_cast<size_t>(v)];
    if (d > 0 && d < band) fixed[static_cast<size_t>(v)] = 0.5 * (1 + std::cos(3.14159265358979323846 * d / band));
  }

  // The skin beside the jaw (jaw.h, "Followers"): above the jaw line and
  // beyond the mouth corners, within kJawSideBand x MW0 of the jaw's
  // vertices along the skin. Its shares are harmonic: each one the mean of
  // its neighbours', weighted by the inverse edge length, held to the
  // shares around it (1 on the jaw's vertices, 0 beyond the band).
  const double mid = (P("2.4").x() + P("2.5").x()) / 2,
               beyond = std::abs(P("2.4").x() - P("2.5").x()) / 2 + kJawSideMargin * fapu.mw0,
               side_band = kJawSideBand * fapu.mw0;
  const std::vector<double> side =
      edge_path_distances(skin.X0, skin.neighbours, jaw.vertices, side_band, [&](int u) {
        return may_follow(u) && skin.X0(u, 1) >= line_y(skin.X0(u, 0)) && std::abs(skin.X0(u, 0) - mid) > beyond;
      });
  std::vector<int> unknown(static_cast<size_t>(skin.n), -1);
  int count = 0;
  for (int v = 0; v < skin.n; ++v)
    if (const double d = side[static_cast<size_t>(v)]; d > 0 && d < side_band)
      unknown[static_cast<size_t>(v)] = count++;
  Eigen::VectorXd harmonic;
  if (count > 0) {
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(count);
    for (int v = 0; v < skin.n; ++v) {
      const int i = unknown[static_cast<size_t>(v)];
      if (i < 0) continue;
      for (int u : skin.neighbours[static_cast<size_t>(v)]) {
        const double w = 1.0 / std::max((skin.X0.row(u) - skin.X0.row(v)).norm(), 1e-12 * fapu.mw0);
        entries.emplace_back(i, i, w);
        if (const int j = unknown[static_cast<size_t>(u)]; j >= 0)
          entries.emplace_back(i, j, -w);
        else
          rhs[i] += w * fixed[static_cast<size_t>(u)];
      }
    }
    Eigen::SparseMatrix<double> L(count, count);
    L.setFromTriplets(entries.begin(), entries.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(L);
    if (ldlt.info() != Eigen::Success) return Status::error("jaw: the shares beside the jaw cannot be solved");
    harmonic = ldlt.solve(rhs);
  }
  for (int v = 0; v < skin.n; ++v) {
    const int i = unknown[static_cast<size_t>(v)];
    const double share = i >= 0 ? std::clamp(harmonic[i], 0.0, 1.0) : fixed[static_cast<size_t>(v)];
    if (share <= 0 || share >= 1) continue;
    jaw.followers.emplace_back(v, share);
    if (i >= 0) ++jaw.beside;
  }

  jaw.pivot = Eigen::Vector3d(0, (P("5.3").y() + P("5.4").y()) / 2, (P("2.13").z() + P("2.14").z()) / 2);
  jaw.axis = Eigen::Vector3d::UnitX();
  jaw.max_open = 20.0 * 3.14159265358979323846 / 180.0;
  jaw.max_thrust = fapu.mw0 / 5;
  jaw.max_shift = fapu.mw0 / 5;
  // The condyles glide forward as the mouth opens, so that the chin drops
  // rather than swinging back into the throat: at 100 % the glide cancels
  // the rotation's backward motion of 2.1.
  const Eigen::Vector3d chin = P("2.1");
  const Eigen::Vector3d turned = jaw.pivot + Eigen::AngleAxisd(jaw.max_open, jaw.axis) * (chin - jaw.pivot);
  jaw.open_glide = std::max(0.0, chin.z() - turned.z());
  return jaw;
}

std::vector<double> jaw_shares(const Jaw &jaw, int n) {
  std::vector<double> out(static_cast<size_t>(n), 0.0);
  for (int v : jaw.vertices) out[static_cast<size_t>(v)] = 1;
  for (const auto &[v, share] : jaw.followers) out[static_cast<size_t>(v)] = share;
  return out;
}

Eigen::Affine3d jaw_share(const Jaw &jaw, const Eigen::Affine3d &motion, double share) {
  // motion = T(t) T(pivot) R T(-pivot): t = motion(pivot) - pivot, and R's
  // angle about the jaw's axis (signed: the axis is fixed).
  const Eigen::AngleAxisd turn(motion.linear());
  const double angle = turn.angle() * (turn.axis().dot(jaw.axis) < 0 ? -1 : 1);
  const Eigen::Vector3d t = motion * jaw.pivot - jaw.pivot;
  Eigen::Affine3d out = Eigen::Affine3d::Identity();
  out.translate(share * t);
  out.translate(jaw.pivot);
  out.rotate(Eigen::AngleAxisd(share * angle, jaw.axis));
  out.translate(-jaw.pivot);
  return out;
}

Eigen::MatrixXd moved_points(const Eigen::Affine3d &motion, const Eigen::MatrixXd &V) {
  return (V * motion.linear().transpose()).rowwise() + motion.translation().transpose();
}

Eigen::Affine3d jaw_motion(const Jaw &jaw, double open_pct, double thrust_pct, double shift_pct) {
  const double angle = std::max(0.0, open_pct) / 100.0 * jaw.max_open;
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  t.translate((thrust_pct / 100.0 * jaw.max_thrust + std::max(0.0, open_pct) / 100.0 * jaw.open_glide) *
                  Eigen::Vector3d::UnitZ() +
              shift_pct / 100.0 * jaw.max_shift * Eigen::Vector3d::UnitX());
  t.translate(jaw.pivot);
  t.rotate(Eigen::AngleAxisd(angle, jaw.axis));
  t.translate(-jaw.pivot);
  return t;
}

}  // namespace afmb
