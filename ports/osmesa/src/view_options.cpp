// The shared options of afm-render and afm-view. See afm/view_options.h.
#include "afm/view_options.h"

#include <afm/player.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>

namespace afm_face {

std::string lower(std::string s) {
  for (char &c : s) c = (char)std::tolower((unsigned char)c);
  return s;
}

int run_tool(const char *name, const std::function<int()> &body) {
  try {
    return body();
  } catch (const UsageError &e) {
    std::fprintf(stderr, "%s: %s\n(%s --help lists the options)\n", name, e.what(), name);
    return 2;
  } catch (const InputError &e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 1;
  } catch (const std::bad_alloc &) {
    std::fprintf(stderr, "%s: out of memory\n", name);
    return 1;
  }
}

long parse_long(const std::string &opt, const char *s, long lo, long hi) {
  char *end = nullptr;
  errno = 0;
  const long v = std::strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi)
    throw UsageError(opt + ": expected a whole number from " + std::to_string(lo) + " to " +
                     std::to_string(hi) + ", got '" + s + "'");
  return v;
}

double parse_double(const std::string &opt, const char *s, double lo, double hi) {
  char *end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  if (errno || end == s || *end || !std::isfinite(v) || v < lo || v > hi) {
    char buf[160];
    std::snprintf(buf, sizeof buf, ": expected a number from %g to %g, got '", lo, hi);
    throw UsageError(opt + buf + s + "'");
  }
  return v;
}

std::vector<std::string> split(const std::string &s, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  for (;;) {
    const size_t p = s.find(sep, start);
    out.push_back(s.substr(start, p == std::string::npos ? std::string::npos : p - start));
    if (p == std::string::npos) break;
    start = p + 1;
  }
  return out;
}

const char *const kViewOptionsHelp =
    "Camera and look\n"
    "  --yaw DEG             turn the camera toward the face's left (+) or right (-)\n"
    "  --pitch DEG           raise the camera (+) and look down\n"
    "  --closeup             frame the face (its FDPs, without ears and hair)\n"
    "                        instead of the whole neutral model\n"
    "  --fov DEG             vertical field of view, 5..90 (default 25); 0 draws\n"
    "                        an orthographic view\n"
    "  --aa N                supersampling, 1..4 (default 2)\n"
    "  --background R,G,B    background colour, 0..255 each (default 96,96,96)\n"
    "  --textures DIR        look for texture files here first, then beside MODEL\n"
    "  --no-textures         ignore textures: diffuse or vertex colours only\n"
    "  --flip-v              turn textures upside down (v becomes 1 - v): for AFMs\n"
    "                        made elsewhere from models whose images are stored the\n"
    "                        other way up from what their texture coordinates expect\n"
    "                        (VRML: v = 0 is the image's bottom row), such as Song's\n"
    "                        TGA files. Not for an AFM made with afm-import's or\n"
    "                        afm-build's --flip-v: it already stores v the right way,\n"
    "                        and flipping again scrambles the texture\n"
    "\n"
    "The camera is framed once, on the neutral model's bounding box (or its face\n"
    "with --closeup), so every frame of a run, and runs with the same options, are\n"
    "directly comparable.\n"
    "\n"
    "Playing\n"
    "  --mirror LIST         copy one-sided FAPs to the other side: lr (left/right),\n"
    "                        io (inner/outer lip) or lr,io; off by default\n";

bool parse_view_option(const std::string &a, const std::function<const char *()> &value,
                       ViewOptions &o) {
  if (a == "--size") {
    const std::string v = value();
    const size_t x = v.find_first_of("xX");
    if (x == std::string::npos) throw UsageError("--size: expected WxH (e.g. 640x480), got '" + v + "'");
    o.width = (int)parse_long("--size: width (WxH)", v.substr(0, x).c_str(), 16, 4096);
    o.height = (int)parse_long("--size: height (WxH)", v.substr(x + 1).c_str(), 16, 4096);
  } else if (a == "--yaw") {
    o.yaw = (float)parse_double(a, value(), -360, 360);
  } else if (a == "--pitch") {
    o.pitch = (float)parse_double(a, value(), -89, 89);
  } else if (a == "--fov") {
    o.fov = (float)parse_double(a, value(), 0, 90);
    if (o.fov > 0 && o.fov < 5) throw UsageError("--fov: 0 (orthographic) or 5..90 degrees");
  } else if (a == "--closeup") {
    o.closeup = true;
  } else if (a == "--aa") {
    o.aa = (int)parse_long(a, value(), 1, 4);
  } else if (a == "--background") {
    const std::string v = value();
    const std::vector<std::string> parts = split(v, ',');
    if (parts.size() != 3) throw UsageError("--background: expected R,G,B (0..255 each), got '" + v + "'");
    for (int k = 0; k < 3; ++k)
      o.background[k] = (uint8_t)parse_long("--background (R,G,B)", parts[(size_t)k].c_str(), 0, 255);
  } else if (a == "--textures") {
    o.textures_dir = value();
  } else if (a == "--no-textures") {
    o.no_textures = true;
  } else if (a == "--flip-v") {
    o.flip_v = true;
  } else if (a == "--mirror") {
    const std::string m = value();
    if (m == "lr") o.mirror = AFM_MIRROR_LEFT_RIGHT;
    else if (m == "io") o.mirror = AFM_MIRROR_INNER_OUTER;
    else if (m == "lr,io" || m == "io,lr") o.mirror = AFM_MIRROR_LEFT_RIGHT | AFM_MIRROR_INNER_OUTER;
    else throw UsageError("--mirror '" + m + "': use lr, io or lr,io");
  } else {
    return false;
  }
  return true;
}

FaceOptions face_options(const ViewOptions &o, const std::string &model_path) {
  FaceOptions fo;
  fo.model_path = model_path;
  fo.textures_dir = o.textures_dir;
  fo.no_textures = o.no_textures;
  fo.flip_v = o.flip_v;
  fo.closeup = o.closeup;
  return fo;
}

afm_render_view make_view(const ViewOptions &o, const FaceScene &scene, int width, int height) {
  afm_render_view view;
  afm_render_view_init(&view, width, height);
  view.yaw_deg = o.yaw;
  view.pitch_deg = o.pitch;
  view.fov_deg = o.fov;
  view.supersample = o.aa;
  std::memcpy(view.background, o.background, 4);
  for (int k = 0; k < 3; ++k) view.box_min[k] = scene.box_min[k], view.box_max[k] = scene.box_max[k];
  return view;
}

}  // namespace afm_face
