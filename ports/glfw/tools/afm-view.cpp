// afm-view: the desktop preview. A GLFW window draws an AFM with the
// renderer's own GL code (afm/gl_draw.h, as afm-render draws it), plays a
// FAP stream at its rate, and sets FAPs, visemes and expressions live.
#define GL_GLEXT_PROTOTYPES 1
#define GLFW_INCLUDE_GLEXT 1
#include <GLFW/glfw3.h>

#include <afm/face_scene.h>
#include <afm/gl_draw.h>
#include <afm/mpeg4.h>
#include <afm/player.h>
#include <afm/render.h>
#include <afm/view_options.h>

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;

namespace {

using afm_face::InputError;
using afm_face::UsageError;

const char *const kKeysHelp =
    "Keys\n"
    "  Space                 play / pause the stream\n"
    "  Right, Left           one frame forward, back (pauses)\n"
    "  Home, End             the first, the last frame\n"
    "  L                     loop on / off\n"
    "  ], =, +               play faster (x2, up to x4)\n"
    "  [, -                  play slower (/2, down to x0.25)\n"
    "  Tab, Shift+Tab        select the next, previous control: FAPs 3..68, then\n"
    "                        visemes 1..14, then expressions 1..6\n"
    "  /                     type a control by number or name (37, open_jaw, joy,\n"
    "                        viseme:A, expression:2), Enter picks it, Escape cancels\n"
    "  Up, Down              raise, lower the selected control (Shift: 5 steps)\n"
    "  0                     the selected control back to 0\n"
    "  R                     reset every control\n"
    "  W                     wireframe on / off\n"
    "  V                     show only the vertices the pose moves (dots), on / off\n"
    "  P                     screenshot: afm-view-001.png, 002, ... in the current\n"
    "                        directory, rendered like afm-render\n"
    "  C                     reset the camera\n"
    "  Q, Escape             quit\n"
    "  mouse: drag with the left button to orbit, scroll to zoom\n";

void usage(FILE *out) {
  std::fputs(
      "usage: afm-view MODEL.afm [STREAM.fap] [options]\n"
      "\n"
      "The desktop preview: a window showing the Animatable Face Model lit and\n"
      "textured as afm-render draws it, with an orbit camera. Plays the FAP stream\n"
      "at its frame rate (frame and time in the window's title) and sets FAPs,\n"
      "visemes and expressions live, with or without a stream; a live value\n"
      "replaces the stream's for that FAP. Needs an X display (or Xvfb).\n"
      "\n"
      "Window\n"
      "  --size WxH            window size in pixels, 16..4096 each (default 640x480)\n"
      "\n",
      out);
  std::fputs(afm_face::kViewOptionsHelp, out);
  std::fputs(
      "  --speed X             playing speed, 0.25..4 (default 1)\n"
      "  --loop                start with looping on\n"
      "  --paused              start paused (the default with --exit)\n"
      "  --frame N             start at frame N of the stream\n"
      "\n"
      "Controls and scripted runs\n"
      "  --set NAME=VALUE      set a control: a FAP by number or name in FAP units\n"
      "                        (3=400, open_jaw=400), a viseme or expression by\n"
      "                        name or as viseme:N, expression:N at 0..63\n"
      "                        (joy=63, viseme:A=40); repeatable\n"
      "  --keys LIST           press these keys after loading, in order (names:\n"
      "                        space, right, left, home, end, up, down, tab,\n"
      "                        shift+tab, enter, escape, or one character: w, v, ...)\n"
      "  --wireframe           start with the wireframe on\n"
      "  --moved               start showing only the moved vertices\n"
      "  --screenshot FILE.png after --frames frames, write the view as a PNG of the\n"
      "                        window's size, rendered like afm-render (supersampled\n"
      "                        by --aa)\n"
      "  --frames N            frames to draw before the screenshot and --exit\n"
      "                        (default 1)\n"
      "  --exit                close after those frames; prints the last title. The\n"
      "                        clock then moves one stream frame per drawn frame\n"
      "                        (times --speed), so scripted runs repeat exactly\n"
      "\n",
      out);
  std::fputs(kKeysHelp, out);
  std::fputs(
      "\n"
      "Other\n"
      "  --help                this text\n"
      "\n"
      "Exit status: 0 on success, 1 on bad input (the message names the file and\n"
      "line, part or field), no display or a failed write, 2 on bad usage.\n",
      out);
}

// ---- controls: FAPs 3..68, visemes 1..14, expressions 1..6 ---------------------

struct Control {
  int kind = AFM_TARGET_FAP;  // afm_target_kind
  int number = 3;
};

constexpr int kControlCount = (AFM_FAP_COUNT - 2) + (AFM_VISEME_COUNT - 1) + (AFM_EXPRESSION_COUNT - 1);

Control control_at(int i) {
  i = ((i % kControlCount) + kControlCount) % kControlCount;
  if (i < AFM_FAP_COUNT - 2) return {AFM_TARGET_FAP, 3 + i};
  i -= AFM_FAP_COUNT - 2;
  if (i < AFM_VISEME_COUNT - 1) return {AFM_TARGET_VISEME, 1 + i};
  return {AFM_TARGET_EXPRESSION, 1 + i - (AFM_VISEME_COUNT - 1)};
}

int control_index(const Control &c) {
  if (c.kind == AFM_TARGET_FAP) return c.number - 3;
  if (c.kind == AFM_TARGET_VISEME) return AFM_FAP_COUNT - 2 + c.number - 1;
  return AFM_FAP_COUNT - 2 + AFM_VISEME_COUNT - 1 + c.number - 1;
}

std::string control_name(const Control &c) {
  if (c.kind == AFM_TARGET_FAP) return std::string(afm_fap(c.number)->name) + " (FAP " + std::to_string(c.number) + ")";
  if (c.kind == AFM_TARGET_VISEME)
    return std::string("viseme ") + afm_viseme_name(c.number) + " (" + std::to_string(c.number) + ")";
  return std::string("expression ") + afm_expression_name(c.number) + " (" + std::to_string(c.number) + ")";
}

bool all_digits(const std::string &s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
}

// A control by number or name: "37", "open_jaw", "fap:37", a viseme name
// ("A", "p_b_m") or "viseme:N", an expression name ("joy") or "expression:N".
// Empty string on success, else why not.
std::string parse_control(const std::string &text, Control *out) {
  std::string kind, what = text;
  const size_t colon = text.find(':');
  if (colon != std::string::npos) kind = afm_face::lower(text.substr(0, colon)), what = text.substr(colon + 1);
  const bool number = all_digits(what);
  const int n = number && what.size() < 4 ? std::atoi(what.c_str()) : -1;
  if (kind.empty() || kind == "fap") {
    if (number) {
      if (n >= 3 && n <= AFM_FAP_COUNT) return *out = {AFM_TARGET_FAP, n}, "";
      if (kind.empty() && (n == 1 || n == 2))
        return "FAP " + what + " is high level: pick a viseme (viseme:N) or an expression (expression:N)";
      return "FAP " + what + ": the low-level FAPs are 3 to 68";
    }
    const afm_fap_info *f = afm_fap_by_name(what.c_str());
    if (f && f->number >= 3) return *out = {AFM_TARGET_FAP, f->number}, "";
    if (kind == "fap") return "no FAP is named '" + what + "'";
  }
  if (kind.empty() || kind == "viseme") {
    for (int v = 1; v < AFM_VISEME_COUNT; ++v)
      if ((number && n == v) || (!number && what == afm_viseme_name(v))) return *out = {AFM_TARGET_VISEME, v}, "";
    if (kind == "viseme") return "no viseme '" + what + "' (1 to 14, or a name such as p_b_m, A)";
  }
  if (kind.empty() || kind == "expression") {
    for (int e = 1; e < AFM_EXPRESSION_COUNT; ++e)
      if ((number && n == e) || (!number && afm_face::lower(what) == afm_expression_name(e)))
        return *out = {AFM_TARGET_EXPRESSION, e}, "";
    if (kind == "expression") return "no expression '" + what + "' (1 to 6, or joy, sadness, anger, fear, disgust, surprise)";
  }
  if (!kind.empty()) return "'" + kind + "': use fap:, viseme: or expression:";
  return "'" + text + "' is no FAP, viseme or expression";
}

// The values set live. One viseme and one expression at a time (FAPs 1 and 2
// carry two of each, but as a blend of two, not two free weights).
struct Live {
  int32_t fap[AFM_FAP_COUNT + 1] = {};
  bool set[AFM_FAP_COUNT + 1] = {};  // FAPs the user set: they replace the stream's
  int viseme = 0, viseme_value = 0;
  int expression = 0, expression_value = 0;
};

int32_t control_value(const Live &l, const Control &c) {
  if (c.kind == AFM_TARGET_FAP) return l.fap[c.number];
  if (c.kind == AFM_TARGET_VISEME) return l.viseme == c.number ? l.viseme_value : 0;
  return l.expression == c.number ? l.expression_value : 0;
}

// Sets a control, clamped to its range (a FAP's, afm_fap_value_range;
// 0..63 for visemes and expressions).
void set_control(Live &l, const Control &c, long value) {
  if (c.kind == AFM_TARGET_FAP) {
    int32_t lo = 0, hi = 0;
    afm_fap_value_range(c.number, &lo, &hi);
    l.fap[c.number] = (int32_t)std::clamp<long>(value, lo, hi);
    l.set[c.number] = true;
  } else if (c.kind == AFM_TARGET_VISEME) {
    l.viseme = c.number;
    l.viseme_value = (int)std::clamp<long>(value, 0, 63);
  } else {
    l.expression = c.number;
    l.expression_value = (int)std::clamp<long>(value, 0, 63);
  }
}

// One key step: a tenth of the model's target for the FAP (its reference
// value), else a fiftieth of the FAP's range; 4 of 63 for visemes and
// expressions.
long control_step(const afm_doc &doc, const Control &c) {
  if (c.kind != AFM_TARGET_FAP) return 4;
  for (uint32_t i = 0; i < doc.target_count; ++i) {
    const afm_target &t = doc.targets[i];
    if (t.kind == AFM_TARGET_FAP && t.number == c.number && t.reference > 0)
      return std::max<long>(1, t.reference / 10);
  }
  int32_t lo = 0, hi = 0;
  afm_fap_value_range(c.number, &lo, &hi);
  return std::max<long>(1, hi / 50);
}

// The state drawn: the stream's (or neutral), with the live values over it.
afm_fap_state compose(const afm_fap_state *stream_state, const Live &l) {
  afm_fap_state s;
  if (stream_state) s = *stream_state;
  else afm_fap_state_reset(&s);
  for (int f = 3; f <= AFM_FAP_COUNT; ++f)
    if (l.set[f]) s.value[f] = l.fap[f];
  if (l.viseme && l.viseme_value) {
    s.viseme = afm_viseme_value{(uint8_t)l.viseme, 0, (uint8_t)l.viseme_value, 0};
  }
  if (l.expression && l.expression_value) {
    s.expression = afm_expression_value{(uint8_t)l.expression, (uint8_t)l.expression_value, 0, 0, 0, 0};
  }
  return s;
}

// ---- options ----------------------------------------------------------------------

struct Setting {
  Control control;
  long value = 0;
};

struct Options {
  std::string model, stream;
  afm_face::ViewOptions view;
  double speed = 1;
  bool loop = false, paused = false, wireframe = false, moved = false, exit_after = false;
  long frame = 0, frames = 1;
  std::vector<Setting> sets;
  std::vector<std::string> keys;
  std::string screenshot;
};

// Key names for --keys: GLFW key codes, and the character typed, if any.
struct KeyName {
  const char *name;
  int key;
  int mods;
};
const KeyName kKeyNames[] = {
    {"space", GLFW_KEY_SPACE, 0},   {"right", GLFW_KEY_RIGHT, 0},   {"left", GLFW_KEY_LEFT, 0},
    {"home", GLFW_KEY_HOME, 0},     {"end", GLFW_KEY_END, 0},       {"up", GLFW_KEY_UP, 0},
    {"down", GLFW_KEY_DOWN, 0},     {"tab", GLFW_KEY_TAB, 0},       {"shift+tab", GLFW_KEY_TAB, GLFW_MOD_SHIFT},
    {"shift+up", GLFW_KEY_UP, GLFW_MOD_SHIFT}, {"shift+down", GLFW_KEY_DOWN, GLFW_MOD_SHIFT},
    {"enter", GLFW_KEY_ENTER, 0},   {"escape", GLFW_KEY_ESCAPE, 0}, {"backspace", GLFW_KEY_BACKSPACE, 0},
};

// A single printable character's key: letters and digits map to their keys
// (GLFW key codes for those are their upper-case ASCII codes).
int char_key(char c) {
  if (c >= 'a' && c <= 'z') return GLFW_KEY_A + (c - 'a');
  if (c >= 'A' && c <= 'Z') return GLFW_KEY_A + (c - 'A');
  if (c >= '0' && c <= '9') return GLFW_KEY_0 + (c - '0');
  switch (c) {
    case '[': return GLFW_KEY_LEFT_BRACKET;
    case ']': return GLFW_KEY_RIGHT_BRACKET;
    case '-': return GLFW_KEY_MINUS;
    case '=': return GLFW_KEY_EQUAL;
    case '/': return GLFW_KEY_SLASH;
    case '+': return GLFW_KEY_KP_ADD;
    case '_': return GLFW_KEY_MINUS;
    case ':': return GLFW_KEY_SEMICOLON;
    default: return GLFW_KEY_UNKNOWN;
  }
}

Options parse_args(int argc, char **argv, bool *help) {
  Options o;
  *help = false;
  std::vector<std::string> positional;
  bool paused_given = false;
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
    } else if (a == "--speed") {
      o.speed = afm_face::parse_double(a, value(), 0.25, 4);
    } else if (a == "--loop") {
      o.loop = true;
    } else if (a == "--paused") {
      o.paused = paused_given = true;
    } else if (a == "--frame") {
      o.frame = afm_face::parse_long(a, value(), 0, 100000000);
    } else if (a == "--set") {
      const std::string v = value();
      const size_t eq = v.rfind('=');
      if (eq == std::string::npos || eq == 0)
        throw UsageError("--set " + v + ": expected NAME=VALUE (e.g. open_jaw=400, joy=63)");
      Setting s;
      const std::string why = parse_control(v.substr(0, eq), &s.control);
      if (!why.empty()) throw UsageError("--set " + v + ": " + why);
      int32_t lo = 0, hi = 63;
      if (s.control.kind == AFM_TARGET_FAP) afm_fap_value_range(s.control.number, &lo, &hi);
      s.value = afm_face::parse_long("--set " + v.substr(0, eq), v.c_str() + eq + 1, lo, hi);
      o.sets.push_back(s);
    } else if (a == "--keys") {
      for (std::string k : afm_face::split(value(), ',')) {
        for (const std::string &w : afm_face::split(k, ' ')) {
          if (w.empty()) continue;
          const std::string lw = afm_face::lower(w);
          bool known = w.size() == 1 && char_key(w[0]) != GLFW_KEY_UNKNOWN;
          for (const KeyName &kn : kKeyNames) known = known || lw == kn.name;
          if (!known) throw UsageError("--keys: unknown key '" + w + "' (afm-view --help lists the names)");
          o.keys.push_back(w.size() == 1 ? w : lw);
        }
      }
    } else if (a == "--wireframe") {
      o.wireframe = true;
    } else if (a == "--moved") {
      o.moved = true;
    } else if (a == "--screenshot") {
      o.screenshot = value();
      if (afm_face::lower(fs::path(o.screenshot).extension().string()) != ".png")
        throw UsageError("--screenshot " + o.screenshot + ": the file's name must end in .png");
    } else if (a == "--frames") {
      o.frames = afm_face::parse_long(a, value(), 1, 100000000);
    } else if (a == "--exit") {
      o.exit_after = true;
    } else if (a.size() > 1 && a[0] == '-') {
      throw UsageError("unknown option '" + a + "'");
    } else {
      positional.push_back(a);
    }
  }
  if (positional.empty()) throw UsageError("give a model (.afm), and optionally a FAP stream (.fap)");
  if (positional.size() > 2) throw UsageError("too many arguments: '" + positional[2] + "'");
  o.model = positional[0];
  if (positional.size() == 2) o.stream = positional[1];
  if (o.exit_after && !paused_given) o.paused = true;  // scripted runs are repeatable
  return o;
}

