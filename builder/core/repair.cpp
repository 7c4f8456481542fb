#include "core/repair.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <numeric>

namespace afmb {

int repair_coincident_vertices(Scene &scene, int part_index, std::vector<std::string> *log) {
  Part &part = scene.parts[static_cast<size_t>(part_index)];
  const Eigen::Index nv = part.V.rows();
  std::vector<int> to(static_cast<size_t>(nv));
  std::iota(to.begin(), to.end(), 0);
  auto root = [&](int v) {
    while (to[static_cast<size_t>(v)] != v) v = to[static_cast<size_t>(v)];
    return v;
  };
  std::string welded;
  for (Eigen::Index f = 0; f < part.F.rows(); ++f) {
    Eigen::Vector3d a = part.V.row(part.F(f, 0)), b = part.V.row(part.F(f, 1)), c = part.V.row(part.F(f, 2));
    if ((b - a).cross(c - a).squaredNorm() != 0) continue;
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        int p = root(part.F(f, i)), q = root(part.F(f, j));
        if (p == q || part.V.row(p) != part.V.row(q)) continue;
        if (p > q) std::swap(p, q);
        to[static_cast<size_t>(q)] = p;
        welded += " " + std::to_string(q) + "->" + std::to_string(p);
      }
  }
  if (welded.empty()) return 0;
  std::vector<Eigen::Index> keep;
  std::string dropped;
  for (Eigen::Index f = 0; f < part.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) part.F(f, k) = root(part.F(f, k));
    if (part.F(f, 0) == part.F(f, 1) || part.F(f, 1) == part.F(f, 2) || part.F(f, 0) == part.F(f, 2))
      dropped += " " + std::to_string(f);
    else
      keep.push_back(f);
  }
  const int removed = static_cast<int>(part.F.rows() - static_cast<Eigen::Index>(keep.size()));
  Eigen::MatrixXi F(static_cast<Eigen::Index>(keep.size()), 3), FTC;
  const bool has_ftc = part.FTC.rows() == part.F.rows() && part.FTC.rows() > 0;
  if (has_ftc) FTC.resize(static_cast<Eigen::Index>(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) {
    F.row(static_cast<Eigen::Index>(i)) = part.F.row(keep[i]);
    if (has_ftc) FTC.row(static_cast<Eigen::Index>(i)) = part.FTC.row(keep[i]);
  }
  part.F = F;
  if (has_ftc) part.FTC = FTC;
  if (log) {
    log->push_back("part '" + part.name + "': welded coincident vertices" + welded);
    log->push_back("part '" + part.name + "': dropped " + std::to_string(removed) +
                   " zero-area triangles (input triangles" + dropped + ")");
  }
  return removed;
}

}  // namespace afmb
