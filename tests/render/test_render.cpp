// afm-render end to end, and the image readers of ports/osmesa.
//
//   Golden*      the reference head posed by a synthetic stream written here
//                (neutral, smile, jaw open, blink, head turn, the joy
//                expression) and by a real xface stream, against committed
//                pictures in tests/data/golden/render/, within tolerances.
//   Properties*  what must hold whatever the pictures look like: framing and
//                coverage, left/right symmetry, a jaw-open frame differing
//                from neutral at the mouth and not on the forehead (regions
//                found by projecting the AFM's FDPs here, independently of
//                the renderer), determinism and resampling.
//   Song*        the textured Song head (shared data): textured, not blank,
//                texture the right way up.
//   Tga*, Png*   the readers against images encoded here.
//
// Goldens: regenerate after an intended change to the reference head, the
// analytic targets, the player or the renderer with
//   AFM_UPDATE_GOLDEN=1 AFM_BUILD=build build/tests/test_render --gtest_filter='Golden*'
// (tests/data/golden/README.md), look at the new pictures, and commit them.
#include <afm/format.h>
#include <afm/image.h>
#include <afm/render.h>
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../common/test_paths.h"

namespace fs = std::filesystem;

namespace {

// ---- running the tools -----------------------------------------------------------

std::string build_dir() {
  const char *b = std::getenv("AFM_BUILD");
  fs::path p = b ? b : "build";
  if (p.is_relative()) p = fs::path(afmtest::source_dir()) / p;
  return p.lexically_normal().string();
}

std::string tool(const std::string &name) { return build_dir() + "/bin/" + name; }

std::string quote(const std::string &s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs a command line with stdout and stderr into `log`; returns the exit status.
int run(const std::string &command, const std::string &log) {
  const int st = std::system((command + " >" + quote(log) + " 2>&1").c_str());
  if (st == -1 || !WIFEXITED(st)) return -1;
  return WEXITSTATUS(st);
}

std::string last_lines(const std::string &log) {
  std::string s = afmtest::read_file(log);
  if (s.size() > 2000) s = "..." + s.substr(s.size() - 2000);
  return s;
}

// ---- pictures --------------------------------------------------------------------

struct Image {
  int w = 0, h = 0;
  std::vector<uint8_t> px;  // RGBA, top row first
  const uint8_t *at(int x, int y) const { return &px[((size_t)y * w + x) * 4]; }
};

Image load_png(const std::string &path) {
  afm_image im{};
  Image out;
  if (afm_png_read(path.c_str(), &im) != AFM_OK) {
    ADD_FAILURE() << afm_render_last_error();
    return out;
  }
  out.w = im.width;
  out.h = im.height;
  out.px.assign(im.rgba, im.rgba + (size_t)im.width * im.height * 4);
  afm_image_free(&im);
  return out;
}

int channel_diff(const uint8_t *a, const uint8_t *b) {
  int m = 0;
  for (int k = 0; k < 4; ++k) m = std::max(m, std::abs(a[k] - b[k]));
  return m;
}

// Golden comparison. OSMesa's rasteriser is exact for edges (fixed-point rules),
// but shading is float arithmetic that llvmpipe compiles for the CPU at hand
// (SSE, AVX2, AVX-512; LLVM versions) and softpipe computes differently: a
// few counts here and there, and an edge pixel where a silhouette passes
// exactly through a sample. llvmpipe against softpipe on this machine differ
// in 0.02 % of the pixels, by at most 8. So a pixel "differs" when a channel is
// off by more than 24, and a picture matches when at most 0.25 % of its pixels
// differ and the mean difference stays under 1 count. The smallest pose
// change in the set (a blink at 160x200) moves about 0.5 % of the pixels by
// more than 24; GoldenSet.ToleranceSeesEveryPose checks that each golden is
// outside the tolerance of the neutral one, so the bound stays meaningful.
constexpr int kPixelTolerance = 24;
constexpr double kMaxDifferingFraction = 0.0025;
constexpr double kMaxMeanDifference = 1.0;

struct Diff {
  double differing = 1;  // fraction of pixels off by more than kPixelTolerance
  double mean = 255;     // mean absolute difference per channel
  bool same_size = false;
  bool matches() const {
    return same_size && differing <= kMaxDifferingFraction && mean <= kMaxMeanDifference;
  }
};

Diff compare(const Image &a, const Image &b) {
  Diff d;
  if (a.w != b.w || a.h != b.h || a.px.empty()) return d;
  d.same_size = true;
  size_t n = (size_t)a.w * a.h, off = 0;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t *p = &a.px[i * 4], *q = &b.px[i * 4];
    for (int k = 0; k < 4; ++k) sum += std::abs(p[k] - q[k]);
    if (channel_diff(p, q) > kPixelTolerance) ++off;
  }
  d.differing = (double)off / n;
  d.mean = sum / (4.0 * n);
  return d;
}

// |a - b| amplified 4x, for a person to look at when a comparison fails.
void write_diff(const Image &a, const Image &b, const std::string &path) {
  if (a.w != b.w || a.h != b.h) return;
  std::vector<uint8_t> d(a.px.size());
  for (size_t i = 0; i < a.px.size(); i += 4) {
    for (int k = 0; k < 3; ++k) d[i + k] = (uint8_t)std::min(255, 4 * std::abs(a.px[i + k] - b.px[i + k]));
    d[i + 3] = 255;
  }
  const afm_render_image im{d.data(), a.w, a.h};
  afm_png_write(path.c_str(), &im);
}

std::string golden_dir() { return afmtest::source_dir() + "/tests/data/golden/render"; }

bool updating_goldens() {
  const char *u = std::getenv("AFM_UPDATE_GOLDEN");
  return u && *u && std::strcmp(u, "0") != 0;
}

// Compares a rendered picture with tests/data/golden/render/<name>.png, or
// replaces the golden when AFM_UPDATE_GOLDEN is set.
void expect_golden(const std::string &rendered, const std::string &name) {
  const std::string golden = golden_dir() + "/" + name + ".png";
  if (updating_goldens()) {
    fs::create_directories(golden_dir());
    fs::copy_file(rendered, golden, fs::copy_options::overwrite_existing);
    std::printf("updated %s\n", golden.c_str());
    return;
  }
  if (!fs::exists(golden)) {
    ADD_FAILURE() << golden << " is missing: regenerate the goldens (tests/data/golden/README.md)";
    return;
  }
  const Image got = load_png(rendered), want = load_png(golden);
  const Diff d = compare(got, want);
  if (!d.matches()) {
    const std::string diff_path = rendered.substr(0, rendered.size() - 4) + "-diff.png";
    write_diff(got, want, diff_path);
    ADD_FAILURE() << name << ": " << rendered << " differs from " << golden << ": "
                  << (d.same_size ? "" : "sizes differ; ") << 100 * d.differing
                  << " % of the pixels off by more than " << kPixelTolerance << " (at most "
                  << 100 * kMaxDifferingFraction << " %), mean difference " << d.mean << " (at most "
                  << kMaxMeanDifference << "); |difference| x4 in " << diff_path;
  }
}

// ---- the synthetic stream ---------------------------------------------------------

struct Pose {
  std::string name;
  std::map<int, int> fap;  // low-level FAP -> value
  int expression = 0, intensity = 0;
};

const std::vector<Pose> &poses() {
  static const std::vector<Pose> p = {
      {"neutral", {}, 0, 0},
      // Lip corners up and out, inner and outer contours.
      {"smile", {{12, 400}, {13, 400}, {59, 400}, {60, 400}, {6, 200}, {7, 200}, {53, 200}, {54, 200}}, 0, 0},
      {"jaw_open", {{3, 700}}, 0, 0},
      // Upper lids down by one IRISD, lower lids up a little.
      {"blink", {{19, 1024}, {20, 1024}, {21, 300}, {22, 300}}, 0, 0},
      // Head yaw 0.3 rad toward the face's left.
      {"head_turn", {{49, 30000}}, 0, 0},
      // FAP 2: expression 1 (joy) at full intensity.
      {"joy", {}, 1, 63},
  };
  return p;
}

int pose_index(const std::string &name) {
  for (size_t i = 0; i < poses().size(); ++i)
    if (poses()[i].name == name) return (int)i;
  return -1;
}

// One frame per pose at 25 fps. Every frame sends FAP 2 and every FAP 3..68,
// so each is a complete pose, whatever came before.
std::string stream_text() {
  std::ostringstream s;
  s << "2.1 afm-render-test 25 " << poses().size() << "\n";
  for (size_t f = 0; f < poses().size(); ++f) {
    const Pose &p = poses()[f];
    s << "# " << p.name << "\n0 1";
    for (int i = 3; i <= 68; ++i) s << " 1";
    s << "\n" << f << " " << p.expression << " " << p.intensity << " 0 0 0 0";
    for (int i = 3; i <= 68; ++i) {
      auto it = p.fap.find(i);
      s << " " << (it == p.fap.end() ? 0 : it->second);
    }
    s << "\n";
  }
  return s.str();
}

void write_text(const std::string &path, const std::string &text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The reference head (3000 skin vertices, analytic targets) and the stream,
// made once per test binary.
struct Fixture {
  std::string dir, afm, fap;
  bool ok = false;
  std::string error;
};

const Fixture &fixture() {
  static Fixture f = [] {
    Fixture x;
    x.dir = afmtest::temp_dir("render");
    const std::string wrl = x.dir + "/head.wrl", fdp = x.dir + "/head.fdp";
    x.afm = x.dir + "/head.afm";
    x.fap = x.dir + "/poses.fap";
    write_text(x.fap, stream_text());
    const std::string log = x.dir + "/setup.log";
    if (run(quote(tool("afm-headgen")) + " --vertices 3000 -o " + quote(wrl) + " --fdp " + quote(fdp), log) != 0 ||
        run(quote(tool("afm-import")) + " " + quote(wrl) + " " + quote(fdp) + " -o " + quote(x.afm) + " --analytic",
            log) != 0) {
      x.error = "making the reference head failed:\n" + last_lines(log);
      return x;
    }
    x.ok = true;
    return x;
  }();
  return f;
}

#define REQUIRE_FIXTURE()                                 \
  const Fixture &fx = fixture();                          \
  ASSERT_TRUE(fx.ok) << fx.error

// Renders with afm-render; returns the output directory (frames in it).
std::string render(const std::string &name, const std::string &model, const std::string &stream,
                   const std::string &options) {
  const std::string out = fixture().dir + "/" + name;
  fs::remove_all(out);
  const std::string log = fixture().dir + "/" + name + ".log";
  const int st = run(quote(tool("afm-render")) + " " + quote(model) + " " + quote(stream) + " -o " + quote(out) +
                         " --quiet " + options,
                     log);
  EXPECT_EQ(st, 0) << "afm-render " << options << ":\n" << last_lines(log);
  return out;
}

std::string frame_path(const std::string &dir, int k) {
  char name[32];
  std::snprintf(name, sizeof name, "/frame_%05d.png", k);
  return dir + name;
}

// ---- goldens ----------------------------------------------------------------------

// The options every golden of the reference head is rendered with.
const char *const kGoldenOptions = "--size 160x200 --closeup";

TEST(GoldenSet, SyntheticPoses) {
  REQUIRE_FIXTURE();
  const std::string out = render("golden-poses", fx.afm, fx.fap, kGoldenOptions);
  for (size_t i = 0; i < poses().size(); ++i) {
    SCOPED_TRACE(poses()[i].name);
    expect_golden(frame_path(out, (int)i), "refhead_" + poses()[i].name);
  }
}

// Every golden must be outside the tolerance of the neutral one: a render
// that lost the smile, the blink or the jaw would fail.
TEST(GoldenSet, ToleranceSeesEveryPose) {
  if (updating_goldens()) GTEST_SKIP() << "updating the goldens";
  const Image neutral = load_png(golden_dir() + "/refhead_neutral.png");
  ASSERT_GT(neutral.w, 0);
  for (size_t i = 1; i < poses().size(); ++i) {
    const Image g = load_png(golden_dir() + "/refhead_" + poses()[i].name + ".png");
    const Diff d = compare(neutral, g);
    EXPECT_FALSE(d.matches()) << poses()[i].name << " is within the tolerance of neutral: "
                              << 100 * d.differing << " % differing, mean " << d.mean;
    EXPECT_GT(d.differing, 1.5 * kMaxDifferingFraction) << poses()[i].name << ": too close to neutral";
  }
}

// A real stream: frames 0, 40 and 80 of xface's joy.fap on a contact sheet.
TEST(GoldenSet, XfaceJoySheet) {
  AFM_REQUIRE_SHARED_DATA();
  REQUIRE_FIXTURE();
  const std::string sheet = fx.dir + "/xface-joy-sheet.png", log = fx.dir + "/xface-joy.log";
  ASSERT_EQ(run(quote(tool("afm-render")) + " " + quote(fx.afm) + " " +
                    quote(afmtest::shared_data("fap/xface/joy.fap")) + " --sheet " + quote(sheet) +
                    " --sheet-frames 0,40,80 --quiet " + kGoldenOptions,
                log),
            0)
      << last_lines(log);
  expect_golden(sheet, "refhead_xface_joy_0_40_80");
}

// ---- properties --------------------------------------------------------------------

constexpr uint8_t kBg[3] = {0, 255, 0};  // a background no face pixel has
const char *const kBgOption = " --background 0,255,0";

bool is_bg(const uint8_t *p) { return p[0] == kBg[0] && p[1] == kBg[1] && p[2] == kBg[2]; }

struct Mask {
  int w = 0, h = 0;
  std::vector<uint8_t> on;
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  size_t count = 0;
  bool at(int x, int y) const { return on[(size_t)y * w + x] != 0; }
};

Mask face_mask(const Image &im) {
  Mask m;
  m.w = im.w;
  m.h = im.h;
  m.on.assign((size_t)im.w * im.h, 0);
  for (int y = 0; y < im.h; ++y)
    for (int x = 0; x < im.w; ++x)
      if (!is_bg(im.at(x, y))) {
        m.on[(size_t)y * im.w + x] = 1;
        ++m.count;
        m.x0 = std::min(m.x0, x), m.x1 = std::max(m.x1, x);
        m.y0 = std::min(m.y0, y), m.y1 = std::max(m.y1, y);
      }
  return m;
}

// Intersection over union of mask `m` and the left/right mirror image of
// `n` (of the same size).
double mirror_iou(const Mask &m, const Mask &n) {
  size_t inter = 0, uni = 0;
  for (int y = 0; y < m.h; ++y)
    for (int x = 0; x < m.w; ++x) {
      const bool a = m.at(x, y), b = n.at(m.w - 1 - x, y);
      inter += a && b;
      uni += a || b;
    }
  return uni ? (double)inter / uni : 0;
}

// The same of a mask and its own mirror image: 1 for a symmetric outline.
double mirror_iou(const Mask &m) { return mirror_iou(m, m); }

TEST(Properties, NeutralIsFramedAndCoversSensibleFraction) {
  REQUIRE_FIXTURE();
  const std::string out = render("prop-neutral", fx.afm, fx.fap, std::string("--size 240x300 --frames 0") + kBgOption);
  const Image im = load_png(frame_path(out, 0));
  ASSERT_EQ(im.w, 240);
  ASSERT_EQ(im.h, 300);
  const Mask m = face_mask(im);
  const double cover = (double)m.count / (im.w * im.h);
  EXPECT_GT(cover, 0.15) << "the head covers too little of the picture";
  EXPECT_LT(cover, 0.70) << "the head covers too much of the picture";
  // Framed on the neutral model with a 6 % margin: inside the picture, centred,
  // and filling it in the tighter direction.
  EXPECT_GT(m.x0, 2);
  EXPECT_GT(m.y0, 2);
  EXPECT_LT(m.x1, im.w - 3);
  EXPECT_LT(m.y1, im.h - 3);
  EXPECT_NEAR((m.x0 + m.x1) / 2.0, im.w / 2.0, 2.5);
  EXPECT_GT(std::max((double)(m.x1 - m.x0 + 1) / im.w, (double)(m.y1 - m.y0 + 1) / im.h), 0.75);
}

TEST(Properties, NeutralIsSymmetricAndCameraTurnsMirror) {
  REQUIRE_FIXTURE();
  std::string opts = std::string("--size 240x300") + kBgOption;
  const std::string front = render("prop-sym", fx.afm, fx.fap, opts + " --frames 0");
  const Mask neutral = face_mask(load_png(frame_path(front, 0)));
  EXPECT_GT(mirror_iou(neutral), 0.985) << "the neutral head's outline is not symmetric";
  // The head turned by FAP 49 is not: the check can fail.
  const std::string turned = render("prop-sym-turn", fx.afm, fx.fap, opts + " --frames " +
                                                                          std::to_string(pose_index("head_turn")));
  EXPECT_LT(mirror_iou(face_mask(load_png(frame_path(turned, pose_index("head_turn"))))), 0.97);
  // Cameras at +30 and -30 degrees see mirror images of a symmetric head.
  const std::string left = render("prop-yaw-left", fx.afm, fx.fap, opts + " --frames 0 --yaw 30");
  const std::string right = render("prop-yaw-right", fx.afm, fx.fap, opts + " --frames 0 --yaw -30");
  const Mask l = face_mask(load_png(frame_path(left, 0))), r = face_mask(load_png(frame_path(right, 0)));
  ASSERT_EQ(l.w, r.w);
  ASSERT_EQ(l.h, r.h);
  EXPECT_GT(mirror_iou(l, r), 0.985) << "yaw +30 and -30 are not mirror images";
  EXPECT_LT(mirror_iou(l), 0.95) << "a 30 degree view looks like a front view";
}

// Reads the AFM back: the neutral box and the FDPs, to find picture regions.
struct ModelInfo {
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  std::map<std::string, std::array<float, 3>> fdp;  // "8.1" -> position
};

ModelInfo model_info(const std::string &path) {
  ModelInfo info;
  uint8_t *data = nullptr;
  size_t size = 0;
  afm_doc *doc = nullptr;
  afm_read_options ro{};
  if (afm_file_read(path.c_str(), nullptr, &data, &size) != AFM_OK ||
      afm_doc_read_alloc(data, size, &ro, nullptr, &doc) != AFM_OK) {
    ADD_FAILURE() << "cannot read " << path;
    afm_free(nullptr, data);
    return info;
  }
  const afm_geometry &g = doc->geometry;
  const int16_t *q[3] = {g.px, g.py, g.pz};
  for (uint32_t v = 0; v < g.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) {
      const float x = (float)(g.origin[k] + (double)q[k][v] * g.step);
      info.lo[k] = std::min(info.lo[k], x);
      info.hi[k] = std::max(info.hi[k], x);
    }
  for (uint32_t i = 0; i < doc->meta.fdp_count; ++i) {
    const afm_fdp_point &p = doc->meta.fdps[i];
    info.fdp[std::to_string(p.group) + "." + std::to_string(p.index)] = {p.pos[0], p.pos[1], p.pos[2]};
  }
  afm_free(nullptr, doc);
  afm_free(nullptr, data);
  return info;
}

// Where a model point lands in a W x H front orthographic picture (--fov 0)
// framed on the box [lo, hi] with the default 6 % margin: the box's centre in
// the middle, its larger half-extent (against the aspect) filling 88 %.
struct Ortho {
  double cx, cy, half_h, aspect;
  int w, h;
  Ortho(const ModelInfo &m, int W, int H) : w(W), h(H) {
    cx = 0.5 * (m.lo[0] + m.hi[0]);
    cy = 0.5 * (m.lo[1] + m.hi[1]);
    aspect = (double)W / H;
    const double fill = 0.88, ex = 0.5 * (m.hi[0] - m.lo[0]), ey = 0.5 * (m.hi[1] - m.lo[1]);
    half_h = std::max(ey / fill, ex / fill / aspect);
  }
  double px(double x) const { return w / 2.0 + (x - cx) / (half_h * aspect) * (w / 2.0); }
  double py(double y) const { return h / 2.0 - (y - cy) / half_h * (h / 2.0); }
};

struct Box {
  int x0, y0, x1, y1;  // inclusive
};

// The box around some FDPs, grown by `pad` pixels.
Box fdp_box(const ModelInfo &m, const Ortho &o, const std::vector<std::string> &names, int pad) {
  Box b{1 << 30, 1 << 30, -(1 << 30), -(1 << 30)};
  for (const std::string &n : names) {
    auto it = m.fdp.find(n);
    if (it == m.fdp.end()) {
      ADD_FAILURE() << "the model has no FDP " << n;
      continue;
    }
    const int x = (int)std::lround(o.px(it->second[0])), y = (int)std::lround(o.py(it->second[1]));
    b.x0 = std::min(b.x0, x - pad), b.x1 = std::max(b.x1, x + pad);
    b.y0 = std::min(b.y0, y - pad), b.y1 = std::max(b.y1, y + pad);
  }
  return b;
}

// Fraction of a box's pixels that differ between two pictures.
double changed(const Image &a, const Image &b, const Box &box) {
  size_t n = 0, off = 0;
  for (int y = std::max(0, box.y0); y <= std::min(a.h - 1, box.y1); ++y)
    for (int x = std::max(0, box.x0); x <= std::min(a.w - 1, box.x1); ++x) {
      ++n;
      off += channel_diff(a.at(x, y), b.at(x, y)) > kPixelTolerance;
    }
  return n ? (double)off / n : 0;
}

TEST(Properties, JawOpenChangesTheMouthNotTheForehead) {
  REQUIRE_FIXTURE();
  const ModelInfo info = model_info(fx.afm);
  const int W = 240, H = 300, jaw = pose_index("jaw_open");
  const std::string out = render("prop-jaw", fx.afm, fx.fap,
                                 "--size 240x300 --fov 0 --frames 0:" + std::to_string(jaw) + kBgOption);
  const Image neutral = load_png(frame_path(out, 0)), open = load_png(frame_path(out, jaw));
  const Ortho o(info, W, H);
  // The projection is right: the nose tip, the eyes and the lips are on the head.
  const Mask m = face_mask(neutral);
  for (const char *n : {"9.3", "3.5", "3.6", "8.1", "2.1", "4.1"}) {
    auto it = info.fdp.find(n);
    ASSERT_NE(it, info.fdp.end()) << n;
    const int x = (int)std::lround(o.px(it->second[0])), y = (int)std::lround(o.py(it->second[1]));
    ASSERT_TRUE(x >= 0 && x < W && y >= 0 && y < H && m.at(x, y)) << "FDP " << n << " projects to " << x << ","
                                                                   << y << ", off the head";
  }
  // Mouth: the lips' FDPs (corners, mid-lips) and the chin. Forehead: from above
  // the eyebrows to the hairline's middle (11.1), between the outer brows.
  const Box mouth = fdp_box(info, o, {"8.1", "8.2", "8.3", "8.4", "2.2", "2.3"}, 2);
  Box forehead = fdp_box(info, o, {"4.5", "4.6", "11.1"}, 0);
  forehead.y1 = (int)std::lround(o.py(std::max(info.fdp.at("4.3")[1], info.fdp.at("4.4")[1]))) - 4;
  ASSERT_GT(forehead.y1 - forehead.y0, 5) << "the forehead box is empty";
  const double at_mouth = changed(neutral, open, mouth), at_forehead = changed(neutral, open, forehead);
  EXPECT_GT(at_mouth, 0.25) << "opening the jaw barely changes the mouth";
  EXPECT_LT(at_forehead, 0.005) << "opening the jaw changes the forehead";
  // The smile too changes the mouth and not the forehead.
  const Image smile = load_png(frame_path(out, pose_index("smile")));
  EXPECT_GT(changed(neutral, smile, mouth), 0.05);
  EXPECT_LT(changed(neutral, smile, forehead), 0.005);
}

// A frame's picture does not depend on what was rendered before it, and a
// resampled clock lands on the stream's frames exactly.
TEST(Properties, FramesAreIndependentAndResamplingIsExact) {
  REQUIRE_FIXTURE();
  const std::string all = render("prop-all", fx.afm, fx.fap, "--size 120x150");
  const std::string one = render("prop-one", fx.afm, fx.fap, "--size 120x150 --frames 4");
  EXPECT_EQ(compare(load_png(frame_path(all, 4)), load_png(frame_path(one, 4))).mean, 0.0)
      << "frame 4 alone differs from frame 4 after frames 0 to 3";
  // 50 fps: frame 2k is the stream's frame k; 2k+1 lies between.
  const std::string fast = render("prop-50fps", fx.afm, fx.fap, "--size 120x150 --fps 50");
  size_t frames = 0;
  for (const auto &e : fs::directory_iterator(fast)) frames += e.path().extension() == ".png";
  EXPECT_EQ(frames, 2 * poses().size() - 1);
  for (int k = 0; k < (int)poses().size(); ++k)
    EXPECT_EQ(compare(load_png(frame_path(fast, 2 * k)), load_png(frame_path(all, k))).mean, 0.0) << k;
  const int j = pose_index("jaw_open");
  const Image a = load_png(frame_path(all, j - 1)), b = load_png(frame_path(all, j)),
              mid = load_png(frame_path(fast, 2 * j - 1));
  EXPECT_GT(compare(mid, a).mean, 0.0);
  EXPECT_GT(compare(mid, b).mean, 0.0);
}

// ---- the Song head (shared data) ---------------------------------------------------

// Mean of R - G over boxes: lips are redder than skin.
double redness(const Image &im, const std::vector<Box> &boxes) {
  double sum = 0;
  size_t n = 0;
  for (const Box &b : boxes)
    for (int y = std::max(0, b.y0); y <= std::min(im.h - 1, b.y1); ++y)
      for (int x = std::max(0, b.x0); x <= std::min(im.w - 1, b.x1); ++x) {
        sum += im.at(x, y)[0] - im.at(x, y)[1];
        ++n;
      }
  return n ? sum / n : 0;
}

std::vector<uint8_t> encode_tga(const std::vector<uint8_t> &rgba, int w, int h, int bits, bool rle,
                                bool top_down, bool right_left, const std::string &id = "");

TEST(Song, RendersTexturedTheRightWayUp) {
  AFM_REQUIRE_SHARED_DATA();
  REQUIRE_FIXTURE();
  const std::string song_dir = afmtest::shared_data("faces/song");
  const std::string afm = fx.dir + "/song.afm", log = fx.dir + "/song-import.log";
  ASSERT_EQ(run(quote(tool("afm-import")) + " " + quote(song_dir + "/song.WRL") + " " +
                    quote(song_dir + "/song.fdp") + " -o " + quote(afm) + " --analytic",
                log),
            0)
      << last_lines(log);
  // The same textures, but the face's (front.tga) a flat blue.
  const std::string blue_dir = fx.dir + "/song-blue-textures";
  fs::create_directories(blue_dir);
  for (const auto &e : fs::directory_iterator(song_dir))
    if (e.path().extension() == ".tga")
      fs::copy_file(e.path(), blue_dir + "/" + e.path().filename().string(), fs::copy_options::overwrite_existing);
  std::vector<uint8_t> blue(8 * 8 * 4);
  for (size_t i = 0; i < blue.size(); i += 4) blue[i] = 0, blue[i + 1] = 0, blue[i + 2] = 255, blue[i + 3] = 255;
  const std::vector<uint8_t> blue_tga = encode_tga(blue, 8, 8, 24, false, false, false);
  write_text(blue_dir + "/front.tga", std::string(blue_tga.begin(), blue_tga.end()));

  const std::string stream = afmtest::shared_data("fap/xface/joy.fap");
  const std::string common = "--size 200x250 --fov 0 --frames 0:2" + std::string(kBgOption);
  const std::string tex = render("song-tex", afm, stream, common + " --flip-v --textures " + quote(song_dir));
  const std::string plain = render("song-plain", afm, stream, common + " --no-textures");
  const std::string upside = render("song-upside-down", afm, stream, common + " --textures " + quote(song_dir));
  const std::string blued = render("song-blue", afm, stream, common + " --flip-v --textures " + quote(blue_dir));
  const ModelInfo info = model_info(afm);
  const Ortho o(info, 200, 250);
  const std::vector<Box> lips = {fdp_box(info, o, {"8.1", "8.2", "8.3", "8.4"}, 1)};
  const std::vector<Box> cheeks = {fdp_box(info, o, {"5.1"}, 2), fdp_box(info, o, {"5.2"}, 2)};
  const std::vector<Box> face = {fdp_box(info, o, {"9.3"}, 3), fdp_box(info, o, {"5.1"}, 2),
                                 fdp_box(info, o, {"5.2"}, 2)};
  for (int k = 0; k <= 2; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const Image t = load_png(frame_path(tex, k)), p = load_png(frame_path(plain, k)),
                u = load_png(frame_path(upside, k)), b = load_png(frame_path(blued, k));
    ASSERT_GT(t.w, 0);
    // Not blank: the head covers a good part of the picture.
    const Mask m = face_mask(t);
    EXPECT_GT((double)m.count / (t.w * t.h), 0.2);
    // Textured: over the head the colours differ clearly from the untextured render.
    double diff = 0;
    size_t n = 0;
    for (int y = 0; y < t.h; ++y)
      for (int x = 0; x < t.w; ++x)
        if (m.at(x, y)) diff += channel_diff(t.at(x, y), p.at(x, y)), ++n;
    EXPECT_GT(diff / n, 10) << "the textured render looks like the untextured one";
    // The colours come from the texture file: with a blue front.tga the nose
    // and cheeks are blue, with the real one skin-coloured.
    double skin[3] = {0, 0, 0}, bl[3] = {0, 0, 0};
    size_t fn = 0;
    for (const Box &bx : face)
      for (int y = bx.y0; y <= bx.y1; ++y)
        for (int x = bx.x0; x <= bx.x1; ++x, ++fn)
          for (int c = 0; c < 3; ++c) skin[c] += t.at(x, y)[c], bl[c] += b.at(x, y)[c];
    EXPECT_GT(skin[0], 1.2 * skin[2]) << "the face is not skin-coloured";
    EXPECT_GT(bl[2], 3 * bl[0]) << "the face does not take its colour from front.tga";
    EXPECT_GT(bl[2] / fn, 60);
    // The right way up: with --flip-v (Song's texture coordinates count v from
    // the image's top) the lips' FDPs are redder than the cheeks' and than
    // the same place with the texture upside down.
    EXPECT_GT(redness(t, lips), redness(t, cheeks) + 12) << "no lips where the lips are";
    EXPECT_GT(redness(t, lips), redness(u, lips) + 12) << "the texture fits either way up";
  }
}

// ---- renderer additions: cut-out alpha, texture uploads ------------------------------

// A square facing the camera, textured left half red and opaque, right half
// green with alpha 0; rendered orthographically onto blue.
struct Quad {
  float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
  float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
  uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
  std::vector<uint8_t> px;
  afm_render_image tex{};
  afm_render_mesh mesh{};
  afm_render_view view{};
  Quad() : px(4 * 4 * 4) {
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        uint8_t *p = &px[((size_t)y * 4 + x) * 4];
        p[0] = x < 2 ? 255 : 0, p[1] = x < 2 ? 0 : 255, p[2] = 0, p[3] = x < 2 ? 255 : 0;
      }
    tex = {px.data(), 4, 4};
    mesh.positions = pos;
    mesh.vertex_count = 4;
    mesh.triangles = tri;
    mesh.triangle_count = 2;
    mesh.uvs = uv;
    mesh.texture = &tex;
    mesh.unlit = 1;
    for (float &c : mesh.color) c = 1;
    afm_render_view_init(&view, 40, 40);
    view.fov_deg = 0;
    view.supersample = 1;
    view.background[0] = view.background[1] = 0, view.background[2] = 255;
  }
};

TEST(Renderer, AlphaCutoffDropsTransparentTexels) {
  Quad q;
  std::vector<uint8_t> img(40 * 40 * 4);
  ASSERT_EQ(afm_render(&q.mesh, 1, &q.view, img.data()), AFM_OK) << afm_render_last_error();
  const uint8_t *left = &img[(20 * 40 + 8) * 4], *right = &img[(20 * 40 + 31) * 4];
  EXPECT_GT(left[0], 200);
  EXPECT_GT(right[1], 200) << "without a cut-off the transparent half is drawn";
  q.mesh.alpha_cutoff = 0.5f;
  ASSERT_EQ(afm_render(&q.mesh, 1, &q.view, img.data()), AFM_OK) << afm_render_last_error();
  EXPECT_GT(left[0], 200);
  EXPECT_EQ(right[1], 0) << "the transparent half is drawn";
  EXPECT_EQ(right[2], 255) << "the background does not show through";
}

TEST(Renderer, TexturesUploadPerFrameUnlessStatic) {
  Quad q;
  afm_renderer *r = nullptr;
  ASSERT_EQ(afm_renderer_create(&r), AFM_OK);
  std::vector<uint8_t> img(40 * 40 * 4);
  const size_t centre = (20 * 40 + 8) * 4;
  ASSERT_EQ(afm_renderer_draw(r, &q.mesh, 1, &q.view, img.data()), AFM_OK);
  EXPECT_GT(img[centre], 200);
  // Pixels changed in place: a plain texture is read again at every draw.
  for (size_t i = 0; i < q.px.size(); i += 4) q.px[i] = 0, q.px[i + 2] = 255;
  ASSERT_EQ(afm_renderer_draw(r, &q.mesh, 1, &q.view, img.data()), AFM_OK);
  EXPECT_LT(img[centre], 50);
  EXPECT_GT(img[centre + 2], 200);
  // A static one is kept from its first upload as static.
  q.mesh.texture_static = 1;
  ASSERT_EQ(afm_renderer_draw(r, &q.mesh, 1, &q.view, img.data()), AFM_OK);
  for (size_t i = 0; i < q.px.size(); i += 4) q.px[i] = 255, q.px[i + 2] = 0;
  ASSERT_EQ(afm_renderer_draw(r, &q.mesh, 1, &q.view, img.data()), AFM_OK);
  EXPECT_GT(img[centre + 2], 200) << "a static texture was uploaded again";
  // Two meshes, two images, one frame: each shows its own.
  std::vector<uint8_t> other(q.px.size(), 255);
  afm_render_image tex2{other.data(), 4, 4};
  afm_render_mesh m2 = q.mesh;
  float pos2[12];
  for (int i = 0; i < 12; ++i) pos2[i] = q.pos[i] * 0.25f + (i % 3 == 2 ? 0.5f : 0.0f);
  m2.positions = pos2;
  m2.texture = &tex2;
  m2.texture_static = 0;
  const afm_render_mesh both[2] = {q.mesh, m2};
  q.view.box_min[0] = q.view.box_min[1] = q.view.box_min[2] = -1;
  q.view.box_max[0] = q.view.box_max[1] = q.view.box_max[2] = 1;
  ASSERT_EQ(afm_renderer_draw(r, both, 2, &q.view, img.data()), AFM_OK) << afm_render_last_error();
  const uint8_t *mid = &img[(20 * 40 + 20) * 4];
  EXPECT_GT(mid[0], 200);
  EXPECT_GT(mid[1], 200);
  EXPECT_GT(mid[2], 200) << "the small square does not show its white texture";
  afm_renderer_destroy(r);
}

// ---- TGA and PNG readers ------------------------------------------------------------

// A test pattern: every pixel different, alpha varying.
std::vector<uint8_t> pattern(int w, int h) {
  std::vector<uint8_t> p((size_t)w * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t *q = &p[((size_t)y * w + x) * 4];
      q[0] = (uint8_t)(x * 40 + y);
      q[1] = (uint8_t)(y * 50 + 7);
      q[2] = (uint8_t)(x * y + 3);
      q[3] = (uint8_t)(255 - x - y);
    }
  return p;
}

// Encodes `rgba` (top row first) as a TGA: type 2 or 10 (rle), 24 or 32 bits,
// stored bottom-up unless top_down, mirrored when right_left. Rows in RLE
// are encoded as one stream, so packets cross rows.
std::vector<uint8_t> encode_tga(const std::vector<uint8_t> &rgba, int w, int h, int bits, bool rle,
                                bool top_down, bool right_left, const std::string &id) {
  std::vector<uint8_t> out(18, 0);
  out[0] = (uint8_t)id.size();
  out[2] = rle ? 10 : 2;
  out[12] = (uint8_t)(w & 255), out[13] = (uint8_t)(w >> 8);
  out[14] = (uint8_t)(h & 255), out[15] = (uint8_t)(h >> 8);
  out[16] = (uint8_t)bits;
  out[17] = (uint8_t)((bits == 32 ? 8 : 0) | (top_down ? 0x20 : 0) | (right_left ? 0x10 : 0));
  for (char c : id) out.push_back((uint8_t)c);
  std::vector<std::vector<uint8_t>> px;  // stored order
  for (int r = 0; r < h; ++r) {
    const int y = top_down ? r : h - 1 - r;
    for (int c = 0; c < w; ++c) {
      const int x = right_left ? w - 1 - c : c;
      const uint8_t *s = &rgba[((size_t)y * w + x) * 4];
      std::vector<uint8_t> v = {s[2], s[1], s[0]};
      if (bits == 32) v.push_back(s[3]);
      px.push_back(v);
    }
  }
  if (!rle) {
    for (auto &v : px) out.insert(out.end(), v.begin(), v.end());
    return out;
  }
  size_t i = 0;
  while (i < px.size()) {
    size_t run = 1;
    while (i + run < px.size() && run < 128 && px[i + run] == px[i]) ++run;
    if (run > 1) {
      out.push_back((uint8_t)(0x80 | (run - 1)));
      out.insert(out.end(), px[i].begin(), px[i].end());
      i += run;
    } else {
      size_t raw = 1;
      while (i + raw < px.size() && raw < 128 && !(i + raw + 1 < px.size() && px[i + raw] == px[i + raw + 1]))
        ++raw;
      out.push_back((uint8_t)(raw - 1));
      for (size_t k = 0; k < raw; ++k) out.insert(out.end(), px[i + k].begin(), px[i + k].end());
      i += raw;
    }
  }
  return out;
}

void expect_decodes_to(const std::vector<uint8_t> &file, const std::vector<uint8_t> &want, int w, int h,
                       bool alpha) {
  afm_image im{};
  ASSERT_EQ(afm_tga_decode(file.data(), file.size(), "t.tga", &im), AFM_OK) << afm_render_last_error();
  ASSERT_EQ(im.width, w);
  ASSERT_EQ(im.height, h);
  EXPECT_EQ(im.has_alpha != 0, alpha);
  for (int i = 0; i < w * h; ++i)
    for (int k = 0; k < 4; ++k) {
      const int expect = (k == 3 && !alpha) ? 255 : want[(size_t)i * 4 + k];
      ASSERT_EQ(im.rgba[(size_t)i * 4 + k], expect) << "pixel " << i % w << "," << i / w << " channel " << k;
    }
  afm_image_free(&im);
}

TEST(Tga, DecodesEveryLayout) {
  const int w = 7, h = 5;
  std::vector<uint8_t> p = pattern(w, h);
  // Runs, some crossing from one row into the next.
  for (int i = 3; i < 12; ++i) std::memcpy(&p[(size_t)i * 4], &p[12], 4);
  for (int bits : {24, 32})
    for (int rle = 0; rle < 2; ++rle)
      for (int td = 0; td < 2; ++td)
        for (int rl = 0; rl < 2; ++rl) {
          SCOPED_TRACE(std::to_string(bits) + " bits, rle " + std::to_string(rle) + ", top-down " +
                       std::to_string(td) + ", right-left " + std::to_string(rl));
          expect_decodes_to(encode_tga(p, w, h, bits, rle, td, rl, "id!"), p, w, h, bits == 32);
        }
}

TEST(Tga, GreyAnd16BitAndAlphaRules) {
  // 8-bit grey, 2x2, top-down.
  const std::vector<uint8_t> grey = {0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2, 0, 8, 0x20, 10, 20, 30, 40};
  afm_image im{};
  ASSERT_EQ(afm_tga_decode(grey.data(), grey.size(), "g.tga", &im), AFM_OK) << afm_render_last_error();
  EXPECT_EQ(im.rgba[0], 10);
  EXPECT_EQ(im.rgba[2], 10);
  EXPECT_EQ(im.rgba[3], 255);
  EXPECT_EQ(im.rgba[12], 40);
  afm_image_free(&im);
  // 16-bit A1R5G5B5, one pixel: pure red, opaque; 5 bits scale to 8.
  const std::vector<uint8_t> c16 = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 1, 0, 16, 1, 0x00, 0xFC};
  ASSERT_EQ(afm_tga_decode(c16.data(), c16.size(), "c.tga", &im), AFM_OK) << afm_render_last_error();
  EXPECT_EQ(im.rgba[0], 255);
  EXPECT_EQ(im.rgba[1], 0);
  EXPECT_EQ(im.rgba[2], 0);
  afm_image_free(&im);
  // 32 bits with alpha zero everywhere (a writer bug): opaque.
  std::vector<uint8_t> p = pattern(3, 2);
  for (size_t i = 3; i < p.size(); i += 4) p[i] = 0;
  std::vector<uint8_t> f = encode_tga(p, 3, 2, 32, false, false, false);
  ASSERT_EQ(afm_tga_decode(f.data(), f.size(), "z.tga", &im), AFM_OK);
  EXPECT_EQ(im.has_alpha, 0);
  EXPECT_EQ(im.rgba[3], 255);
  afm_image_free(&im);
}