// ---- the viewer -------------------------------------------------------------------

struct Viewer {
  Options opt;
  const afm_doc *doc = nullptr;
  afm_face::FaceScene face;
  afm_face::Stream stream;
  bool has_stream = false;
  afm_fap_cursor cursor{};
  long frame_count = 1;  // frames of the stream at its rate
  long frame = 0;
  double clock_s = 0;    // time into the stream while playing (seconds, scaled by speed)
  bool playing = false, loop = false;
  double speed = 1;
  Live live;
  Control selected;
  bool typing = false;
  std::string typed, message;
  bool wireframe = false, moved_only = false;
  float yaw = 0, pitch = 0, zoom = 1;
  bool dragging = false;
  double drag_x = 0, drag_y = 0;
  bool dirty = true;  // the pose must be recomputed
  bool quit = false;
  std::vector<float> neutral, moved;  // #V x 3 neutral positions; #M x 3 moved ones
  afm_gl_drawer *drawer = nullptr;
  GLFWwindow *window = nullptr;
  int shots = 0;
};

double stream_fps(const Viewer &v) {
  return (double)v.stream.header.fps_num / v.stream.header.fps_den;
}

void seek_frame(Viewer &v, long f) {
  if (!v.has_stream) return;
  v.frame = std::clamp<long>(f, 0, v.frame_count - 1);
  v.clock_s = (double)v.frame / stream_fps(v);
  v.dirty = true;
}

