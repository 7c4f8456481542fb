#include "core/fdp.h"

#include <afm/mpeg4.h>

#include <cmath>
#include <limits>
#include <set>

#include "core/part_kind.h"

namespace afmb {

std::optional<FdpId> FdpId::parse(std::string_view text) {
  int g = 0, i = 0;
  if (!afm_fdp_parse(text.data(), text.size(), &g, &i)) return std::nullopt;
  return FdpId{g, i};
}

std::string FdpId::str() const { return std::to_string(group) + "." + std::to_string(index); }

const FdpPoint *FdpSet::find(FdpId id, int part) const {
  const FdpPoint *first = nullptr;
  for (const FdpPoint &p : points) {
    if (p.id != id) continue;
    if (part < 0 || p.part == part) return &p;
    if (!first) first = &p;
  }
  return first;
}

size_t FdpSet::distinct_count() const {
  std::set<FdpId> ids;
  for (const FdpPoint &p : points) ids.insert(p.id);
  return ids.size();
}

std::string fdp_location(const FdpSet &fdps, const FdpPoint &point) {
  std::string where;
  if (!fdps.source.empty()) {
    where = fdps.source;
    if (point.line > 0) where += ":" + std::to_string(point.line);
    where += ": ";
  }
  return where + "FDP " + point.id.str();
}

namespace {

// The scene as messages name it: its file's name, else its model name.
std::string scene_label(const Scene &scene) {
  if (!scene.source.empty()) {
    size_t slash = scene.source.find_last_of('/');
    return slash == std::string::npos ? scene.source : scene.source.substr(slash + 1);
  }
  return scene.name.empty() ? std::string("the scene") : scene.name;
}

std::string part_list(const Scene &scene) {
  std::string out;
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    if (i) out += ", ";
    out += scene.parts[i].name;
    if (i == 11 && scene.parts.size() > 12) {
      out += ", ... (" + std::to_string(scene.parts.size()) + " in all)";
      break;
    }
  }
  return out.empty() ? std::string("none") : out;
}

// "@N" with N a canonical decimal index into scene.parts, else -1.
int part_by_index(const Scene &scene, const std::string &name) {
  if (name.size() < 2 || name.size() > 10 || name[0] != '@') return -1;
  if (name.size() > 2 && name[1] == '0') return -1;
  long n = 0;
  for (size_t i = 1; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
    n = n * 10 + (name[i] - '0');
  }
  return n < static_cast<long>(scene.parts.size()) ? static_cast<int>(n) : -1;
}

}  // namespace

Status bind_fdps(FdpSet &fdps, const Scene &scene) {
  for (FdpPoint &p : fdps.points) {
    if (p.part_name.empty()) {  // a free point keeps its given position
      p.part = -1;
      p.vertex = -1;
      continue;
    }
    int part = scene.find_part(p.part_name);
    if (part < 0) part = part_by_index(scene, p.part_name);
    if (part < 0)
      return Status::error(fdp_location(fdps, p) + ": part '" + p.part_name + "' not in " +
                           scene_label(scene) + " (parts: " + part_list(scene) + ")");
    const Part &pt = scene.parts[static_cast<size_t>(part)];
    if (p.vertex < 0 || p.vertex >= pt.V.rows())
      return Status::error(fdp_location(fdps, p) + ": vertex " + std::to_string(p.vertex) +
                           " out of range: part '" + pt.name + "' has " +
                           std::to_string(pt.V.rows()) + " vertices");
    p.part = part;
    p.pos = pt.V.row(p.vertex).transpose();
  }
  return Status::ok();
}

namespace {

// The nearest vertex of the parts `use` allows (all when null).
NearestVertex nearest_on(const Scene &scene, const Eigen::Vector3d &pos, const std::vector<char> *use) {
  NearestVertex best;
  double best2 = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    if (use && !(*use)[i]) continue;
    const Eigen::MatrixXd &V = scene.parts[i].V;
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      const double d2 = (V.row(v).transpose() - pos).squaredNorm();
      if (d2 < best2) best2 = d2, best = {static_cast<int>(i), static_cast<int>(v), 0.0};
    }
  }
  if (best.part >= 0) best.distance = std::sqrt(best2);
  return best;
}

