#include "export/obj_export.h"

#include <filesystem>
#include <system_error>

#include "export/export_model.h"
#include "io/mesh_io.h"

namespace afmb {

namespace fs = std::filesystem;

Status export_obj(const afm_doc &doc, const std::string &dir,
                  const std::function<void(size_t done, size_t total)> &progress,
                  ObjExportStats *stats) {
  std::error_code ec;
  const bool created = !fs::exists(dir, ec);
  if (created && !fs::create_directory(dir, ec))
    return Status::error(dir + ": cannot create the directory: " + ec.message());
  if (!fs::is_directory(dir, ec)) return Status::error(dir + ": not a directory");

  const int decimals = position_decimals(doc.geometry.step);
  Scene scene = afm_scene(doc, decimals);
  const std::vector<std::string> names = target_names(doc);
  std::vector<std::string> written;
  const size_t total = size_t(doc.target_count) + 1;
  // One material library for all the files: each part's colour and texture.
  const std::string library = (fs::path(dir) / kObjMaterials).string();
  if (Status s = write_mtl(scene, library); !s) {
    if (created) fs::remove(dir, ec);
    return s;
  }
  written.push_back(library);
  if (stats) stats->bytes += size_t(fs::file_size(library, ec));
  for (size_t k = 0; k < total; ++k) {
    const afm_target *t = k == 0 ? nullptr : &doc.targets[k - 1];
    for (uint32_t pi = 0; pi < doc.geometry.part_count; ++pi)
      scene.parts[pi].V = part_positions(doc, doc.geometry.parts[pi], t, decimals);
    const std::string path = (fs::path(dir) / ((k == 0 ? std::string("neutral") : names[k - 1]) + ".obj")).string();
    if (Status s = write_obj(scene, path, kObjMaterials); !s) {
      for (const std::string &f : written) fs::remove(f, ec);
      if (created) fs::remove(dir, ec);
      return s;
    }
    written.push_back(path);
    if (stats) stats->bytes += size_t(fs::file_size(path, ec));
    if (progress) progress(k + 1, total);
  }
  if (stats) stats->files = written.size() - 1;
  return Status::ok();
}

}  // namespace afmb