void reset_camera(Viewer &v) {
  v.yaw = v.opt.view.yaw;
  v.pitch = v.opt.view.pitch;
  v.zoom = 1;
}

void step_control(Viewer &v, int steps) {
  const long now = control_value(v.live, v.selected);
  set_control(v.live, v.selected, now + steps * control_step(*v.doc, v.selected));
  v.dirty = true;
}

void write_screenshot(Viewer &v, const std::string &path);

void finish_typing(Viewer &v) {
  v.typing = false;
  Control c;
  const std::string why = parse_control(v.typed, &c);
  if (why.empty()) {
    v.selected = c;
    v.message.clear();
  } else {
    v.message = why;
  }
  v.typed.clear();
}

void on_key(Viewer &v, int key, int mods) {
  const bool shift = (mods & GLFW_MOD_SHIFT) != 0;
  if (v.typing) {
    if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) finish_typing(v);
    else if (key == GLFW_KEY_ESCAPE) v.typing = false, v.typed.clear();
    else if (key == GLFW_KEY_BACKSPACE && !v.typed.empty()) v.typed.pop_back();
    return;  // characters arrive through on_char
  }
  switch (key) {
    case GLFW_KEY_SPACE:
      if (v.has_stream) {
        if (!v.playing && v.frame >= v.frame_count - 1) seek_frame(v, 0);
        v.playing = !v.playing;
      }
      break;
    case GLFW_KEY_RIGHT: v.playing = false; seek_frame(v, v.frame + 1); break;
    case GLFW_KEY_LEFT: v.playing = false; seek_frame(v, v.frame - 1); break;
    case GLFW_KEY_HOME: seek_frame(v, 0); break;
    case GLFW_KEY_END: seek_frame(v, v.frame_count - 1); break;
    case GLFW_KEY_L: v.loop = !v.loop; break;
    case GLFW_KEY_RIGHT_BRACKET: case GLFW_KEY_EQUAL: case GLFW_KEY_KP_ADD:
      v.speed = std::min(4.0, v.speed * 2);
      break;
    case GLFW_KEY_LEFT_BRACKET: case GLFW_KEY_MINUS: case GLFW_KEY_KP_SUBTRACT:
      v.speed = std::max(0.25, v.speed / 2);
      break;
    case GLFW_KEY_TAB: v.selected = control_at(control_index(v.selected) + (shift ? -1 : 1)); break;
    case GLFW_KEY_SLASH: case GLFW_KEY_ENTER:
      v.typing = true;
      v.typed.clear();
      break;
    case GLFW_KEY_UP: step_control(v, shift ? 5 : 1); break;
    case GLFW_KEY_DOWN: step_control(v, shift ? -5 : -1); break;
    case GLFW_KEY_0: set_control(v.live, v.selected, 0); v.dirty = true; break;
    case GLFW_KEY_R: v.live = Live(); v.dirty = true; break;
    case GLFW_KEY_W: v.wireframe = !v.wireframe; break;
    case GLFW_KEY_V: v.moved_only = !v.moved_only; break;
    case GLFW_KEY_P: {
      char name[32];
      std::error_code ec;
      do std::snprintf(name, sizeof name, "afm-view-%03d.png", ++v.shots);
      while (fs::exists(name, ec) && v.shots < 999);
      write_screenshot(v, name);
      break;
    }
    case GLFW_KEY_C: reset_camera(v); break;
    case GLFW_KEY_Q: case GLFW_KEY_ESCAPE: v.quit = true; break;
    default: break;
  }
}

