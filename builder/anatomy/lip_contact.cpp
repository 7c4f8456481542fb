#include "anatomy/lip_contact.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "anatomy/skin_model.h"

namespace afmb {

LipContactValue lip_contact_energy(const LipPair &p, double s) {
  const double u = (p.on - s) / p.margin;
  if (!(u > 0)) return {};
  return {p.stiffness * p.margin * u * u * u / 3, -p.stiffness * u * u, 2 * p.stiffness * u / p.margin};
}

std::vector<LipPair> lip_pairs(const SkinModel &m, const std::vector<int> &upper, const std::vector<int> &lower,
                               double modulus, double band, double margin) {
  auto at = [&](int v) { return Eigen::Vector3d(m.X0.row(m.node(kEpidermis, v))); };
  auto usable = [&](int v) { return v >= 0 && v < m.n && m.in_mesh[static_cast<size_t>(v)]; };
  // Each vertex's nearest on the other lip (the lips hold a few hundred
  // vertices at most: the quadratic search costs nothing).
  std::vector<std::pair<int, int>> found;  // (upper vertex, lower vertex)
  auto nearest = [&](int v, const std::vector<int> &other) {
    int best = -1;
    double d2 = band * band;
    for (int w : other)
      if (usable(w))
        if (const double d = (at(v) - at(w)).squaredNorm(); d <= d2) d2 = d, best = w;
    return best;
  };
  for (int a : upper)
    if (usable(a))
      if (const int b = nearest(a, lower); b >= 0) found.emplace_back(a, b);
  for (int b : lower)
    if (usable(b))
      if (const int a = nearest(b, upper); a >= 0) found.emplace_back(a, b);
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  // One above the other, the upper vertex not below the lower one.
  std::vector<std::pair<int, int>> kept;
  for (const auto &[a, b] : found) {
    if (a == b) continue;  // a vertex both searches reached (round a mouth corner)
    const Eigen::Vector3d d = at(a) - at(b);
    const double side = std::hypot(d.x(), d.z());
    if (d.y() >= 0 && side <= std::max(kLipPairSlant * d.y(), margin)) kept.emplace_back(a, b);
  }
  std::vector<int> count(static_cast<size_t>(m.n), 0);
  for (const auto &[a, b] : kept) ++count[static_cast<size_t>(a)], ++count[static_cast<size_t>(b)];
  std::vector<LipPair> pairs;
  for (const auto &[a, b] : kept) {
    LipPair p;
    p.upper = m.node(kEpidermis, a);
    p.lower = m.node(kEpidermis, b);
    p.on = 0;  // contact where the upper vertex comes down to the lower one's height
    p.margin = margin;
    p.stiffness = modulus * (m.area[a] / count[static_cast<size_t>(a)] + m.area[b] / count[static_cast<size_t>(b)]) / 2;
    pairs.push_back(p);
  }
  return pairs;
}

int crossed_lip_pairs(const SkinModel &m, const Eigen::MatrixXd &X, double depth) {
  int crossed = 0;
  for (const LipPair &p : m.lip_pairs)
    if (X(p.upper, 1) - X(p.lower, 1) < p.on - depth) ++crossed;
  return crossed;
}

}  // namespace afmb
