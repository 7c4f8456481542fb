// An AFM ready to draw, for the tools that show faces: afm-render (OSMesa,
// PNG frames) and afm-view (ports/glfw, a window). C++17 over the C99
// reader, player and render types.
//
//   load_model, load_stream   files -> decoded AFM, parsed FAP stream
//   FaceScene                 the player, one afm_render_mesh per part over
//                             shared vertex arrays, textures, framing box
//   pose_face                 a FAP state (or two blended) -> the arrays
//
// Errors: InputError, whose message names the file and the line, part or
// field ("head.afm: part skin: texture 'skin.tga' is not in ...").
#pragma once

#include <afm/format.h>
#include <afm/image.h>
#include <afm/player.h>
#include <afm/render.h>

#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace afm_face {

// An input that cannot be used: a file that cannot be read or parsed, a
// missing texture. The tools exit 1 with its message.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct DocFree {
  void operator()(afm_doc *d) const { afm_free(nullptr, d); }
};
using Doc = std::unique_ptr<afm_doc, DocFree>;

// The whole file; a directory or unreadable file is an InputError.
std::vector<uint8_t> read_whole(const std::string &path);

// Reads an AFM (raw or draco profile). The model must have triangles.
Doc load_model(const std::string &path);

struct Stream {
  afm_fap_header header{};
  afm_fap_stats stats{};
  std::vector<afm_fap_frame> frames;  // at least one
};

// Parses an ASCII FAP stream; errors name the file and line ("x.fap:4: ...").
Stream load_stream(const std::string &path);

// Microseconds from frame 0 to render frame k at num/den frames per second,
// rounded down exactly as afm_fap_cursor times the stream's own frames.
uint64_t frame_time_us(uint64_t k, uint32_t num, uint32_t den);

struct FaceOptions {
  std::string model_path;    // names the model in messages; textures are looked for beside it
  std::string textures_dir;  // looked in first when not empty (must be a directory)
  bool no_textures = false;  // ignore the parts' textures
  bool flip_v = false;       // v becomes 1 - v (images stored the other way up)
  bool closeup = false;      // frame the face (its FDPs without ears and skull)
};

struct Texture {
  afm_image image{};
  afm_render_image view{};
  Texture() = default;
  Texture(const Texture &) = delete;
  Texture &operator=(const Texture &) = delete;
  ~Texture() { afm_image_free(&image); }
};

// A model with its player and meshes. Not copyable: the meshes point into the
// arrays. `doc` must outlive it.
struct FaceScene {
  const afm_doc *doc = nullptr;
  afm_player *player = nullptr;
  std::vector<float> positions;  // #V x 3, model units, the last pose
  std::vector<float> normals;    // #V x 3, unit
  std::vector<float> uvs;        // #V x 2, or empty
  std::vector<afm_render_mesh> meshes;  // one per part with triangles
  std::map<std::string, std::unique_ptr<Texture>> textures;  // by file path
  size_t textured_parts = 0;
  float box_min[3] = {0, 0, 0}, box_max[3] = {0, 0, 0};  // framing box of the neutral model

  FaceScene() = default;
  FaceScene(const FaceScene &) = delete;
  FaceScene &operator=(const FaceScene &) = delete;
  ~FaceScene() { std::free(player_memory); }
  void *player_memory = nullptr;
};

// Loads the textures, builds the player and the meshes, frames the neutral
// model (or its face) and poses it neutral. InputError when a texture is
// missing or unreadable, or the player cannot play the model.
void init_face(FaceScene &scene, const afm_doc &doc, const FaceOptions &options);

// Poses the face for state a blended toward b by t (afm_player_pose) and
// fills positions and normals. Returns the player's result.
afm_result pose_face(FaceScene &scene, const afm_fap_state *a, const afm_fap_state *b, afm_q16 t);

}  // namespace afm_face