void on_char(Viewer &v, unsigned codepoint) {
  // '/' opened the entry (its character event follows the key's); no name has one.
  if (v.typing && codepoint > 32 && codepoint < 127 && codepoint != '/' && v.typed.size() < 40)
    v.typed.push_back((char)codepoint);
}

// A --keys entry, as if typed.
void press(Viewer &v, const std::string &k) {
  for (const KeyName &kn : kKeyNames)
    if (k == kn.name) return on_key(v, kn.key, kn.mods);
  const bool was_typing = v.typing;
  on_key(v, char_key(k[0]), 0);
  if (was_typing) on_char(v, (unsigned char)k[0]);
}

// ---- drawing ----------------------------------------------------------------------

void update_pose(Viewer &v) {
  const afm_fap_state *a = nullptr, *b = nullptr;
  afm_q16 t = 0;
  if (v.has_stream) {
    const afm_result r = afm_fap_cursor_seek(&v.cursor, afm_face::frame_time_us((uint64_t)v.frame,
                                             v.stream.header.fps_num, v.stream.header.fps_den), &a, &b, &t);
    if (r != AFM_OK) throw InputError(v.opt.stream + ": frame " + std::to_string(v.frame) + ": " + afm_result_string(r));
  }
  // The stream's frames fall on its own times: t is 0 there, a is the frame.
  const afm_fap_state s = compose(a, v.live);
  const afm_result r = afm_face::pose_face(v.face, &s, nullptr, 0);
  if (r != AFM_OK) throw InputError("the player fails: " + std::string(afm_result_string(r)));
  v.moved.clear();
  for (size_t i = 0; i < v.neutral.size(); i += 3)
    if (v.face.positions[i] != v.neutral[i] || v.face.positions[i + 1] != v.neutral[i + 1] ||
        v.face.positions[i + 2] != v.neutral[i + 2])
      v.moved.insert(v.moved.end(), v.face.positions.begin() + (long)i, v.face.positions.begin() + (long)i + 3);
  v.dirty = false;
}