TEST(Tga, RefusesBadFilesWithClearMessages) {
  const std::vector<uint8_t> p = pattern(4, 4);
  const std::vector<uint8_t> good = encode_tga(p, 4, 4, 24, false, false, false);
  const std::vector<uint8_t> rle = encode_tga(p, 4, 4, 24, true, false, false);
  afm_image im{};
  auto expect_error = [&](std::vector<uint8_t> f, afm_result r, const std::string &text) {
    EXPECT_EQ(afm_tga_decode(f.data(), f.size(), "bad.tga", &im), r) << text;
    const std::string msg = afm_render_last_error();
    EXPECT_NE(msg.find("bad.tga"), std::string::npos) << msg;
    EXPECT_NE(msg.find(text), std::string::npos) << msg;
    EXPECT_EQ(im.rgba, nullptr);
  };
  expect_error(std::vector<uint8_t>(good.begin(), good.begin() + 10), AFM_ERR_TRUNCATED, "header");
  expect_error(std::vector<uint8_t>(good.begin(), good.end() - 5), AFM_ERR_TRUNCATED, "row 3 of 4");
  expect_error(std::vector<uint8_t>(rle.begin(), rle.end() - 4), AFM_ERR_TRUNCATED, "run-length");
  std::vector<uint8_t> f = good;
  f[2] = 1;  // colour-mapped
  expect_error(f, AFM_ERR_RANGE, "image type 1 (colour-mapped)");
  f = good;
  f[16] = 12;
  expect_error(f, AFM_ERR_RANGE, "12 bits per pixel");
  f = good;
  f[12] = f[13] = 0;
  expect_error(f, AFM_ERR_RANGE, "size 0x4");
  // A run that passes the image's end.
  f = std::vector<uint8_t>(good.begin(), good.begin() + 18);
  f[2] = 10;
  f.insert(f.end(), {0xFF, 1, 2, 3});
  expect_error(f, AFM_ERR_RANGE, "128 pixels from pixel 0");
}

