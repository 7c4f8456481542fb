// AFM (+ FAP stream) -> glTF 2.0 binary (.glb). The mapping is specified in
// formats/export.md; in short:
//   - one mesh per AFM part (one triangle primitive: positions in model
//     units, the AFM's normals, texture coordinates with v flipped to glTF's
//     top-left origin, vertex colours), one material per part (its diffuse
//     colour; its texture embedded when the file is PNG or JPEG);
//   - every morph target on the meshes of the parts it moves, as a sparse
//     POSITION target at the target's reference value, named in
//     mesh.extras.targetNames (target_name(): "open_jaw", "viseme_A",
//     "expression_joy");
//   - rigid parts (eyes, jaw, head) as pivot nodes: a node at the pivot
//     ("head_pivot", "jaw_pivot", "eye_left_pivot", "eye_right_pivot")
//     holding a node at minus the pivot ("..._offset") holding the parts it
//     moves; the jaw
//     and eyes nest inside the head, so a part follows them as the player
//     moves it (jaw and eyes first, then the head);
//   - with a stream: one animation, keyed at every stream frame, of the
//     morph weights (the player's own weights, afm_player_weights) and the
//     pivot nodes' rotation and translation (afm_rigid_pose), linear.
// The root node scales the model's units to metres (glTF's unit); its
// frame is the MPEG-4 one, which is glTF's (+y up, the face looks along +z).
#pragma once

#include <afm/format.h>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/status.h"
#include "export/export_model.h"

namespace afmb {

struct GltfOptions {
  const FapStream *stream = nullptr;       // animate from it; null: no animation
  std::string stream_path;                 // the stream's file, for messages
  std::vector<std::string> texture_dirs;   // where texture files are looked for, in order
  // Called for things left out (a texture not found or not PNG/JPEG).
  std::function<void(const std::string &note)> note;
  // Called after each animated frame: frames done, frames in all.
  std::function<void(size_t done, size_t total)> progress;
};

struct GltfStats {
  size_t bytes = 0;          // the .glb file
  size_t meshes = 0;
  size_t nodes = 0;
  size_t mesh_targets = 0;   // morph targets summed over meshes (a target on two parts counts twice)
  size_t targets = 0;        // distinct AFM targets exported
  size_t frames = 0;         // animation keys
  size_t textures = 0;       // images embedded
};

// The .glb bytes. `source` names the AFM in messages.
Expected<std::vector<uint8_t>> gltf_bytes(const afm_doc &doc, const std::string &source,
                                          const GltfOptions &options, GltfStats *stats = nullptr);

// gltf_bytes, then an atomic write to `path`.
Status export_gltf(const afm_doc &doc, const std::string &source, const std::string &path,
                   const GltfOptions &options, GltfStats *stats = nullptr);

}  // namespace afmb
