#include "core/validate.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unordered_map>

namespace afmb {

namespace {

std::string tri_str(const Eigen::MatrixXi &F, Eigen::Index t) {
  return "triangle " + std::to_string(t) + " (" + std::to_string(F(t, 0)) + ", " +
         std::to_string(F(t, 1)) + ", " + std::to_string(F(t, 2)) + ")";
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

uint64_t key(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

}  // namespace

Status check_skin(const Scene &scene, int part_index) {
  if (part_index < 0 || part_index >= static_cast<int>(scene.parts.size()))
    return Status::error((scene.source.empty() ? std::string("scene") : scene.source) + ": no part " +
                         std::to_string(part_index) + " (" + std::to_string(scene.parts.size()) +
                         " parts)");
  const Part &p = scene.parts[part_index];
  const std::string where =
      (scene.source.empty() ? std::string() : scene.source + ": ") + "part '" + p.name + "'";
  auto fail = [&where](const std::string &msg) { return Status::error(where + ": " + msg); };
  const Eigen::MatrixXd &V = p.V;
  const Eigen::MatrixXi &F = p.F;
  if (V.cols() != 3 || F.cols() != 3) return fail("vertex or triangle matrix is not n x 3");
  if (F.rows() == 0) return fail("no triangles");
  const int nv = static_cast<int>(V.rows());

  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite()) return fail("vertex " + std::to_string(i) + " has a non-finite coordinate");

  const double diag = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  // Zero area, relative to the model's size: below 1e-10 of the squared
  // bounding-box diagonal (a 20 cm head: 4e-12 m^2, a triangle of about 3 um
  // sides), which float-rounded collinear or coincident points fall under and
  // no real skin triangle does.
  const double min_area = 1e-10 * diag * diag;

  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    for (int k = 0; k < 3; ++k)
      if (F(t, k) < 0 || F(t, k) >= nv)
        return fail(tri_str(F, t) + ": vertex index " + std::to_string(F(t, k)) + " out of range (" +
                    std::to_string(nv) + " vertices)");
    if (F(t, 0) == F(t, 1) || F(t, 1) == F(t, 2) || F(t, 0) == F(t, 2))
      return fail(tri_str(F, t) + " repeats a vertex");
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (!(area > min_area))
      return fail(tri_str(F, t) + " is degenerate: area " + num(area) + " is below " + num(min_area) +
                  " (1e-10 of the squared bounding-box diagonal)");
  }

  // Undirected edge -> triangles using it, directed edge -> triangle.
  struct EdgeUse {
    int count = 0;
    int tri[3] = {-1, -1, -1};
  };
  std::unordered_map<uint64_t, EdgeUse> edges;
  std::unordered_map<uint64_t, int> directed;
  edges.reserve(static_cast<size_t>(F.rows()) * 2);
  directed.reserve(static_cast<size_t>(F.rows()) * 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = F(t, k), b = F(t, (k + 1) % 3);
      EdgeUse &e = edges[key(std::min(a, b), std::max(a, b))];
      if (e.count < 3) e.tri[e.count] = static_cast<int>(t);
      ++e.count;
    }
  // Report in triangle order: the first triangle touching a bad edge.
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = F(t, k), b = F(t, (k + 1) % 3);
      const EdgeUse &e = edges[key(std::min(a, b), std::max(a, b))];
      if (e.count > 2)
        return fail("edge " + std::to_string(std::min(a, b)) + "-" + std::to_string(std::max(a, b)) +
                    " is shared by " +
                    std::to_string(e.count) + " triangles (" + std::to_string(e.tri[0]) + ", " +
                    std::to_string(e.tri[1]) + ", " + std::to_string(e.tri[2]) +
                    (e.count > 3 ? ", ..." : "") + "): not edge-manifold");
    }
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = F(t, k), b = F(t, (k + 1) % 3);
      auto [it, fresh] = directed.emplace(key(a, b), static_cast<int>(t));
      if (!fresh)
        return fail("triangles " + std::to_string(it->second) + " and " + std::to_string(t) +
                    " both run along edge " + std::to_string(a) + "->" + std::to_string(b) +
                    ": inconsistent orientation (or a duplicated triangle)");
    }
  return Status::ok();
}

}  // namespace afmb
