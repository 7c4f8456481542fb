// afm-headgen: writes the procedural reference head, its FDPs and a picture.
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <algorithm>

#include "core/fapu.h"
#include "io/fdp_io.h"
#include "io/mesh_io.h"
#include "io/vrml.h"
#include "refhead/refhead.h"
#include "render/scene_render.h"

using namespace afmb;

namespace {

void usage(FILE *out) {
  std::fprintf(out,
      "usage: afm-headgen [options]\n"
      "\n"
      "Generates the project's reference head: a procedural human head in metres in\n"
      "the MPEG-4 neutral frame (+x the face's own left, +y up, +z gaze), in the\n"
      "neutral state (eyes open, lids tangent to the iris, lips closed, teeth\n"
      "touching). Parts: skin (with a mouth slit and eye openings), eye_left,\n"
      "eye_right, teeth_upper, teeth_lower, tongue, with per-vertex colours. Writes\n"
      "the scene, its full FDP set and optionally a picture, and prints the FAP units.\n"
      "\n"
      "  --vertices N        skin vertex count, 1000..100000 (default 10000; met\n"
      "                      within about 2 %%)\n"
      "  -o, --output FILE   the scene: .wrl/.vrml writes VRML97, .obj writes OBJ\n"
      "                      (default refhead.wrl)\n"
      "  --fdp FILE          the FDP text file (formats/fdp.md), with a fapu line\n"
      "                      (default: the output's name with .fdp)\n"
      "  --render FILE.png   also render a picture: front and three-quarter views\n"
      "  --fdp-dots          draw the FDPs on the picture (red on the skin, green on\n"
      "                      other parts, blue for free points)\n"
      "  --wireframe         draw the skin's triangle edges on the picture\n"
      "  --size WxH          size of each view in pixels (default 600x720)\n"
      "  --views LIST        camera yaw angles in degrees, comma-separated, each\n"
      "                      optionally with :pitch (default 0,40:5: front and\n"
      "                      three-quarter; positive yaw shows the face's left side)\n"
      "  --closeup           frame the face (by its FDPs) rather than the whole head\n"
      "  --help              this text\n"
      "\n"
      "Every file is written completely or not at all. Exit status: 0 on success,\n"
      "1 when generating or writing fails, 2 on bad usage.\n");
}

int usage_error(const std::string &msg) {
  std::fprintf(stderr, "afm-headgen: %s\n(afm-headgen --help lists the options)\n", msg.c_str());
  return 2;
}

int fail(const Status &s) {
  std::fprintf(stderr, "afm-headgen: %s\n", s.message().c_str());
  return 1;
}

std::string lower_ext(const std::string &path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot);
  for (char &c : e) c = (char)std::tolower((unsigned char)c);
  return e;
}

bool parse_int(const char *s, long lo, long hi, long *out) {
  char *end = nullptr;
  errno = 0;
  const long v = std::strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi) return false;
  *out = v;
  return true;
}

}  // namespace