// Song's front.tga (24-bit, bottom-up): the reader's pixels against the file's
// bytes read directly.
TEST(Tga, ReadsSongsTexture) {
  AFM_REQUIRE_SHARED_DATA();
  const std::string path = afmtest::shared_data("faces/song/front.tga");
  const std::string bytes = afmtest::read_file(path);
  ASSERT_GT(bytes.size(), 18u);
  const auto b = [&](size_t i) { return (uint8_t)bytes[i]; };
  const int w = b(12) | b(13) << 8, h = b(14) | b(15) << 8;
  ASSERT_EQ(b(16), 24);
  ASSERT_EQ(b(17) & 0x30, 0);  // bottom-up, left to right
  afm_image im{};
  ASSERT_EQ(afm_image_read(path.c_str(), &im), AFM_OK) << afm_render_last_error();
  ASSERT_EQ(im.width, w);
  ASSERT_EQ(im.height, h);
  const size_t start = 18 + b(0);
  for (int y = 0; y < h; y += 37)
    for (int x = 0; x < w; x += 29) {
      const size_t s = start + ((size_t)(h - 1 - y) * w + x) * 3;
      const uint8_t *q = im.rgba + ((size_t)y * w + x) * 4;
      ASSERT_EQ(q[0], b(s + 2));
      ASSERT_EQ(q[1], b(s + 1));
      ASSERT_EQ(q[2], b(s));
      ASSERT_EQ(q[3], 255);
    }
  afm_image_free(&im);
}

