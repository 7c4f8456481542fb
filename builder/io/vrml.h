// VRML97 scenes of named IndexedFaceSet parts: Xface, visage and Song models.
//
// Reads Transform / Group / Collision / Anchor / Billboard / Switch (the
// chosen child, or every one with VrmlReadOptions) / LOD (the first level) /
// Shape / IndexedFaceSet / Coordinate / TextureCoordinate / Color /
// Appearance / Material / ImageTexture, DEF and USE, and nested Transforms
// (translation, rotation, scale, scaleOrientation, center:
// P' = T C R SR S -SR -C P), applied to the points. Every other node (PROTO
// instances included) is skipped whole, as are PROTO, EXTERNPROTO and ROUTE
// statements and unknown fields. The file must start with "#VRML V2.0".
//
// Each IndexedFaceSet instance becomes a part. Its name: the DEF of the
// innermost DEF'd grouping node that holds no other mesh (Song:
// "song_head"), else the IndexedFaceSet's DEF, else the Shape's, else
// "shape<N>" (N = the part's index); a name already taken gets "_2", "_3".
// Aliases: the IndexedFaceSet's DEF ("song_head-FACES", the name XfaceEd FDP
// files use) and the Shape's DEF when they differ from the name, and, for an
// IndexedFaceSet without DEF, "<file name>_<N>" with N counting such
// IndexedFaceSets from 0 in file order (XfaceEd's name for them, e.g.
// "alice.wrl_3"). The kind is guessed from the names (guess_part_kind).
//
// Geometry: every Coordinate point is kept, used or not, so FDP vertex
// indices stay valid. Polygons (-1 terminated; a missing final -1 is
// accepted) are fan-triangulated from their first corner; `ccw FALSE`, or a
// mirroring transform, reverses them so triangles stay counter-clockwise
// seen from outside. texCoordIndex (or coordIndex when it is absent) gives
// FTC. Colours: colorPerVertex TRUE only, colour i for point i or per corner
// through colorIndex (a point takes its first corner's colour); per-face
// colours are ignored. Normals are ignored.
//
// Errors name the file and line: "song.WRL:1733: coordIndex 9999 out of range
// (2916 points)", a bracket never closed (the line where it opened), USE of
// an undefined name, a malformed number, a polygon of fewer than 3 corners,
// texCoordIndex polygons that do not match coordIndex, an Inline (its
// geometry would be missing). A file without any IndexedFaceSet is an error.
#pragma once

#include <set>
#include <string>
#include <string_view>

#include "core/scene.h"
#include "core/status.h"

namespace afmb {

struct VrmlReadOptions {
  // Read every choice of a Switch, not only the chosen one: for files that
  // keep alternatives out of sight, such as the morph targets afm-export
  // stores in a Switch with whichChoice -1 (formats/export.md).
  bool all_switch_choices = false;
};

Expected<Scene> read_vrml(const std::string &path, const VrmlReadOptions &options = {});
// `source_name` is used in messages and for the "<file>_<N>" aliases.
Expected<Scene> parse_vrml(std::string_view text, const std::string &source_name,
                           const VrmlReadOptions &options = {});

// Writes one DEF'd Transform + Shape + IndexedFaceSet per part, with Material,
// ImageTexture and TextureCoordinate where the part has them, and per-vertex
// Color when it has C; numbers in their shortest exact form, so read_vrml()
// gives back the same doubles. The Transform is DEF'd with the part's name,
// the IndexedFaceSet with its first alias that is a legal VRML name (else
// "<name>-FACES"); characters VRML forbids in names become '_' and repeated
// names get "_2". Kinds and further aliases are not written. Atomic.
Status write_vrml(const Scene &scene, const std::string &path);

// The part nodes write_vrml writes (no header line), for writers that add
// nodes of their own. `used` holds the DEF names already taken in the file
// and gets the new ones. Errors (malformed matrices) name `where`.
Expected<std::string> vrml_parts_text(const Scene &scene, std::set<std::string> *used,
                                      const std::string &where);
// A VRML SFString literal: quotes, with '"' and '\\' escaped.
std::string vrml_string(const std::string &text);

}  // namespace afmb
