#include "anatomy/mirror.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

namespace afmb {

namespace {

// For every row of V, the rows within `tolerance` of its reflection in the
// plane x = mid, nearest first (ties: lower index first).
std::vector<std::vector<int>> image_candidates(const Eigen::MatrixXd &V, double mid, double tolerance) {
  const int n = static_cast<int>(V.rows());
  std::vector<std::vector<int>> out(static_cast<size_t>(n));
  if (!(tolerance > 0)) return out;
  // A hash grid of cells `tolerance` wide: the image's cell and its 26
  // neighbours hold every candidate.
  auto cell = [tolerance](const Eigen::Vector3d &x) {
    return Eigen::Vector3i(static_cast<int>(std::floor(x.x() / tolerance)), static_cast<int>(std::floor(x.y() / tolerance)),
                           static_cast<int>(std::floor(x.z() / tolerance)));
  };
  auto key = [](const Eigen::Vector3i &c) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(c.x())) * 73856093u) ^
           (static_cast<uint64_t>(static_cast<uint32_t>(c.y())) * 19349663u) ^
           (static_cast<uint64_t>(static_cast<uint32_t>(c.z())) * 83492791u);
  };
  std::unordered_multimap<uint64_t, int> grid;
  for (int v = 0; v < n; ++v) grid.emplace(key(cell(V.row(v).transpose())), v);
  for (int v = 0; v < n; ++v) {
    Eigen::Vector3d image = V.row(v).transpose();
    image.x() = 2 * mid - image.x();
    const Eigen::Vector3i c = cell(image);
    std::vector<std::pair<double, int>> near;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto range = grid.equal_range(key(c + Eigen::Vector3i(dx, dy, dz)));
          for (auto it = range.first; it != range.second; ++it) {
            const double d = (V.row(it->second).transpose() - image).norm();
            if (d < tolerance) near.emplace_back(d, it->second);
          }
        }
    std::sort(near.begin(), near.end());
    for (const auto &[d, u] : near) out[static_cast<size_t>(v)].push_back(u);
  }
  return out;
}

// Each row's nearest candidate, or -1.
std::vector<int> nearest(const std::vector<std::vector<int>> &near) {
  std::vector<int> out(near.size(), -1);
  for (size_t v = 0; v < near.size(); ++v)
    if (!near[v].empty()) out[v] = near[v].front();
  return out;
}

}  // namespace

std::vector<int> mirror_vertices(const Eigen::MatrixXd &V, double mid, double tolerance) {
  return nearest(image_candidates(V, mid, tolerance));
}

SkinMirror skin_mirror(const Eigen::MatrixXd &V, const std::vector<uint8_t> &used, double mid_guess, double tolerance,
                       const std::vector<std::vector<int>> *neighbours) {
  const int n = static_cast<int>(V.rows());
  auto counts = [&](int v) { return used.empty() || used[static_cast<size_t>(v)]; };
  int total = 0;
  for (int v = 0; v < n; ++v) total += counts(v) ? 1 : 0;
  SkinMirror out;
  const std::vector<std::vector<int>> near = image_candidates(V, mid_guess, tolerance);
  std::vector<int> image = nearest(near);
  if (neighbours) {
    // Where vertices coincide (a seam, the corners of a slit), the nearest
    // is no answer: the candidate whose neighbours are the images of most
    // of v's neighbours is.
    for (int v = 0; v < n; ++v) {
      const std::vector<int> &cs = near[static_cast<size_t>(v)];
      if (cs.size() < 2) continue;
      int best = -1;
      for (int u : cs) {
        int score = 0;
        for (int a : (*neighbours)[static_cast<size_t>(v)])
          for (int b : (*neighbours)[static_cast<size_t>(u)]) {
            const std::vector<int> &ia = near[static_cast<size_t>(a)];
            if (std::find(ia.begin(), ia.end(), b) != ia.end()) {
              ++score;
              break;
            }
          }
        if (score > best) best = score, image[static_cast<size_t>(v)] = u;
      }
    }
  }
  for (int v = 0; v < n; ++v)
    if (!counts(v) || (image[static_cast<size_t>(v)] >= 0 && !counts(image[static_cast<size_t>(v)])))
      image[static_cast<size_t>(v)] = -1;
  std::vector<double> middles;
  for (int v = 0; v < n; ++v)
    if (const int m = image[static_cast<size_t>(v)]; m >= 0) middles.push_back(0.5 * (V(v, 0) + V(m, 0)));
  if (total == 0 || middles.size() * 10 < static_cast<size_t>(total) * 9) return out;
  std::nth_element(middles.begin(), middles.begin() + static_cast<std::ptrdiff_t>(middles.size() / 2), middles.end());
  out.mid = middles[middles.size() / 2];
  out.image = std::move(image);
  return out;
}

std::string twin_name(const std::string &muscle) {
  for (const auto &[from, to] : {std::pair<const char *, const char *>{"_left", "_right"}, {"_right", "_left"}}) {
    const size_t n = std::char_traits<char>::length(from);
    if (muscle.size() > n && muscle.compare(muscle.size() - n, n, from) == 0)
      return muscle.substr(0, muscle.size() - n) + to;
  }
  return std::string();
}

bool right_side(const std::string &muscle) {
  const size_t n = std::char_traits<char>::length("_right");
  return muscle.size() > n && muscle.compare(muscle.size() - n, n, "_right") == 0;
}

}  // namespace afmb
