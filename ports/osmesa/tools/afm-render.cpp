// afm-render: plays a FAP stream on an AFM with the fixed-point player and
// renders the frames offscreen (OSMesa) to PNG files and a contact sheet.
#include <afm/fap_stream.h>
#include <afm/format.h>
#include <afm/face_scene.h>
#include <afm/view_options.h>
#include <afm/player.h>
#include <afm/render.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace {

void usage(FILE *out) {
  std::fprintf(out,
      "usage: afm-render MODEL.afm STREAM.fap -o DIR [options]\n"
      "       afm-render MODEL.afm STREAM.fap --sheet FILE.png [options]\n"
      "\n"
      "Plays an MPEG-4 FAP stream on an Animatable Face Model with the fixed-point\n"
      "player and renders each frame offscreen: smooth shading with the player's\n"
      "normals, the AFM's vertex colours when it has them, and each part's texture\n"
      "(TGA or PNG) when the AFM has texture coordinates. Frames are written as\n"
      "DIR/frame_00000.png, frame_00001.png, ... at the stream's rate (or --fps),\n"
      "numbered from the stream's first frame.\n"
      "\n"
      "Output\n"
      "  -o, --output DIR      write the frames here (created when missing; its parent\n"
      "                        must exist)\n"
      "  --size WxH            frame size in pixels, 16..4096 each (default 640x480)\n"
      "  --frames A:B          render frames A to B, both included; A: to the end, :B\n"
      "                        from the start, N one frame (default: all)\n"
      "  --fps N               render at N frames per second (decimals allowed, e.g.\n"
      "                        29.97), resampling the stream: poses in between its\n"
      "                        frames are blended, no frame's values are dropped\n"
      "                        (default: the stream's own rate)\n"
      "  --sheet FILE.png      also write a contact sheet of chosen frames; without -o\n"
      "                        only those frames are rendered\n"
      "  --sheet-frames LIST   frames on the sheet, comma-separated (default: 12 spread\n"
      "                        evenly from the first to the last rendered frame)\n"
      "  --sheet-every N       every Nth rendered frame on the sheet instead\n"
      "  --sheet-columns N     tiles per row (default: up to 6)\n"
      "  --sheet-shrink N      tiles N times smaller than the frames (default 1)\n"
      "\n"
      );
  std::fputs(afm_face::kViewOptionsHelp, out);
  std::fputs(
      "\n"
      "Other\n"
      "  --progress N          a progress line on stderr every N frames (default 25;\n"
      "                        0: none)\n"
      "  --quiet               no progress and no summary\n"
      "  --help                this text\n"
      "\n"
      "Every PNG is written completely or not at all; when a run fails, the frames it\n"
      "wrote are removed. Exit status: 0 on success, 1 on bad input (the message names\n"
      "the file and line, part or field) or a failed write, 2 on bad usage.\n", out);
}

// Exit 2: the command line is wrong. Exit 1: an input is bad or a write failed.
using afm_face::InputError;
using afm_face::UsageError;
using afm_face::lower;
using afm_face::parse_double;
using afm_face::parse_long;
using afm_face::split;

struct Options {
  std::string model, stream, out_dir, sheet;
  afm_face::ViewOptions view;  // --size, camera, look, --mirror
  long first = 0, last = -1;  // -1: to the end
  uint32_t fps_num = 0, fps_den = 1;  // 0: the stream's rate
  std::vector<long> sheet_frames;
  long sheet_every = 0, sheet_columns = 0, sheet_shrink = 1;
  bool quiet = false;
  long progress = 25;
};