// The meshes of the current look: the parts (with their edges when the
// wireframe is on), or only the moved vertices as dots.
std::vector<afm_render_mesh> meshes_to_draw(const Viewer &v) {
  std::vector<afm_render_mesh> out;
  if (v.moved_only) {
    if (v.moved.empty()) return out;
    afm_render_mesh dots{};
    dots.positions = v.moved.data();
    dots.vertex_count = v.moved.size() / 3;
    dots.unlit = 1;
    dots.point_size = 3;
    const float orange[4] = {1.0f, 0.55f, 0.1f, 1.0f};
    std::memcpy(dots.color, orange, sizeof orange);
    out.push_back(dots);
    return out;
  }
  out = v.face.meshes;
  for (afm_render_mesh &m : out) m.wireframe = v.wireframe;
  return out;
}

afm_render_view current_view(const Viewer &v, int width, int height) {
  afm_render_view view = afm_face::make_view(v.opt.view, v.face, width, height);
  view.yaw_deg = v.yaw;
  view.pitch_deg = v.pitch;
  view.zoom = v.zoom;
  return view;
}

// Renders the current view at the window's size into an offscreen
// framebuffer `aa` times larger and box-filters it, as afm-render does.
void write_screenshot(Viewer &v, const std::string &path) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(v.window, &w, &h);
  if (w <= 0 || h <= 0) throw InputError(path + ": the window has no size to capture");
  if (v.dirty) update_pose(v);
  const afm_render_view view = current_view(v, w, h);
  const int s = afm_gl_supersample(&view);
  const int sw = w * s, sh = h * s;
  GLuint fbo = 0, colour = 0, depth = 0;
  glGenFramebuffers(1, &fbo);
  glGenRenderbuffers(1, &colour);
  glGenRenderbuffers(1, &depth);
  glBindRenderbuffer(GL_RENDERBUFFER, colour);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, sw, sh);
  glBindRenderbuffer(GL_RENDERBUFFER, depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, sw, sh);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
  std::string error;
  std::vector<uint8_t> big((size_t)sw * sh * 4), rgba((size_t)w * h * 4);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    error = "OpenGL cannot make a " + std::to_string(sw) + "x" + std::to_string(sh) + " offscreen image";
  } else {
    const std::vector<afm_render_mesh> meshes = meshes_to_draw(v);
    if (afm_gl_draw(v.drawer, meshes.data(), meshes.size(), &view, s) != AFM_OK) {
      error = afm_render_last_error();
    } else {
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, sw, sh, GL_RGBA, GL_UNSIGNED_BYTE, big.data());
      afm_gl_resolve(big.data(), w, h, s, rgba.data());
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteRenderbuffers(1, &colour);
  glDeleteRenderbuffers(1, &depth);
  glDeleteFramebuffers(1, &fbo);
  if (!error.empty()) throw InputError(path + ": " + error);
  const afm_render_image im = {rgba.data(), w, h};
  if (afm_png_write(path.c_str(), &im) != AFM_OK) throw InputError(afm_render_last_error());
  std::printf("wrote %s (%dx%d)\n", path.c_str(), w, h);
  std::fflush(stdout);
}

