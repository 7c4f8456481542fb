// AFM -> VRML97 "animatable face model", after the method paper's AFM (a
// VRML file that any viewer shows as the neutral face, with the morph
// targets stored in it). Layout (formats/export.md):
//   - a WorldInfo whose info strings list every target: name, kind, number,
//     reference value, and the parts it moves;
//   - the neutral face: one DEF'd Transform + Shape + IndexedFaceSet per AFM
//     part (as write_vrml writes them), points in AFM vertex order, with the
//     part's material, texture, texture coordinates and vertex colours;
//   - DEF afm_morph_targets Switch { whichChoice -1 ... }: not drawn. One
//     choice per target, a Group DEF'd with the target's name
//     (target_name()), holding per part the target moves a Transform DEF'd
//     "<target>__<part>" whose IndexedFaceSet has every point of the part at
//     the target's reference value (point i is the neutral part's point i)
//     and, as faces, the part's triangles the target moves.
// Positions are written to position_decimals(step) places: they read back
// to the AFM's quanta, and a target minus the neutral face to its deltas.
#pragma once

#include <afm/format.h>

#include <cstddef>
#include <string>

#include "core/status.h"

namespace afmb {

struct VrmlExportStats {
  size_t bytes = 0;
  size_t target_shapes = 0;  // (target, part) pairs stored
};

// The file's text. `source` names the AFM in messages.
Expected<std::string> vrml_afm_text(const afm_doc &doc, const std::string &source,
                                    VrmlExportStats *stats = nullptr);

// vrml_afm_text, then an atomic write.
Status export_vrml(const afm_doc &doc, const std::string &source, const std::string &path,
                   VrmlExportStats *stats = nullptr);

}  // namespace afmb