Options parse_args(int argc, char **argv, bool *help) {
  Options o;
  *help = false;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char * {
      if (i + 1 >= argc) throw UsageError(a + " needs a value");
      return argv[++i];
    };
    if (afm_face::parse_view_option(a, value, o.view)) {
      continue;
    } else if (a == "--help" || a == "-h") {
      *help = true;
      return o;
    } else if (a == "-o" || a == "--output") {
      o.out_dir = value();
      if (o.out_dir.empty()) throw UsageError(a + ": empty directory name");
    } else if (a == "--frames") {
      const std::string v = value();
      const size_t c = v.find(':');
      if (c == std::string::npos) {
        o.first = o.last = parse_long("--frames (A:B or N)", v.c_str(), 0, 100000000);
      } else {
        const std::string lo = v.substr(0, c), hi = v.substr(c + 1);
        o.first = lo.empty() ? 0 : parse_long("--frames: A (A:B)", lo.c_str(), 0, 100000000);
        o.last = hi.empty() ? -1 : parse_long("--frames: B (A:B)", hi.c_str(), 0, 100000000);
        if (o.last >= 0 && o.last < o.first)
          throw UsageError("--frames " + v + ": the last frame comes before the first");
      }
    } else if (a == "--fps") {
      const double f = parse_double("--fps", value(), 0.01, 1000.0);
      // As a ratio with three decimals: 29.97 -> 29970/1000, reduced.
      uint64_t num = (uint64_t)std::llround(f * 1000.0), den = 1000;
      for (uint64_t g : {2, 2, 2, 5, 5, 5})
        if (num % g == 0 && den % g == 0) num /= g, den /= g;
      if (num == 0) throw UsageError("--fps: must be above 0");
      o.fps_num = (uint32_t)num;
      o.fps_den = (uint32_t)den;
    } else if (a == "--sheet") {
      o.sheet = value();
      if (lower(fs::path(o.sheet).extension().string()) != ".png")
        throw UsageError("--sheet " + o.sheet + ": the contact sheet's name must end in .png");
    } else if (a == "--sheet-frames") {
      const std::string v = value();
      for (const std::string &item : split(v, ','))
        o.sheet_frames.push_back(parse_long("--sheet-frames (comma-separated frame numbers)",
                                            item.c_str(), 0, 100000000));
    } else if (a == "--sheet-every") {
      o.sheet_every = parse_long(a, value(), 1, 100000000);
    } else if (a == "--sheet-columns") {
      o.sheet_columns = parse_long(a, value(), 1, 100);
    } else if (a == "--sheet-shrink") {
      o.sheet_shrink = parse_long(a, value(), 1, 16);
    } else if (a == "--progress") {
      o.progress = parse_long(a, value(), 0, 100000000);
    } else if (a == "--quiet") {
      o.quiet = true;
    } else if (a.size() > 1 && a[0] == '-') {
      throw UsageError("unknown option '" + a + "'");
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() != 2)
    throw UsageError(positional.size() < 2 ? "give a model (.afm) and a FAP stream (.fap)"
                                           : "too many arguments: '" + positional[2] + "'");
  o.model = positional[0];
  o.stream = positional[1];
  if (o.out_dir.empty() && o.sheet.empty())
    throw UsageError("nothing to write: give -o DIR for the frames and/or --sheet FILE.png");
  if (o.sheet.empty() && (!o.sheet_frames.empty() || o.sheet_every || o.sheet_columns || o.sheet_shrink != 1))
    throw UsageError("--sheet-frames, --sheet-every, --sheet-columns and --sheet-shrink need --sheet FILE.png");
  if (!o.sheet_frames.empty() && o.sheet_every)
    throw UsageError("give --sheet-frames or --sheet-every, not both");
  return o;
}

// ---- pictures ------------------------------------------------------------------

