// Feature points (FDPs) and FAP units (FAPU) of a scene.
//
// An FdpSet is what an FDP file says, before or after it is bound to a scene:
// each point names an FDP and either a part + vertex or a free position.
// bind_fdps() resolves part names and vertex indices against a Scene and fills
// in positions; compute_fapu() derives the five FAPU distances from them.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct FdpId {
  int group = 0;  // 2..11
  int index = 0;  // 1..15

  // "2.10" -> {2, 10}; nullopt unless it is one of the 84 standard FDPs.
  static std::optional<FdpId> parse(std::string_view text);
  std::string str() const;  // "2.10"
  bool operator==(const FdpId &o) const { return group == o.group && index == o.index; }
  bool operator!=(const FdpId &o) const { return !(*this == o); }
  bool operator<(const FdpId &o) const {
    return group != o.group ? group < o.group : index < o.index;
  }
};

struct FdpPoint {
  FdpId id;
  std::string part_name;  // as the file names it ("song_head-FACES"), "@N" for the scene's
                          // N-th part (0-based; visage mesh indices), or empty for a free point
  int part = -1;          // index into Scene::parts once bound, -1 for a free point
  int vertex = -1;        // vertex index in that part, -1 for a free point
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();  // model units; filled by bind_fdps for vertex points
                                                  // (a visage file's own coordinates until then)
  int line = 0;           // line in the source file, for messages (0 = unknown)
};

// FAPU distances X0 in model units (one FAP unit is X0 / 1024).
struct Fapu {
  double es0 = 0;     // eye separation: 3.5 to 3.6
  double irisd0 = 0;  // iris diameter: 3.1 to 3.3 (and 3.2 to 3.4)
  double ens0 = 0;    // eye-nose separation: eye height to 9.15
  double mns0 = 0;    // mouth-nose separation: 9.15 to 2.2
  double mw0 = 0;     // mouth width: 8.3 to 8.4
};

struct FdpSet {
  std::string source;         // file the set was read from, for messages
  std::vector<FdpPoint> points;  // in file order; one FDP may appear on several parts
  std::optional<Fapu> stored_fapu;  // FAPU the file itself states, if any

  // First point with this id, preferring one on `part` when part >= 0.
  const FdpPoint *find(FdpId id, int part = -1) const;
  // Number of distinct FDP ids.
  size_t distinct_count() const;
};

// Resolves every point's part name against the scene (name or alias; "@N"
// is the scene's N-th part when no part is called that) and its vertex index
// against that part, and sets part, vertex and pos. Free points keep their
// position. Stops at the first error, which names the source file, line and
// FDP: "song.fdp:57: FDP 2.2: part 'foo' not in song.WRL (parts: ...)". On
// error `fdps` may be partly bound.
Status bind_fdps(FdpSet &fdps, const Scene &scene);

// Attaches each free point that lies on the mesh to the vertex it lies on,
// so that a file of coordinates (a visage file without mesh indices, a text
// file of `FDP X Y Z` lines) drives the face as part + vertex points do. A
// point's candidates are the vertices of the parts of its own kind
// (fdp_part_kind(): the pupils on the eyes, 6.x on the tongue, the incisors
// on the teeth, every other FDP on the skin) when the scene's parts are
// named so (guess_part_kinds), else of every part; the nearest within
// `tolerance` (model units) wins. Among vertices at one position, the lips',
// lids' and incisors' points take the one on their side (2.2 the one whose
// triangles lie above, 2.3 below: a closed mouth's inner contours coincide,
// as do touching teeth), others the lowest index (an exporter's split seam). The point
// then gets that part, its name and vertex, and the vertex's own position.
// Points farther from every candidate stay free: FDP 7.1, the top of the
// spine, lies inside the neck. A free point whose FDP the set already has on
// the part found also stays free (one point per FDP and part).
struct FreeFdpAttachment {
  int attached = 0;
  double farthest = 0;        // model units, of the attached points
  // Into fdps.points (valid while it is not resized): the attached point
  // that lay farthest, and the points that stay free.
  const FdpPoint *at = nullptr;
  std::vector<const FdpPoint *> free;
};
FreeFdpAttachment attach_free_fdps(FdpSet &fdps, const Scene &scene, double tolerance);

// The nearest vertex to `pos` over every part: {part, vertex, distance}, or
// part -1 in a scene without vertices. For messages about points left free.
struct NearestVertex {
  int part = -1, vertex = -1;
  double distance = 0;
};
NearestVertex nearest_vertex(const Scene &scene, const Eigen::Vector3d &pos);

// "song.fdp:57: FDP 2.2", the prefix of every message about one point ("song.fdp:
// FDP 2.2" when the line is unknown, "FDP 2.2" when the source is too).
std::string fdp_location(const FdpSet &fdps, const FdpPoint &point);

}  // namespace afmb
