// VRML97 scenes of named IndexedFaceSet parts: Xface, visage and Song models.
//
// Reads Transform / Group / Shape / IndexedFaceSet / Coordinate /
// TextureCoordinate / Appearance / Material / ImageTexture, DEF and USE, and
// nested Transforms (translation, rotation, scale, scaleOrientation,
// center), applied to the points. Each IndexedFaceSet becomes a part named
// after the nearest DEF'd Transform (else its own DEF, else "shape<N>"), with
// aliases: its own DEF name and "<file name>_<N>" (XfaceEd's name for
// un-DEF'd meshes). Polygons are fan-triangulated; `ccw FALSE` flips them.
// Unknown nodes are skipped whole. Errors name the file and line.
#pragma once

#include <string>
#include <string_view>

#include "core/scene.h"
#include "core/status.h"

namespace afmb {

Expected<Scene> read_vrml(const std::string &path);
// `source_name` is used in messages and for the "<file>_<N>" aliases.
Expected<Scene> parse_vrml(std::string_view text, const std::string &source_name);

// Writes one DEF'd Transform + Shape + IndexedFaceSet per part, with Material,
// ImageTexture and TextureCoordinate where the part has them, and per-vertex
// Color when it has C. Atomic.
Status write_vrml(const Scene &scene, const std::string &path);

}  // namespace afmb