int main(int argc, char **argv) {
  long vertices = 10000;
  std::string out_path = "refhead.wrl", fdp_path, render_path;
  SceneRenderOptions ropt;
  bool dots = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    // The option's value, or nullptr when the command line ends.
    auto value = [&]() -> const char * { return i + 1 < argc ? argv[++i] : nullptr; };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--vertices") {
      const char *v = value();
      if (!v) return usage_error("--vertices needs a number");
      if (!parse_int(v, 1000, 100000, &vertices))
        return usage_error(std::string("--vertices must be a whole number in 1000..100000, got '") +
                           v + "'");
    } else if (a == "-o" || a == "--output") {
      const char *v = value();
      if (!v) return usage_error(a + " needs a file name");
      out_path = v;
    } else if (a == "--fdp") {
      const char *v = value();
      if (!v) return usage_error("--fdp needs a file name");
      fdp_path = v;
    } else if (a == "--render") {
      const char *v = value();
      if (!v) return usage_error("--render needs a file name");
      render_path = v;
    } else if (a == "--fdp-dots") {
      dots = true;
    } else if (a == "--wireframe") {
      ropt.wireframe = true;
    } else if (a == "--size") {
      const char *v = value();
      int w = 0, h = 0;
      char extra = 0;
      if (!v || std::sscanf(v, "%dx%d%c", &w, &h, &extra) != 2 || w < 16 || h < 16 || w > 4096 ||
          h > 4096)
        return usage_error("--size needs WxH with both in 16..4096, e.g. 600x720");
      ropt.width = w;
      ropt.height = h;
    } else if (a == "--views") {
      const char *v = value();
      if (!v) return usage_error("--views needs a list such as 0,40:5,90");
      ropt.views.clear();
      std::string list = v;
      size_t start = 0;
      while (start <= list.size()) {
        const size_t comma = std::min(list.find(',', start), list.size());
        const std::string item = list.substr(start, comma - start);
        SceneView sv;
        char extra = 0;
        const int got = std::sscanf(item.c_str(), "%f:%f%c", &sv.yaw_deg, &sv.pitch_deg, &extra);
        if (item.empty() || got < 1 || got > 2 || std::abs(sv.yaw_deg) > 360 ||
            std::abs(sv.pitch_deg) > 89)
          return usage_error("--views: '" + item +
                             "' is not YAW or YAW:PITCH in degrees (|pitch| < 90)");
        ropt.views.push_back(sv);
        start = comma + 1;
      }
    } else if (a == "--closeup") {
      ropt.face_closeup = true;
    } else {
      return usage_error("unknown argument '" + a + "'");
    }
  }
  const std::string ext = lower_ext(out_path);
  if (ext != ".wrl" && ext != ".vrml" && ext != ".obj")
    return usage_error("cannot tell the format of '" + out_path +
                       "': the output must end in .wrl, .vrml or .obj");
  if (fdp_path.empty()) fdp_path = out_path.substr(0, out_path.size() - ext.size()) + ".fdp";
  if (!render_path.empty() && lower_ext(render_path) != ".png")
    return usage_error("--render writes PNG: the name must end in .png, got '" + render_path + "'");

  const auto t0 = std::chrono::steady_clock::now();
  Expected<RefHead> head = make_reference_head(RefHeadOptions{(int)vertices});
  if (!head) return fail(head.status());
  const double gen_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  std::string notes;
  Expected<Fapu> fapu = compute_fapu(head->fdps, &notes);
  if (!fapu) return fail(fapu.status().wrap("reference head FAPU"));

  Status st = ext == ".obj" ? write_obj(head->scene, out_path) : write_vrml(head->scene, out_path);
  if (!st) return fail(st);
  st = write_fdp_text(head->fdps, head->scene, fdp_path, &*fapu);
  if (!st) return fail(st);
  if (!render_path.empty()) {
    // The close-up frames the face by its FDPs, drawn or not.
    SceneRenderOptions r = ropt;
    if (!dots) r.fdp_dot_pixels = 0.0f;
    st = render_scene_png(head->scene, &head->fdps, r, render_path);
    if (!st) return fail(st);
  }

  const Part &skin = head->scene.parts[head->scene.find_kind(PartKind::Skin)];
  std::printf("reference head: %lld skin vertices (target %ld), %lld triangles, %zu vertices in all, "
              "%zu FDPs, generated in %.0f ms\n",
              (long long)skin.V.rows(), vertices, (long long)skin.F.rows(),
              head->scene.vertex_count(), head->fdps.points.size(), gen_ms);
  std::printf("FAPU (m): ES0 %.5f  IRISD0 %.5f  ENS0 %.5f  MNS0 %.5f  MW0 %.5f\n", fapu->es0,
              fapu->irisd0, fapu->ens0, fapu->mns0, fapu->mw0);
  std::printf("wrote %s, %s%s%s\n", out_path.c_str(), fdp_path.c_str(),
              render_path.empty() ? "" : ", ", render_path.c_str());
  return 0;
}
