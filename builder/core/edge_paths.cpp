#include "core/edge_paths.h"

#include <algorithm>
#include <queue>
#include <utility>

namespace afmb {

std::vector<std::vector<int>> vertex_neighbours(const Eigen::MatrixXi &F, int n) {
  std::vector<std::vector<int>> adj(static_cast<size_t>(n));
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      adj[static_cast<size_t>(a)].push_back(b);
      adj[static_cast<size_t>(b)].push_back(a);
    }
  for (std::vector<int> &a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  return adj;
}

std::vector<double> edge_path_distances(const Eigen::MatrixXd &X, const std::vector<std::vector<int>> &neighbours,
                                        const std::vector<int> &sources, double limit,
                                        const std::function<bool(int)> &enter) {
  std::vector<double> d(neighbours.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  for (int s : sources) d[static_cast<size_t>(s)] = 0, q.push({0.0, s});
  while (!q.empty()) {
    const auto [dv, v] = q.top();
    q.pop();
    if (dv > d[static_cast<size_t>(v)]) continue;
    for (int u : neighbours[static_cast<size_t>(v)]) {
      if (enter && !enter(u)) continue;
      const double du = dv + (X.row(v) - X.row(u)).norm();
      if (du < limit && du < d[static_cast<size_t>(u)]) d[static_cast<size_t>(u)] = du, q.push({du, u});
    }
  }
  return d;
}

}  // namespace afmb
