// Mesh files in and out: OBJ, PLY, OFF, STL (through OpenMesh) and VRML97.
#pragma once

#include <string>

#include "core/scene.h"
#include "core/status.h"

namespace afmb {

// Reads a scene; the format comes from the extension (case-insensitive):
//   .obj         OpenMesh; each `o`/`g` group becomes a part named by the rest
//                of that line (faces before any o/g, or a file without
//                groups: a part named after the file stem; a group named again
//                later continues; groups without faces are dropped; repeated
//                names get "_2", "_3"). `vt` become TC/FTC when every face of
//                the group has them. With one part it keeps every vertex in
//                file order, so vertex i is the file's `v` number i+1; with
//                several, each part keeps the vertices its faces use, in file
//                order. Materials: each part takes the `usemtl` most of its
//                triangles use, from the `mtllib` files beside the OBJ: `Kd`
//                becomes its diffuse colour, `map_Kd` its texture (the file
//                name as written, options such as `-s 1 1 1` left out), and
//                keeps each triangle's (Part::face_material: a head exported
//                as one object, split into pieces, gives each its own); a
//                missing library or material is a note (Scene::notes), a
//                malformed `Kd` an error naming the MTL file and line.
//   .ply .off .stl  OpenMesh, one part named after the file stem; PLY/OFF
//                vertex colours become C and vertex texcoords TC (FTC = F).
//   .wrl .vrml   read_vrml().
// Polygons are fan-triangulated from their first vertex. Part kinds are
// guessed from names (guess_part_kind). Errors name the file and, where the
// format has lines, the line: a missing file, an unknown extension, an index
// out of range, a face repeating a vertex, a face OpenMesh drops (found by
// comparing OpenMesh's face count with the file's).
// Faces OpenMesh can hold only by splitting them off onto copies of their
// vertices (inconsistent orientation, a third face on an edge, two fans at a
// vertex): in OBJ they are kept as written, on the file's vertices, and left
// for check_skin() to judge (the Candide-3 OBJ has 29 edges where neighbouring
// triangles wind opposite ways); in
// PLY/OFF/STL, where the file's indices are not at hand, they are an error
// naming the face. OpenMesh's own messages are captured into the error
// instead of going to stderr (its streams are process-wide: do not read
// meshes from two threads at once).
Expected<Scene> read_scene(const std::string &path);

// Writes an OBJ with one `o` per part, `vt`/`f v/vt` when a part has TC,
// numbers in their shortest exact form. With `mtllib`, that line first and
// `usemtl <part name>` after each `o` (write_mtl writes the library).
// Vertex colours and kinds are not written. Atomic: the file appears
// complete or not at all.
Status write_obj(const Scene &scene, const std::string &path, const std::string &mtllib = "");

// Writes an MTL library with one material per part, named as the part: `Kd`
// its diffuse colour, `map_Kd` its texture when it has one (as the part
// names it). Atomic.
Status write_mtl(const Scene &scene, const std::string &path);

}  // namespace afmb