std::vector<uint8_t> shrink(const std::vector<uint8_t> &rgba, int w, int h, int s, int *ow, int *oh) {
  *ow = w / s;
  *oh = h / s;
  std::vector<uint8_t> out((size_t)*ow * *oh * 4);
  const unsigned n = (unsigned)(s * s);
  for (int y = 0; y < *oh; ++y)
    for (int x = 0; x < *ow; ++x)
      for (int k = 0; k < 4; ++k) {
        unsigned acc = 0;
        for (int j = 0; j < s; ++j)
          for (int i = 0; i < s; ++i) acc += rgba[(((size_t)(y * s + j) * w) + (size_t)(x * s + i)) * 4 + (size_t)k];
        out[((size_t)y * *ow + (size_t)x) * 4 + (size_t)k] = (uint8_t)((acc + n / 2) / n);
      }
  return out;
}

// Frames written by this run, removed again if the run fails.
struct Written {
  std::vector<std::string> files;
  std::string created_dir;
  bool keep = false;
  ~Written() {
    if (keep) return;
    for (const std::string &f : files) std::remove(f.c_str());
    if (!created_dir.empty()) {
      std::error_code ec;
      fs::remove(created_dir, ec);  // only when empty
    }
  }
};

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

struct Renderer {
  afm_renderer *r = nullptr;
  Renderer() {
    if (afm_renderer_create(&r) != AFM_OK)
      throw InputError(std::string("cannot start the renderer: ") + afm_render_last_error());
  }
  ~Renderer() { afm_renderer_destroy(r); }
};

