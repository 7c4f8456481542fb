#include "fap/fap_partition.h"

#include <algorithm>
#include <limits>
#include <numeric>

#include "core/edge_paths.h"

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

}  // namespace afmb