TEST(Png, RoundTripAndErrors) {
  const std::string dir = afmtest::temp_dir("render-png");
  const std::vector<uint8_t> p = pattern(9, 6);
  const afm_render_image src{p.data(), 9, 6};
  const std::string path = dir + "/p.png";
  ASSERT_EQ(afm_png_write(path.c_str(), &src), AFM_OK) << afm_render_last_error();
  afm_image im{};
  ASSERT_EQ(afm_image_read(path.c_str(), &im), AFM_OK) << afm_render_last_error();
  ASSERT_EQ(im.width, 9);
  ASSERT_EQ(im.height, 6);
  EXPECT_EQ(std::memcmp(im.rgba, p.data(), p.size()), 0);
  afm_image_free(&im);
  // Missing, damaged.
  EXPECT_EQ(afm_png_read((dir + "/none.png").c_str(), &im), AFM_ERR_IO);
  EXPECT_NE(std::string(afm_render_last_error()).find("none.png"), std::string::npos);
  std::string bytes = afmtest::read_file(path);
  write_text(dir + "/cut.png", bytes.substr(0, bytes.size() / 2));
  EXPECT_EQ(afm_png_read((dir + "/cut.png").c_str(), &im), AFM_ERR_RANGE);
  EXPECT_NE(std::string(afm_render_last_error()).find("cut.png"), std::string::npos);
  EXPECT_EQ(im.rgba, nullptr);
}

}  // namespace