std::string title(const Viewer &v) {
  char buf[160];
  std::string t = "afm-view: " + fs::path(v.opt.model).filename().string();
  if (v.has_stream) {
    std::snprintf(buf, sizeof buf, "  %s  frame %ld/%ld  %.3f s  x%g  %s%s",
                  fs::path(v.opt.stream).filename().string().c_str(), v.frame, v.frame_count - 1,
                  (double)afm_face::frame_time_us((uint64_t)v.frame, v.stream.header.fps_num,
                                                  v.stream.header.fps_den) * 1e-6,
                  v.speed, v.playing ? "playing" : "paused", v.loop ? "  loop" : "");
    t += buf;
  }
  if (v.typing) {
    t += "  | pick: " + v.typed + "_";
  } else {
    std::snprintf(buf, sizeof buf, " = %ld", (long)control_value(v.live, v.selected));
    t += "  | " + control_name(v.selected) + buf;
    if (!v.message.empty()) t += "  (" + v.message + ")";
  }
  if (v.wireframe) t += "  | wireframe";
  if (v.moved_only) t += "  | moved vertices: " + std::to_string(v.moved.size() / 3);
  return t;
}

void draw_window(Viewer &v) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(v.window, &w, &h);
  if (w <= 0 || h <= 0) return;  // minimised
  if (v.dirty) update_pose(v);
  // On screen the window's own multisampling smooths the edges (no
  // supersampled copy per frame); screenshots take afm-render's way.
  const afm_render_view view = current_view(v, w, h);
  const std::vector<afm_render_mesh> meshes = meshes_to_draw(v);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (afm_gl_draw(v.drawer, meshes.data(), meshes.size(), &view, 1) != AFM_OK)
    throw InputError(std::string("drawing fails: ") + afm_render_last_error());
  glfwSwapBuffers(v.window);
}

