#include "io/load_face.h"

#include "core/orient.h"
#include "core/part_kind.h"
#include "core/repair.h"
#include "core/validate.h"
#include "io/mesh_io.h"

namespace afmb {

Expected<LoadedFace> load_face(const std::string &mesh_path, const std::string &fdp_path,
                               const LoadOptions &options, std::vector<std::string> *log) {
  LoadedFace face;
  Expected<Scene> scene = read_scene(mesh_path);
  if (!scene) return scene.status();
  face.scene = std::move(*scene);
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

  guess_part_kinds(face.scene);
  assign_part_kinds(face.scene, face.fdps);
  face.skin = face.scene.find_kind(PartKind::Skin);
  if (face.skin < 0) return Status::error(mesh_path + ": no skin part: no part holds FDP 2.1 (chin)");
  std::vector<std::string> repairs;
  repair_coincident_vertices(face.scene, face.skin, &repairs);
  if (log)
    for (const std::string &r : repairs) log->push_back("repaired: " + r);
  if (Status s = check_skin(face.scene, face.skin); !s) return s;
  return face;
}

}  // namespace afmb
