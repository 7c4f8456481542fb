#include "core/fdp.h"

#include <afm/mpeg4.h>

#include <set>

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

}  // namespace afmb