void advance(Viewer &v, double dt) {
  if (!v.playing || !v.has_stream) return;
  v.clock_s += dt * v.speed;
  long f = (long)std::floor(v.clock_s * stream_fps(v) + 1e-9);
  if (f >= v.frame_count) {
    // Looping: the last frame shows for one frame's time, then frame 0.
    v.clock_s = std::fmod(v.clock_s, (double)v.frame_count / stream_fps(v));
    f = (long)std::floor(v.clock_s * stream_fps(v) + 1e-9) % v.frame_count;
  }
  if (!v.loop && f >= v.frame_count - 1) {
    f = v.frame_count - 1;  // the end: nothing after the last frame
    v.playing = false;
  }
  if (f != v.frame) {
    v.frame = f;
    v.dirty = true;
  }
}

// GLFW reports errors through a callback; the last one explains a failure.
std::string glfw_error;
void on_glfw_error(int code, const char *description) {
  glfw_error = description ? description : "error " + std::to_string(code);
}

Viewer *viewer_of(GLFWwindow *w) { return static_cast<Viewer *>(glfwGetWindowUserPointer(w)); }

void install_callbacks(GLFWwindow *w) {
  glfwSetKeyCallback(w, [](GLFWwindow *win, int key, int, int action, int mods) {
    if (action == GLFW_PRESS || action == GLFW_REPEAT) on_key(*viewer_of(win), key, mods);
  });
  glfwSetCharCallback(w, [](GLFWwindow *win, unsigned cp) { on_char(*viewer_of(win), cp); });
  glfwSetMouseButtonCallback(w, [](GLFWwindow *win, int button, int action, int) {
    Viewer &v = *viewer_of(win);
    if (button != GLFW_MOUSE_BUTTON_LEFT) return;
    v.dragging = action == GLFW_PRESS;
    glfwGetCursorPos(win, &v.drag_x, &v.drag_y);
  });
  glfwSetCursorPosCallback(w, [](GLFWwindow *win, double x, double y) {
    Viewer &v = *viewer_of(win);
    if (!v.dragging) return;
    // Dragging turns the face with the mouse, as if held.
    v.yaw = (float)std::remainder(v.yaw - 0.4 * (x - v.drag_x), 360.0);
    v.pitch = (float)std::clamp(v.pitch + 0.4 * (y - v.drag_y), -89.0, 89.0);
    v.drag_x = x;
    v.drag_y = y;
  });
  glfwSetScrollCallback(w, [](GLFWwindow *win, double, double dy) {
    Viewer &v = *viewer_of(win);
    v.zoom = (float)std::clamp(v.zoom * std::pow(1.1, dy), 0.2, 20.0);
  });
}

#if defined(__SANITIZE_ADDRESS__)
// Closing the display unloads Mesa's GL driver, and LeakSanitizer, which
// checks at exit, can then name neither the library nor the function that
// kept memory, so no suppression matches. Under the sanitizers every library
// loaded so far stays loaded to the end (RTLD_NODELETE).
int pin_library(struct dl_phdr_info *info, size_t, void *) {
  if (info->dlpi_name && info->dlpi_name[0]) dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
  return 0;
}
void pin_loaded_libraries() { dl_iterate_phdr(pin_library, nullptr); }
#else
void pin_loaded_libraries() {}
#endif

struct Glfw {
  Glfw() {
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit())
      throw InputError("cannot open a window: " + glfw_error +
                       " (afm-view needs a display: set DISPLAY, or run it under Xvfb)");
  }
  ~Glfw() {
    pin_loaded_libraries();
    glfwTerminate();
  }
};