// +1 for an FDP on the upper lip, an upper lid or the upper teeth, -1 on the
// lower ones, 0 elsewhere. In a closed mouth the inner contours' points
// coincide (2.2 and 2.3 are two vertices at one position), as do the
// incisors' edges where the teeth touch, so coordinates alone cannot say
// which side a point is on.
int vertical_side(FdpId id) {
  static const FdpId up[] = {{2, 2}, {2, 6}, {2, 7},  {8, 1},  {8, 5},  {8, 6}, {8, 9},
                             {8, 10}, {3, 1}, {3, 2}, {3, 13}, {3, 14}, {9, 8}, {9, 10}};
  static const FdpId down[] = {{2, 3}, {2, 8}, {2, 9}, {8, 2}, {8, 7}, {8, 8},
                               {3, 3}, {3, 4}, {3, 9}, {3, 10}, {9, 9}, {9, 11}};
  for (const FdpId &u : up)
    if (u == id) return 1;
  for (const FdpId &d : down)
    if (d == id) return -1;
  return 0;
}

// Of the vertices of `part` at the nearest one's position, the one on the
// FDP's side: the mean height of its triangles' corners highest (side +1) or
// lowest (-1); the lowest index where the side says nothing.
int pick_coincident(const Part &part, int nearest, int side) {
  if (side == 0) return nearest;
  std::vector<int> same;
  for (Eigen::Index v = 0; v < part.V.rows(); ++v)
    if (part.V.row(v) == part.V.row(nearest)) same.push_back(static_cast<int>(v));
  if (same.size() < 2) return nearest;
  std::vector<double> height(same.size(), 0), count(same.size(), 0);
  for (Eigen::Index f = 0; f < part.F.rows(); ++f)
    for (size_t k = 0; k < same.size(); ++k)
      if ((part.F.row(f).array() == same[k]).any()) {
        for (int c = 0; c < 3; ++c) height[k] += part.V(part.F(f, c), 1);
        count[k] += 3;
      }
  int best = nearest;
  double best_h = 0;
  bool first = true;
  for (size_t k = 0; k < same.size(); ++k) {
    if (count[k] == 0) continue;  // unused: a welded-away copy
    const double h = side * height[k] / count[k];
    if (first || h > best_h) best = same[k], best_h = h, first = false;
  }
  return best;
}

}  // namespace

NearestVertex nearest_vertex(const Scene &scene, const Eigen::Vector3d &pos) { return nearest_on(scene, pos, nullptr); }

FreeFdpAttachment attach_free_fdps(FdpSet &fdps, const Scene &scene, double tolerance) {
  FreeFdpAttachment out;
  for (FdpPoint &p : fdps.points) {
    if (!p.part_name.empty()) continue;
    const PartKind kind = fdp_part_kind(p.id);
    std::vector<char> own(scene.parts.size(), 0);
    bool any = false;
    for (size_t i = 0; i < scene.parts.size(); ++i) any |= own[i] = scene.parts[i].kind == kind;
    const NearestVertex n = nearest_on(scene, p.pos, any ? &own : nullptr);
    bool taken = false;
    for (const FdpPoint &q : fdps.points) taken |= &q != &p && q.id == p.id && q.part == n.part && n.part >= 0;
    if (n.part < 0 || n.distance > tolerance || taken) {
      out.free.push_back(&p);
      continue;
    }
    const Part &part = scene.parts[static_cast<size_t>(n.part)];
    p.part = n.part;
    p.part_name = part.name;
    p.vertex = pick_coincident(part, n.vertex, vertical_side(p.id));
    p.pos = part.V.row(n.vertex).transpose();
    ++out.attached;
    if (!out.at || n.distance > out.farthest) out.farthest = n.distance, out.at = &p;
  }
  return out;
}

}  // namespace afmb
