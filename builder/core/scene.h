// Scene: a face model as imported, before any anatomy is built.
//
// A scene is a list of named parts (skin, eyeballs, teeth, tongue, hair...),
// each an indexed triangle mesh in model units, in the MPEG-4 neutral frame
// once orient_scene() has run: +x the face's own left, +y up, +z forward.
// Texture coordinates are per corner, as in VRML and libigl (TC/FTC), so a
// UV seam does not split the welded vertices the simulation works on; the
// AFM writer splits them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <string_view>
#include <initializer_list>
#include <vector>

namespace afmb {

// What a part is. The numeric values are the AFM part kinds of
// formats/afm.md (GEOM chunk) and must not change.
enum class PartKind : uint8_t {
  Other = 0,
  Skin = 1,        // the simulated face surface: the part holding FDP 2.1
  EyeLeft = 2,     // the face's left eyeball (FDP 3.5)
  EyeRight = 3,    // the face's right eyeball (FDP 3.6)
  TeethUpper = 4,  // follows the skull
  TeethLower = 5,  // follows the jaw
  Tongue = 6,      // follows the jaw
  Hair = 7,        // follows the head
  Eyelid = 8,      // lashes or lid strips: follow the skin around the eyes
  Mouth = 9,       // mouth cavity or throat
};

const char *part_kind_name(PartKind kind);           // "skin", "eye_left", ...
bool part_kind_from_name(std::string_view name, PartKind *kind);

struct Part {
  std::string name;                  // unique in the scene (VRML Transform DEF, OBJ group...)
  std::vector<std::string> aliases;  // other names FDP files use for it (IndexedFaceSet DEF, "file.wrl_3")
  PartKind kind = PartKind::Other;

  Eigen::MatrixXd V;    // #V x 3 vertex positions, model units
  Eigen::MatrixXi F;    // #F x 3 triangles, 0-based into V, counter-clockwise seen from outside
  Eigen::MatrixXd TC;   // #TC x 2 texture coordinates, or 0 x 2
  Eigen::MatrixXi FTC;  // #F x 3 corners into TC, or 0 x 3 when TC is empty
  Eigen::MatrixXd C;    // #V x 3 per-vertex RGB in [0,1], or 0 x 3

  Eigen::Vector3d diffuse{0.8, 0.8, 0.8};  // material colour, RGB in [0,1]
  std::string texture;  // image file as named by the source, or empty

  // The faces' own materials where the source gives each face one (OBJ's
  // usemtl), for splitting the part into pieces (split_skin_pieces): each
  // piece takes the one most of its faces use. diffuse and texture above
  // are the part's most used one's. Empty, or #F indices into `materials`
  // (-1: none).
  struct Material {
    Eigen::Vector3d diffuse{0.8, 0.8, 0.8};
    std::string texture;
  };
  std::vector<Material> materials;
  std::vector<int> face_material;

  bool matches(std::string_view name_or_alias) const;
};

struct Scene {
  std::string name;    // model name, e.g. the source file's stem
  std::string units;   // "m", "cm", "mm" or "" when the source does not say
  std::string source;  // path the scene was read from, for messages
  std::vector<Part> parts;
  // What the reader passed over and the user should hear of (an OBJ's
  // material library that is missing), one line each; the import logs them.
  std::vector<std::string> notes;

  // Index of the part whose name or alias is `name`, or -1.
  int find_part(std::string_view name) const;
  // Index of the first part of this kind, or -1.
  int find_kind(PartKind kind) const;
  // Indices of every part of these kinds, kind by kind, each in part order
  // (the jaw carries {TeethLower, Tongue}: a split head may have several).
  std::vector<int> find_kinds(std::initializer_list<PartKind> kinds) const;
  size_t vertex_count() const;
  size_t triangle_count() const;
};

}  // namespace afmb
