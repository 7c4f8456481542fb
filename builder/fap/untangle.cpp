#include "fap/untangle.h"

#include <Eigen/Dense>
#include <algorithm>
#include <numeric>

#include "anatomy/face_model.h"

namespace afmb {

Untangled untangle(const Eigen::MatrixXd &V0, const Eigen::MatrixXi &F, const std::vector<char> &hold,
                   const SimMesh *sim, Eigen::MatrixXd &D) {
  const bool lifted = sim && sim->decimated;
  std::vector<int> coarse, fine;  // the triangles to untangle of the last count
  const RestFaces rest = rest_faces(V0, F);
  // The slivers that count as turned when nearly edge-on (untangle.h).
  std::vector<int> slivers;
  const double mean = rest.total / std::max<double>(1, static_cast<double>(F.rows()));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (rest.length(f) > 1e-3 * mean && rest.length(f) < kNearTurnArea * mean) slivers.push_back(static_cast<int>(f));
  int turned = 0;  // of the last count: those really turned, the nearly turned left out
  auto count = [&](const Eigen::MatrixXd &E) {
    const Eigen::MatrixXd V = V0 + E;
    coarse = turned_faces(rest, F, V);
    fine = lifted ? lifted_turned_faces(*sim, E) : std::vector<int>();
    turned = static_cast<int>(coarse.size() + fine.size());
    for (int f : slivers) {
      const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
      const Eigen::Vector3d n = (b - a).cross(c - a);
      const double along = rest.normal[static_cast<size_t>(f)].dot(n);
      if (along > 0 && along < kNearTurnCos * rest.length(f) * n.norm()) coarse.push_back(f);
    }
    return static_cast<int>(coarse.size() + fine.size());
  };
  // Rounds compare by the triangles really turned, then by all counted.
  int best_total = count(D);
  Untangled out;
  out.turned_before = out.turned_after = turned;
  out.near_before = best_total - turned;
  if (best_total == 0) return out;
  auto better = [&](int total) {
    if (turned > out.turned_after || (turned == out.turned_after && total >= best_total)) return false;
    out.turned_after = turned, best_total = total;
    return true;
  };

  // Patches: a union-find over the vertices; `rigid` and `pinned` per root.
  const size_t n = static_cast<size_t>(V0.rows());
  std::vector<int> root(n);
  std::iota(root.begin(), root.end(), 0);
  // pinned: the patch holds a held or fixed vertex; fixed_in: a fixed one.
  std::vector<char> member(n, 0), rigid(n, 0), pinned(n, 0), fixed_in(n, 0);
  // How far a held patch may move (kHeldPatchShare of the mean rest edge).
  double mean_edge = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) mean_edge += (V0.row(F(f, (k + 1) % 3)) - V0.row(F(f, k))).norm();
  const double held_reach = kHeldPatchShare * mean_edge / std::max<double>(1, 3.0 * static_cast<double>(F.rows()));
  auto find = [&root](int v) {
    while (root[static_cast<size_t>(v)] != v)
      v = root[static_cast<size_t>(v)] = root[static_cast<size_t>(root[static_cast<size_t>(v)])];
    return v;
  };
  auto join = [&](int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return;
    const size_t r = static_cast<size_t>(std::min(a, b)), o = static_cast<size_t>(std::max(a, b));
    root[o] = static_cast<int>(r);
    rigid[r] = rigid[r] || rigid[o];
    pinned[r] = pinned[r] || pinned[o];
    fixed_in[r] = fixed_in[r] || fixed_in[o];
  };
  // The coarse vertices a turned triangle stands for: its corners, or for a
  // lifted one the coarse vertices its corners are bound to.
  auto corners_of = [&](bool is_fine, int f, std::vector<int> &c) {
    c.clear();
    if (!is_fine) {
      for (int k = 0; k < 3; ++k) c.push_back(F(f, k));
      return;
    }
    for (int k = 0; k < 3; ++k) {
      const int v = sim->skin_F(f, k);
      for (int j = 0; j < 3; ++j)
        if (sim->binding.weight(v, j) > 0) c.push_back(sim->binding.corner(v, j));
    }
  };