int run(const Options &o) {
  // Inputs first: a bad file is reported without a window.
  const afm_face::Doc doc = afm_face::load_model(o.model);
  Viewer v;
  v.opt = o;
  v.doc = doc.get();
  if (!o.stream.empty()) {
    v.stream = afm_face::load_stream(o.stream);
    const afm_fap_header &hd = v.stream.header;
    if (hd.fps_num == 0 || hd.fps_den == 0) throw InputError(o.stream + ": line 1: the frame rate is 0");
    if (afm_fap_cursor_init(&v.cursor, v.stream.frames.data(), (uint32_t)v.stream.frames.size(), hd.fps_num,
                            hd.fps_den, o.view.mirror) != AFM_OK)
      throw InputError(o.stream + ": cannot play");
    const uint64_t duration = afm_fap_cursor_duration_us(&v.cursor);
    v.frame_count = 1;
    while (afm_face::frame_time_us((uint64_t)v.frame_count, hd.fps_num, hd.fps_den) <= duration) ++v.frame_count;
    v.has_stream = true;
    if (o.frame >= v.frame_count)
      throw UsageError("--frame " + std::to_string(o.frame) + ": " + o.stream + " has frames 0 to " +
                       std::to_string(v.frame_count - 1));
  }
  afm_face::init_face(v.face, *doc, afm_face::face_options(o.view, o.model));
  v.neutral = v.face.positions;
  for (const Setting &s : o.sets) set_control(v.live, s.control, s.value);
  if (!o.sets.empty()) v.selected = o.sets.back().control;
  v.loop = o.loop;
  v.speed = o.speed;
  v.wireframe = o.wireframe;
  v.moved_only = o.moved;
  reset_camera(v);
  seek_frame(v, o.frame);
  v.playing = v.has_stream && !o.paused;

  Glfw glfw;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  glfwWindowHint(GLFW_SAMPLES, 4);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  v.window = glfwCreateWindow(o.view.width, o.view.height, "afm-view", nullptr, nullptr);
  if (!v.window) {
    // Without multisampling, when the display offers none.
    glfwWindowHint(GLFW_SAMPLES, 0);
    v.window = glfwCreateWindow(o.view.width, o.view.height, "afm-view", nullptr, nullptr);
  }
  if (!v.window) throw InputError("cannot open a window with OpenGL 2.1: " + glfw_error);
  glfwMakeContextCurrent(v.window);
  glfwSwapInterval(1);
  glfwSetWindowUserPointer(v.window, &v);
  install_callbacks(v.window);
  if (afm_gl_drawer_create(&v.drawer) != AFM_OK)
    throw InputError(std::string("cannot draw: ") + afm_render_last_error());
  struct DrawerFree {
    afm_gl_drawer *d;
    ~DrawerFree() { afm_gl_drawer_destroy(d); }
  } drawer_free{v.drawer};

  for (const std::string &k : o.keys) press(v, k);
  long drawn = 0;
  std::string last_title;
  double last = glfwGetTime();
  while (!v.quit && !glfwWindowShouldClose(v.window)) {
    const double now = glfwGetTime();
    // Scripted runs repeat exactly: their clock moves one stream frame per
    // drawn frame (times the speed).
    advance(v, o.exit_after ? (v.has_stream ? 1.0 / stream_fps(v) : 0.0) : now - last);
    last = now;
    if (v.dirty) update_pose(v);
    const std::string t = title(v);
    if (t != last_title) glfwSetWindowTitle(v.window, t.c_str()), last_title = t;
    draw_window(v);
    ++drawn;
    if (drawn == o.frames) {
      if (!o.screenshot.empty()) write_screenshot(v, o.screenshot);
      if (o.exit_after) {
        std::printf("%s\n", t.c_str());
        break;
      }
    }
    // Playing: as fast as frames come (vsync paces it); else wait for input.
    if (v.playing) glfwPollEvents();
    else glfwWaitEventsTimeout(0.25);
  }
  glfwDestroyWindow(v.window);
  return 0;
}

}  // namespace

// The window system's libraries (Mesa's GLX and DRI drivers, X11, GLFW) may
// keep allocations to the end; with them pinned (pin_loaded_libraries)
// LeakSanitizer can attribute such memory, and this hook, which it reads its
// default suppressions from, leaves it to them, as ports/osmesa/src/render.c
// does for OSMesa. Mesa 22.3 under Xvfb leaks nothing it reports once pinned.
// Harmless without the sanitizers.
extern "C" const char *__lsan_default_suppressions(void);
extern "C" const char *__lsan_default_suppressions(void) {
  return "leak:libGLX_mesa.so\nleak:swrast_dri.so\nleak:libgallium\nleak:libX11.so\nleak:libglfw.so\n"
         "leak:libLLVM\nleak:libdrm\nleak:libxcb\n";
}

int main(int argc, char **argv) {
  return afm_face::run_tool("afm-view", [&] {
    bool help = false;
    const Options o = parse_args(argc, argv, &help);
    if (help) {
      usage(stdout);
      return 0;
    }
    return run(o);
  });
}
