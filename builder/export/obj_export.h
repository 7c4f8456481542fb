// AFM -> one OBJ per morph target: DIR/neutral.obj and DIR/<target>.obj
// (target_name(): "open_jaw.obj", "viseme_A.obj", ...), each the whole face
// (every part, as write_obj writes it: an `o` per part, vertices in AFM
// order, texture coordinates when the AFM has them) with the target fully
// applied, i.e. at its reference value. Rigid parts stay neutral. Positions
// are written to position_decimals(step) places, so a target's file minus
// neutral.obj gives its deltas back exactly (in quanta). Every file uses
// DIR/materials.mtl: a material per part, named as the part, with its colour
// and texture (the image's name as the AFM holds it; the images are not
// copied).
#pragma once

#include <afm/format.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/status.h"

namespace afmb {

constexpr const char *kObjMaterials = "materials.mtl";

struct ObjExportStats {
  size_t files = 0;  // OBJ files (the material library besides)
  size_t bytes = 0;  // of every file, the library's too
};

// Writes the files into `dir` (created when missing; its parent must
// exist). Every file is written atomically; when one fails, the files this
// call wrote are removed again. `progress` is called after each file.
Status export_obj(const afm_doc &doc, const std::string &dir,
                  const std::function<void(size_t done, size_t total)> &progress = {},
                  ObjExportStats *stats = nullptr);

}  // namespace afmb