  const Eigen::MatrixXd original = D;
  Eigen::MatrixXd best = D;
  std::vector<int> c;
  for (int round = 0; round < kUntangleMaxRounds && best_total > 0; ++round) {
    // A triangle that turns inside a patch (all it stands for in one) makes
    // that patch move as one piece; then every turned triangle joins one.
    for (bool is_fine : {false, true})
      for (int f : is_fine ? fine : coarse) {
        corners_of(is_fine, f, c);
        bool inside = true;
        for (int v : c) inside = inside && member[static_cast<size_t>(v)] && find(v) == find(c[0]);
        if (inside) rigid[static_cast<size_t>(find(c[0]))] = 1;
      }
    for (bool is_fine : {false, true})
      for (int f : is_fine ? fine : coarse) {
        corners_of(is_fine, f, c);
        for (int v : c) {
          member[static_cast<size_t>(v)] = 1;
          if (!hold.empty() && hold[static_cast<size_t>(v)] != kUntangleFree) pinned[static_cast<size_t>(find(v))] = 1;
          if (!hold.empty() && hold[static_cast<size_t>(v)] == kUntangleFixed) fixed_in[static_cast<size_t>(find(v))] = 1;
          join(c[0], v);
        }
      }
    std::vector<std::vector<int>> patches(n);
    for (size_t v = 0; v < n; ++v)
      if (member[v]) patches[static_cast<size_t>(find(static_cast<int>(v)))].push_back(static_cast<int>(v));
    D = original;
    for (size_t r = 0; r < n; ++r) {
      const std::vector<int> &p = patches[r];
      if (p.empty() || fixed_in[r]) continue;  // a patch holding a fixed vertex stays as solved
      // The affine motion nearest the solved one (least squares, the
      // minimum-norm one where the patch is flat), or one translation, the
      // mean, for a patch that turned inside.
      const Eigen::Index m = static_cast<Eigen::Index>(p.size());
      Eigen::MatrixXd X(m, 4), Y(m, 3);
      Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
      for (int v : p) centre += V0.row(v);
      centre /= static_cast<double>(m);
      for (Eigen::Index i = 0; i < m; ++i) {
        X.row(i) << V0.row(p[static_cast<size_t>(i)]) - centre, 1.0;
        Y.row(i) = original.row(p[static_cast<size_t>(i)]);
      }
      Eigen::MatrixXd W = Eigen::MatrixXd::Zero(4, 3);
      if (rigid[r] || m < 4) W.row(3) = Y.colwise().mean();
      else W = X.completeOrthogonalDecomposition().solve(Y);
      const Eigen::MatrixXd fit = X * W;
      // A held patch (skin held off an eyeball) moves only a little.
      if (pinned[r] && (fit - Y).rowwise().norm().maxCoeff() > held_reach) continue;
      for (Eigen::Index i = 0; i < m; ++i) D.row(p[static_cast<size_t>(i)]) = fit.row(i);
    }
    if (better(count(D))) best = D;
  }
  D = std::move(best);
  // The slivers still turned: an apex to its foot's motion (untangle.h),
  // kept where fewer triangles turn, until no apex helps.
  bool any = best_total > 0;
  while (any) {
    any = false;
    count(D);
    const std::vector<int> faces = coarse;
    for (int f : faces) {
      int e = 0;  // the longest rest edge, e -> e + 1
      double longest = -1;
      for (int k = 0; k < 3; ++k)
        if (const double l = (V0.row(F(f, (k + 1) % 3)) - V0.row(F(f, k))).squaredNorm(); l > longest)
          longest = l, e = k;
      const int a = F(f, e), b = F(f, (e + 1) % 3), apex = F(f, (e + 2) % 3);
      if (!hold.empty() && hold[static_cast<size_t>(apex)] == kUntangleFixed) continue;
      const Eigen::RowVector3d ab = V0.row(b) - V0.row(a);
      const double t = std::clamp((V0.row(apex) - V0.row(a)).dot(ab) / longest, 0.0, 1.0);
      const Eigen::RowVector3d foot = (1 - t) * D.row(a) + t * D.row(b);
      if ((foot - D.row(apex)).squaredNorm() > kSliverShare * kSliverShare * longest) continue;
      const Eigen::RowVector3d was = D.row(apex);
      D.row(apex) = foot;
      if (better(count(D)))
        any = true;
      else
        D.row(apex) = was;
    }
  }
  for (Eigen::Index v = 0; v < D.rows(); ++v) {
    out.moved += D.row(v) != original.row(v);
    out.largest_change = std::max(out.largest_change, (D.row(v) - original.row(v)).norm());
  }
  return out;
}

}  // namespace afmb
