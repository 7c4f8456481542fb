// The command-line options of the tools that show faces (afm-render,
// afm-view): their camera, look and playing options, parsed alike, and the
// number parsers behind them. C++17.
#pragma once

#include <afm/face_scene.h>
#include <afm/render.h>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace afm_face {

// The command line is wrong: the tools exit 2 with its message.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A tool's main: runs `body` and returns its exit status; a UsageError
// prints "NAME: message" and the --help hint and gives 2, an InputError or
// lack of memory prints "NAME: message" and gives 1.
int run_tool(const char *name, const std::function<int()> &body);

// A whole number in lo..hi; UsageError naming `opt` otherwise.
long parse_long(const std::string &opt, const char *s, long lo, long hi);
// A finite number in lo..hi; UsageError naming `opt` otherwise.
double parse_double(const std::string &opt, const char *s, double lo, double hi);
// "a,b,,c" -> {"a", "b", "", "c"}.
std::vector<std::string> split(const std::string &s, char sep);
std::string lower(std::string s);

struct ViewOptions {
  int width = 640, height = 480;  // pixels
  float yaw = 0, pitch = 0, fov = 25;
  int aa = 2;
  uint8_t background[4] = {96, 96, 96, 255};
  bool closeup = false, no_textures = false, flip_v = false;
  std::string textures_dir;
  uint32_t mirror = 0;  // AFM_MIRROR_* flags
};

// When `arg` is one of the shared options (--size, --yaw, --pitch, --fov,
// --aa, --background, --closeup, --textures, --no-textures, --flip-v,
// --mirror), parses it into `o`, taking its value from `value()`, and
// returns true. UsageError for a bad value.
bool parse_view_option(const std::string &arg, const std::function<const char *()> &value,
                       ViewOptions &o);

// The --help lines of those options (Camera and look, Playing).
extern const char *const kViewOptionsHelp;

// What init_face needs from the options.
FaceOptions face_options(const ViewOptions &o, const std::string &model_path);

// The view of width x height framed on the scene's box, with the options'
// camera and look.
afm_render_view make_view(const ViewOptions &o, const FaceScene &scene, int width, int height);

}  // namespace afm_face
