#include "io/load_face.h"

#include "core/orient.h"
#include "core/part_kind.h"
#include "core/repair.h"
#include "core/validate.h"
#include "io/mesh_io.h"

#include <cstdio>
#include <limits>

namespace afmb {

namespace {

// The diagonal of the box around every part's vertices, model units.
double scene_diagonal(const Scene &scene) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Part &p : scene.parts)
    if (p.V.rows()) lo = lo.cwiseMin(p.V.colwise().minCoeff().transpose()), hi = hi.cwiseMax(p.V.colwise().maxCoeff().transpose());
  return (hi - lo).allFinite() ? (hi - lo).norm() : 0.0;
}

}  // namespace

Expected<LoadedFace> load_face(const std::string &mesh_path, const std::string &fdp_path,
                               const LoadOptions &options, std::vector<std::string> *log) {
  LoadedFace face;
  Expected<Scene> scene = read_scene(mesh_path);
  if (!scene) return scene.status();
  face.scene = std::move(*scene);
  if (log)
    for (const std::string &n : face.scene.notes) log->push_back("note: " + n);
  if (options.flip_v)
    for (Part &p : face.scene.parts)
      if (p.TC.rows()) p.TC.col(1) = (1.0 - p.TC.col(1).array()).matrix();
  Expected<FdpSet> fdps = read_fdp(fdp_path, options.fdp_format);
  if (!fdps) return fdps.status();
  face.fdps = std::move(*fdps);
  if (Status s = bind_fdps(face.fdps, face.scene); !s) return s;

  if (!options.orient.empty()) {
    Expected<Orientation> o =
        options.orient == "auto" ? detect_orientation(face.fdps) : parse_orientation(options.orient);
    if (!o) return o.status().wrap("--orient");
    apply_orientation(*o, face.scene, face.fdps);
    if (log) log->push_back("orientation: applied " + o->spec());
  }
  if (Status s = check_orientation(face.fdps); !s) return s.wrap(mesh_path);
  if (log)
    for (const std::string &n : fdp_order_notes(face.fdps)) log->push_back("note: " + fdp_path + ": " + n);

  guess_part_kinds(face.scene);
  const double tolerance = kFreeFdpShare * scene_diagonal(face.scene);
  const FreeFdpAttachment a = attach_free_fdps(face.fdps, face.scene, tolerance);
  if (log && a.attached > 0) {
    char line[160];
    std::snprintf(line, sizeof line, "%d free points attached to the vertex they lie on (", a.attached);
    std::string l = std::string("FDPs: ") + line;
    if (a.farthest > 0) {
      std::snprintf(line, sizeof line, "the farthest %.3g model units away: ", a.farthest);
      l += line + std::string("FDP ") + a.at->id.str() + " on part '" + a.at->part_name + "', vertex " +
           std::to_string(a.at->vertex) + ")";
    } else {
      l += "each exactly on it)";
    }
    if (!a.free.empty()) {
      l += "; free, off the mesh:";
      for (const FdpPoint *p : a.free) l += " " + p->id.str();
    }
    log->push_back(l);
  }
  assign_part_kinds(face.scene, face.fdps);
  face.skin = face.scene.find_kind(PartKind::Skin);
  if (face.skin < 0) {
    for (const FdpPoint *p : a.free)
      if (p->id == FdpId{2, 1}) {
        const NearestVertex n = nearest_vertex(face.scene, p->pos);
        char far[200];
        std::snprintf(far, sizeof far, "%.4g model units from the nearest vertex (part '%s', vertex %d), beyond the %.3g",
                      n.distance, n.part >= 0 ? face.scene.parts[static_cast<size_t>(n.part)].name.c_str() : "",
                      n.vertex, tolerance);
        return Status::error(fdp_location(face.fdps, *p) + " (chin) is a free point " + far +
                             " within which a free point is attached to the mesh (half a percent of the model's "
                             "size): no skin part; give it as part and vertex, or on the surface");
      }
    return Status::error(mesh_path + ": no skin part: no part holds FDP 2.1 (chin)");
  }
  std::vector<std::string> repairs;
  if (split_skin_pieces(face.scene, face.skin, face.fdps, &repairs) > 0) assign_part_kinds(face.scene, face.fdps);
  cut_fused_lips(face.scene, face.skin, face.fdps, &repairs);
  repair_coincident_vertices(face.scene, face.skin, &repairs);
  if (log)
    for (const std::string &r : repairs) log->push_back("repaired: " + r);
  if (Status s = check_skin(face.scene, face.skin); !s) return s;
  return face;
}

}  // namespace afmb
