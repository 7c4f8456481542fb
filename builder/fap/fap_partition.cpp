#include "fap/fap_partition.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>
#include <numeric>

#include "anatomy/face_model.h"
#include "core/edge_paths.h"
#include "core/parallel.h"

namespace afmb {

FapPartition partition_shared_targets(const Eigen::MatrixXd &X, const Eigen::MatrixXi &F,
                                      const std::vector<SharingTarget> &targets) {
  const std::vector<std::vector<int>> adj = vertex_neighbours(F, static_cast<int>(X.rows()));
  const size_t n = targets.size();
  std::vector<size_t> parent(n);
  std::iota(parent.begin(), parent.end(), size_t{0});
  auto root = [&parent](size_t k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  auto usable = [&targets, &X](size_t k) {
    return targets[k].vertex >= 0 && targets[k].vertex < X.rows() && !targets[k].muscles.empty();
  };
  // Linked: the groups share a muscle contracted the same way, or one's
  // target moves the other's FDP, in any direction, by more than
  // kFapOverlap of the other's own motion there along its direction.
  auto overlaps = [&targets](size_t i, size_t j) {
    const SharingTarget &ti = targets[i], &tj = targets[j];
    if (!ti.displacement || !tj.displacement || ti.fap == tj.fap) return false;
    const Eigen::Vector3d along = tj.side * tj.direction;
    const double own = tj.displacement->row(tj.vertex).dot(along.transpose());
    const double cross = ti.displacement->row(tj.vertex).norm();
    return own > 0 && cross > kFapOverlap * own;
  };
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n && usable(a); ++b) {
      if (!usable(b)) continue;
      bool shared = false;
      for (const auto &m : targets[a].muscles)
        shared |= std::find(targets[b].muscles.begin(), targets[b].muscles.end(), m) != targets[b].muscles.end();
      if (shared || overlaps(a, b) || overlaps(b, a)) parent[root(a)] = root(b);
    }
  FapPartition out;
  out.component.assign(n, -1);
  out.weight.assign(n, Eigen::VectorXd());
  std::vector<int> id(n, -1);
  int next = 0;
  for (size_t k = 0; k < n; ++k) {
    const size_t r = root(k);
    if (id[r] < 0) id[r] = next++;
    out.component[k] = id[r];
  }
  for (int c = 0; c < next; ++c) {
    std::vector<size_t> members;
    for (size_t k = 0; k < n; ++k)
      if (out.component[k] == c && usable(k)) members.push_back(k);
    if (members.size() < 2) continue;
    Eigen::Vector3d lo = X.row(targets[members[0]].vertex).transpose(), hi = lo;
    for (size_t k : members) {
      lo = lo.cwiseMin(X.row(targets[k].vertex).transpose());
      hi = hi.cwiseMax(X.row(targets[k].vertex).transpose());
    }
    const double h = 1e-6 * std::max((hi - lo).norm(), 1e-12), h2 = h * h;
    // phi per distinct FDP vertex; at each vertex, the FAPs (each once:
    // both sides of one FAP share its FDP and never play together) counted
    // per direction.
    std::vector<int> vertices;
    for (size_t k : members)
      if (std::find(vertices.begin(), vertices.end(), targets[k].vertex) == vertices.end())
        vertices.push_back(targets[k].vertex);
    Eigen::MatrixXd phi(X.rows(), static_cast<Eigen::Index>(vertices.size()));
    for (size_t u = 0; u < vertices.size(); ++u) {
      // Along the edges: across the mouth the lips are far apart even where they touch.
      Eigen::VectorXd d;
      if (F.rows() > 0) {
        const std::vector<double> e = edge_path_distances(X, adj, {vertices[u]});
        d = Eigen::Map<const Eigen::VectorXd>(e.data(), static_cast<Eigen::Index>(e.size()));
      } else {
        d = (X.rowwise() - X.row(vertices[u])).rowwise().norm();
      }
      phi.col(static_cast<Eigen::Index>(u)) = (d.array().square() + h2).inverse().matrix();
    }
    // A vertex that no FDP's path reaches (not in the mesh, or on another
    // piece of it) takes straight distances.
    for (Eigen::Index v = 0; v < X.rows(); ++v)
      if (!(phi.row(v).sum() > 0))
        for (size_t u = 0; u < vertices.size(); ++u)
          phi(v, static_cast<Eigen::Index>(u)) = 1 / ((X.row(v) - X.row(vertices[u])).squaredNorm() + h2);
    auto count = [&](int vertex, const Eigen::Vector3d &direction) {
      std::vector<int> faps;
      for (size_t k : members)
        if (targets[k].vertex == vertex && targets[k].direction == direction &&
            std::find(faps.begin(), faps.end(), targets[k].fap) == faps.end())
          faps.push_back(targets[k].fap);
      return static_cast<double>(faps.size());
    };
    // Another vertex counts as its largest direction class (63 and 64 at the
    // nose tip are one point for FAP 61; 12 and 59 at the corner two
    // shares); k's own vertex as k's class.
    std::vector<double> largest(vertices.size(), 0);
    for (size_t u = 0; u < vertices.size(); ++u)
      for (size_t k : members)
        if (targets[k].vertex == vertices[u]) largest[u] = std::max(largest[u], count(vertices[u], targets[k].direction));
    for (size_t k : members) {
      Eigen::VectorXd sum = Eigen::VectorXd::Zero(X.rows());
      Eigen::Index own = 0;
      for (size_t u = 0; u < vertices.size(); ++u) {
        const bool mine = vertices[u] == targets[k].vertex;
        if (mine) own = static_cast<Eigen::Index>(u);
        sum += (mine ? count(vertices[u], targets[k].direction) : largest[u]) * phi.col(static_cast<Eigen::Index>(u));
      }
      out.weight[k] = phi.col(own).cwiseQuotient(sum);
    }
  }
  return out;
}

namespace {

// Triangle f's facing under X + w P (fap_partition.h: 1 at rest, below 0
// turned over) and, when `grad`, its derivatives in its corners' weights.
// m: the rest normals over their squares (#F x 3; zero where degenerate).
double facing(const Eigen::MatrixXd &X, const Eigen::MatrixXi &F, const Eigen::MatrixXd &m, const Eigen::VectorXd &w,
              const Eigen::MatrixXd &P, Eigen::Index f, Eigen::Vector3d *grad) {
  const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
  const Eigen::Vector3d Pa = P.row(a).transpose(), Pb = P.row(b).transpose(), Pc = P.row(c).transpose();
  const Eigen::Vector3d pa = X.row(a).transpose() + w(a) * Pa, pb = X.row(b).transpose() + w(b) * Pb,
                        pc = X.row(c).transpose() + w(c) * Pc;
  const Eigen::Vector3d n = m.row(f).transpose();
  if (grad) *grad = Eigen::Vector3d(Pa.cross(pb - pc).dot(n), Pb.cross(pc - pa).dot(n), Pc.cross(pa - pb).dot(n));
  return n.isZero() ? 1 : (pb - pa).cross(pc - pa).dot(n);  // degenerate at rest: nothing to keep
}

}  // namespace

UnfoldedShares unfold_shared_weights(const Eigen::MatrixXd &X, const Eigen::MatrixXi &F,
                                     const std::vector<SharingTarget> &targets, FapPartition &partition,
                                     const std::function<int(size_t, const Eigen::VectorXd &)> &turned,
                                     int threads) {
  const Eigen::Index n = X.rows();
  UnfoldedShares out;
  out.turned_before.assign(targets.size(), 0);
  out.turned_after.assign(targets.size(), 0);
  std::vector<std::vector<int>> faces_of(static_cast<size_t>(n));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int j = 0; j < 3; ++j) faces_of[static_cast<size_t>(F(f, j))].push_back(static_cast<int>(f));
  int components = 0;
  for (int c : partition.component) components = std::max(components, c + 1);
  const Eigen::VectorXd whole = Eigen::VectorXd::Ones(n);
  const RestFaces rest = rest_faces(X, F);
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (const Eigen::Vector3d &n0 = rest.normal[static_cast<size_t>(f)]; n0.squaredNorm() > 0)
      m.row(f) = n0.transpose() / n0.squaredNorm();
  for (int c = 0; c < components; ++c) {
    // The set's FAPs, each with its targets (a FAP's sides share one weight).
    std::vector<int> faps;
    std::vector<std::vector<size_t>> of;
    std::vector<char> fdp(static_cast<size_t>(n), 0);
    for (size_t k = 0; k < targets.size(); ++k) {
      if (partition.component[k] != c || partition.weight[k].size() != n) continue;
      fdp[static_cast<size_t>(targets[k].vertex)] = 1;
      const size_t i = static_cast<size_t>(std::find(faps.begin(), faps.end(), targets[k].fap) - faps.begin());
      if (i == faps.size()) {
        faps.push_back(targets[k].fap);
        of.emplace_back();
      }
      of[i].push_back(k);
    }
    if (faps.size() < 2) continue;
    std::vector<Eigen::VectorXd> w(faps.size());
    for (size_t i = 0; i < faps.size(); ++i) w[i] = partition.weight[of[i][0]];

    // The bounds: each target's triangles that its whole pose keeps facing.
    struct Bound {
      size_t fap;
      const Eigen::MatrixXd *pose;
      int face;
    };
    std::vector<Bound> bounds;
    std::vector<std::vector<int>> bounds_of(static_cast<size_t>(F.rows()));
    std::vector<int> active;  // bounds to visit in the next sweep, ascending
    for (size_t i = 0; i < faps.size(); ++i)
      for (size_t k : of[i]) {
        const Eigen::MatrixXd *P = targets[k].displacement;
        if (!P || P->rows() != n) continue;
        for (Eigen::Index f = 0; f < F.rows(); ++f)
          if (facing(X, F, m, whole, *P, f, nullptr) >= kUnfoldMargin) {
            bounds_of[static_cast<size_t>(f)].push_back(static_cast<int>(bounds.size()));
            if (facing(X, F, m, w[i], *P, f, nullptr) < kUnfoldMargin) active.push_back(static_cast<int>(bounds.size()));
            bounds.push_back({i, P, static_cast<int>(f)});
          }
      }
    // Only where a share turns a triangle its whole pose keeps.
    const bool turns = std::any_of(active.begin(), active.end(), [&](int b) {
      const Bound &r = bounds[static_cast<size_t>(b)];
      return facing(X, F, m, w[r.fap], *r.pose, r.face, nullptr) < 0;
    });
    if (!turns) continue;
    // The triangles a target's share turns before it is untangled (cheap):
    // only targets that turn any, before or after, are judged as stored.
    auto raw_turned = [&](size_t k, const Eigen::VectorXd &wk) {
      const Eigen::MatrixXd *P = targets[k].displacement;
      if (!P || P->rows() != n) return false;
      for (Eigen::Index f = 0; f < F.rows(); ++f)
        if (facing(X, F, m, wk, *P, f, nullptr) < 0) return true;
      return false;
    };
    const std::vector<Eigen::VectorXd> start = w;

    for (int sweep = 0; sweep < kUnfoldSweeps && !active.empty(); ++sweep) {
      std::vector<char> changed(static_cast<size_t>(n), 0);
      for (int b : active) {
        const Bound &r = bounds[static_cast<size_t>(b)];
        Eigen::Vector3d g;
        const double h = facing(X, F, m, w[r.fap], *r.pose, r.face, &g);
        if (h >= kUnfoldMargin) continue;
        for (int j = 0; j < 3; ++j)
          if (fdp[static_cast<size_t>(F(r.face, j))]) g(j) = 0;
        const double gg = g.squaredNorm();
        if (!(gg > 0)) continue;
        const double step = (kUnfoldMargin - h) / gg;
        for (int j = 0; j < 3; ++j) {
          const int v = F(r.face, j);
          if (g(j) == 0) continue;
          double others = 0;
          for (size_t o = 0; o < faps.size(); ++o)
            if (o != r.fap) others += w[o](v);
          if (!(others > 0)) continue;  // nothing to take the difference
          const double d = std::clamp(step * g(j), -w[r.fap](v), others);
          w[r.fap](v) += d;
          const double scale = (others - d) / others;
          for (size_t o = 0; o < faps.size(); ++o)
            if (o != r.fap) w[o](v) *= scale;
          changed[static_cast<size_t>(v)] = 1;
        }
      }
      active.clear();
      for (Eigen::Index v = 0; v < n; ++v)
        if (changed[static_cast<size_t>(v)])
          for (int f : faces_of[static_cast<size_t>(v)])
            active.insert(active.end(), bounds_of[static_cast<size_t>(f)].begin(),
                          bounds_of[static_cast<size_t>(f)].end());
      std::sort(active.begin(), active.end());
      active.erase(std::unique(active.begin(), active.end()), active.end());
    }

    // Each judged before and after, on the workers.
    std::vector<std::pair<size_t, size_t>> judged;  // (fap, target)
    for (size_t i = 0; i < faps.size(); ++i)
      for (size_t k : of[i])
        if (w[i] != start[i] && (raw_turned(k, start[i]) || raw_turned(k, w[i]))) judged.emplace_back(i, k);
    std::vector<int> now(targets.size(), 0);
    for_each_task(2 * judged.size(), threads, [&](size_t task) {
      const auto [i, k] = judged[task / 2];
      if (task % 2 == 0)
        out.turned_before[k] = turned(k, start[i]);
      else
        now[k] = turned(k, w[i]);
    });
    int before = 0, after = 0;
    for (const auto &[i, k] : judged) before += out.turned_before[k], after += now[k];
    if (after >= before) {
      for (size_t i = 0; i < faps.size(); ++i)
        for (size_t k : of[i]) out.turned_after[k] = out.turned_before[k];
      continue;
    }
    std::vector<char> moved(static_cast<size_t>(n), 0);
    for (size_t i = 0; i < faps.size(); ++i) {
      const Eigen::VectorXd &old = partition.weight[of[i][0]];
      for (Eigen::Index v = 0; v < n; ++v)
        if (w[i](v) != old(v)) {
          moved[static_cast<size_t>(v)] = 1;
          out.largest_change = std::max(out.largest_change, std::abs(w[i](v) - old(v)));
        }
      for (size_t k : of[i]) {
        partition.weight[k] = w[i];
        out.turned_after[k] = now[k];
      }
    }
    out.vertices += static_cast<int>(std::count(moved.begin(), moved.end(), 1));
  }
  return out;
}

}  // namespace afmb