int run(const Options &o) {
  // ---- the model and the stream
  const afm_face::Doc doc = afm_face::load_model(o.model);
  const afm_geometry &g = doc->geometry;
  const afm_face::Stream stream = afm_face::load_stream(o.stream);
  const uint32_t fps_num = o.fps_num ? o.fps_num : stream.header.fps_num;
  const uint32_t fps_den = o.fps_num ? o.fps_den : stream.header.fps_den;
  if (fps_num == 0 || fps_den == 0) throw InputError(o.stream + ": line 1: the frame rate is 0");

  afm_fap_cursor cursor;
  afm_result res = afm_fap_cursor_init(&cursor, stream.frames.data(), (uint32_t)stream.frames.size(),
                                       stream.header.fps_num, stream.header.fps_den, o.view.mirror);
  if (res != AFM_OK) throw InputError(o.stream + ": cannot play: " + afm_result_string(res));
  const uint64_t duration_us = afm_fap_cursor_duration_us(&cursor);
  // Render frames 0..total-1: every time from 0 to the last frame's.
  uint64_t total = (uint64_t)((double)duration_us * fps_num / (1e6 * fps_den));
  while (total > 0 && afm_face::frame_time_us(total, fps_num, fps_den) > duration_us) --total;
  while (afm_face::frame_time_us(total + 1, fps_num, fps_den) <= duration_us) ++total;
  ++total;
  if (total > 100000000u) throw InputError(o.stream + ": more than 100000000 frames to render");

  // ---- which frames
  const long first = o.first;
  const long last = o.last < 0 ? (long)total - 1 : o.last;
  char rate[64];
  std::snprintf(rate, sizeof rate, "%.6g fps", (double)fps_num / fps_den);
  if (first >= (long)total || last >= (long)total)
    throw UsageError("--frames: " + o.stream + " gives frames 0 to " + std::to_string(total - 1) +
                     " at " + rate + ", not " + std::to_string(first) + " to " + std::to_string(last));
  std::set<long> sheet_set;
  if (!o.sheet.empty()) {
    if (!o.sheet_frames.empty()) {
      for (long f : o.sheet_frames) {
        if (f < first || f > last)
          throw UsageError("--sheet-frames: frame " + std::to_string(f) + " is not rendered (frames " +
                           std::to_string(first) + " to " + std::to_string(last) + ")");
        sheet_set.insert(f);
      }
    } else if (o.sheet_every) {
      for (long f = first; f <= last; f += o.sheet_every) sheet_set.insert(f);
    } else {
      const long n = std::min<long>(12, last - first + 1);
      for (long i = 0; i < n; ++i)
        sheet_set.insert(n == 1 ? first : first + (long)std::llround((double)i * (last - first) / (n - 1)));
    }
  }
  if (sheet_set.size() > 1000)
    throw UsageError("--sheet: " + std::to_string(sheet_set.size()) +
                     " frames is too many for one contact sheet (at most 1000)");
  if (!sheet_set.empty()) {
    const long n = (long)sheet_set.size();
    const long cols = o.sheet_columns ? std::min<long>(o.sheet_columns, n) : std::min<long>(6, n);
    const long rows = (n + cols - 1) / cols;
    const long tw = o.view.width / o.sheet_shrink, th = o.view.height / o.sheet_shrink;
    if (tw < 1 || th < 1) throw UsageError("--sheet-shrink: tiles would be smaller than a pixel");
    if (cols * (tw + 4) + 4 > 65535 || rows * (th + 4) + 4 > 65535)
      throw UsageError("--sheet: " + std::to_string(n) + " tiles of " + std::to_string(tw) + "x" +
                       std::to_string(th) + " make a sheet larger than 65535 pixels; use "
                       "--sheet-shrink, --sheet-columns or fewer frames");
  }
  std::vector<long> to_render;
  if (!o.out_dir.empty())
    for (long f = first; f <= last; ++f) to_render.push_back(f);
  else
    to_render.assign(sheet_set.begin(), sheet_set.end());

  // ---- the model's meshes, textures, player and framing
  afm_face::FaceScene face;
  afm_face::init_face(face, *doc, afm_face::face_options(o.view, o.model));

  // ---- output places, checked before any work
  Written written;
  if (!o.out_dir.empty()) {
    std::error_code ec;
    if (fs::exists(o.out_dir, ec)) {
      if (!fs::is_directory(o.out_dir, ec)) throw InputError(o.out_dir + ": exists and is not a directory");
    } else {
      if (!fs::create_directory(o.out_dir, ec))
        throw InputError(o.out_dir + ": cannot create the directory: " + ec.message());
      written.created_dir = o.out_dir;
    }
  }
  if (!o.sheet.empty()) {
    std::error_code ec;
    fs::path parent = fs::path(o.sheet).parent_path();
    if (!parent.empty() && !fs::is_directory(parent, ec))
      throw InputError(o.sheet + ": the directory " + parent.string() + " does not exist");
  }

  // ---- the camera: framed once on the neutral model (or its face)
  const afm_render_view view = afm_face::make_view(o.view, face, o.view.width, o.view.height);

  if (!o.quiet) {
    std::printf("%s: %zu frames at %lu/%lu fps (%.3f s); rendering %zu frame(s) at %s (%s, frames %ld to %ld)\n",
                o.stream.c_str(), stream.frames.size(), (unsigned long)stream.header.fps_num,
                (unsigned long)stream.header.fps_den, (double)duration_us * 1e-6, to_render.size(),
                rate, o.fps_num ? "resampled" : "the stream's rate", first, last);
    std::printf("%s: %lu vertices, %lu triangles, %lu parts (%zu textured, %zu texture files%s)\n",
                o.model.c_str(), (unsigned long)g.vertex_count, (unsigned long)g.triangle_count,
                (unsigned long)g.part_count, face.textured_parts, face.textures.size(),
                g.rgba ? ", vertex colours" : "");
    std::fflush(stdout);
  }

  // ---- render
  Renderer renderer;
  std::vector<uint8_t> rgba((size_t)o.view.width * o.view.height * 4);
  std::vector<std::vector<uint8_t>> sheet_tiles;
  double t_pose = 0, t_draw = 0, t_png = 0;
  const auto t_start = std::chrono::steady_clock::now();
  size_t done = 0;
  for (long f : to_render) {
    auto t0 = std::chrono::steady_clock::now();
    const afm_fap_state *a = nullptr, *b = nullptr;
    afm_q16 t = 0;
    res = afm_fap_cursor_seek(&cursor, afm_face::frame_time_us((uint64_t)f, fps_num, fps_den), &a, &b, &t);
    if (res == AFM_OK) res = afm_face::pose_face(face, a, b, t);
    if (res != AFM_OK)
      throw InputError("frame " + std::to_string(f) + ": the player fails: " + afm_result_string(res));
    t_pose += ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    if (afm_renderer_draw(renderer.r, face.meshes.data(), face.meshes.size(), &view, rgba.data()) != AFM_OK)
      throw InputError("frame " + std::to_string(f) + ": " + afm_render_last_error());
    t_draw += ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    if (!o.out_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05ld.png", f);
      const std::string path = (fs::path(o.out_dir) / name).string();
      const afm_render_image im = {rgba.data(), o.view.width, o.view.height};
      if (afm_png_write(path.c_str(), &im) != AFM_OK) throw InputError(afm_render_last_error());
      written.files.push_back(path);
    }
    t_png += ms_since(t0);
    if (sheet_set.count(f)) sheet_tiles.push_back(rgba);
    ++done;
    if (!o.quiet && o.progress > 0 && (done % (size_t)o.progress == 0) && done < to_render.size()) {
      const double el = ms_since(t_start);
      std::fprintf(stderr, "afm-render: frame %ld, %zu of %zu (%.0f%%), %.1f ms per frame, %.1f s left\n", f,
                   done, to_render.size(), 100.0 * done / to_render.size(), el / done,
                   el / done * (to_render.size() - done) * 1e-3);
    }
  }

  // ---- the contact sheet
  int sheet_w = 0, sheet_h = 0, columns = 0;
  if (!o.sheet.empty()) {
    std::vector<std::vector<uint8_t>> small;
    std::vector<afm_render_image> tiles;
    int tw = o.view.width, th = o.view.height;
    for (const std::vector<uint8_t> &tile : sheet_tiles) {
      if (o.sheet_shrink > 1) {
        small.push_back(shrink(tile, o.view.width, o.view.height, (int)o.sheet_shrink, &tw, &th));
        tiles.push_back({small.back().data(), tw, th});
      } else {
        tiles.push_back({tile.data(), tw, th});
      }
    }
    columns = (int)(o.sheet_columns ? o.sheet_columns : std::min<size_t>(6, tiles.size()));
    const uint8_t bg[4] = {40, 40, 40, 255};
    if (afm_sheet_size(tiles.data(), (int)tiles.size(), columns, 4, &sheet_w, &sheet_h) != AFM_OK ||
        afm_sheet_write_png(o.sheet.c_str(), tiles.data(), (int)tiles.size(), columns, 4, bg) != AFM_OK)
      throw InputError(std::string(afm_render_last_error()));
  }
  written.keep = true;

  if (!o.quiet) {
    const double n = (double)std::max<size_t>(done, 1);
    if (!o.out_dir.empty())
      std::printf("wrote %zu frame(s) of %dx%d to %s (frame_%05ld.png to frame_%05ld.png)\n", done, o.view.width,
                  o.view.height, o.out_dir.c_str(), first, last);
    if (!o.sheet.empty())
      std::printf("wrote %s: %zu frame(s), %d per row, %dx%d\n", o.sheet.c_str(), sheet_tiles.size(), columns,
                  sheet_w, sheet_h);
    std::printf("time per frame: pose %.2f ms, render %.1f ms, PNG %.1f ms (%dx%d, %dx supersampled)\n",
                t_pose / n, t_draw / n, t_png / n, o.view.width, o.view.height, o.view.aa);
    if (stream.stats.clamped)
      std::printf("note: %s: %lu value(s) outside their FAP's range were clamped\n", o.stream.c_str(),
                  (unsigned long)stream.stats.clamped);
  }
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  return afm_face::run_tool("afm-render", [&] {
    bool help = false;
    const Options o = parse_args(argc, argv, &help);
    if (help) {
      usage(stdout);
      return 0;
    }
    return run(o);
  });
}
