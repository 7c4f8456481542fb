// VRML97 reader and writer: the Song head from ../shared/data, small
// hand-written scenes, bad input, round trips.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../common/test_paths.h"
#include "core/scene.h"
#include "io/vrml.h"

namespace {

using afmb::PartKind;
using afmb::Scene;

// ---- an independent look at song.WRL's text -----------------------------------
// Deliberately naive: it relies on the file's own layout (one DEF'd Transform
// per part, "point [ ... ]" and "coordIndex [ ... ]" blocks), not on the
// reader under test.
struct TextPart {
  std::string name;
  int points = 0;
  int texcoords = 0;
  int polygons = 0;
  int triangles = 0;  // after fan triangulation: sum of (corners - 2)
  std::string url;
  double first[3] = {0, 0, 0};
};

std::vector<double> numbers_in(const std::string &s) {
  std::vector<double> out;
  std::string clean = s;
  for (char &c : clean)
    if (c == ',') c = ' ';
  std::istringstream in(clean);
  double v;
  while (in >> v) out.push_back(v);
  return out;
}

// The bracketed block after the first `key` at or after `from` in `text`.
std::string block_after(const std::string &text, const std::string &key, size_t from, size_t to) {
  size_t k = text.find(key, from);
  if (k == std::string::npos || k >= to) return {};
  size_t open = text.find('[', k);
  size_t close = text.find(']', open);
  return text.substr(open + 1, close - open - 1);
}

std::vector<TextPart> scan_song(const std::string &text) {
  std::vector<TextPart> parts;
  std::vector<size_t> starts;
  for (size_t p = text.find("DEF "); p != std::string::npos; p = text.find("DEF ", p + 1)) {
    size_t e = text.find(' ', p + 4);
    if (text.compare(e, 11, " Transform ") == 0) starts.push_back(p);
  }
  for (size_t i = 0; i < starts.size(); ++i) {
    const size_t from = starts[i], to = i + 1 < starts.size() ? starts[i + 1] : text.size();
    TextPart t;
    size_t e = text.find(' ', from + 4);
    t.name = text.substr(from + 4, e - from - 4);
    std::vector<double> pts = numbers_in(block_after(text, "Coordinate {", from, to));
    t.points = static_cast<int>(pts.size() / 3);
    for (int k = 0; k < 3 && k < static_cast<int>(pts.size()); ++k) t.first[k] = pts[k];
    t.texcoords = static_cast<int>(numbers_in(block_after(text, "TextureCoordinate {", from, to)).size() / 2);
    std::vector<double> idx = numbers_in(block_after(text, " coordIndex [", from, to));
    int corners = 0;
    for (double v : idx) {
      if (v == -1) {
        ++t.polygons;
        t.triangles += corners - 2;
        corners = 0;
      } else {
        ++corners;
      }
    }
    if (corners > 0) {
      ++t.polygons;
      t.triangles += corners - 2;
    }
    size_t u = text.find("url \"", from);
    if (u != std::string::npos && u < to) {
      size_t q = text.find('"', u + 5);
      t.url = text.substr(u + 5, q - u - 5);
    }
    parts.push_back(t);
  }
  return parts;
}

// The Song line of SOURCES.md: "... 6379 vertices: head 2916, hair 2707,
// eyeballs 145+145, tongue 117, upper/lower eyelid-brow strips 110/90,
// throat 71, teeth 39+39 ...".
struct SongCounts {
  int parts = 0, total = 0, head = 0, hair = 0, eye_a = 0, eye_b = 0, tongue = 0;
  int strip_upper = 0, strip_lower = 0, throat = 0, teeth_a = 0, teeth_b = 0;
};

// The integer right after `key` in `line` (then, with `second`, the one after
// the separator that follows), or -1.
int number_after(const std::string &line, const std::string &key, int *second = nullptr) {
  size_t k = line.find(key);
  if (k == std::string::npos) return -1;
  const char *p = line.c_str() + k + key.size();
  char *end = nullptr;
  const long a = std::strtol(p, &end, 10);
  if (end == p) return -1;
  if (second) *second = static_cast<int>(std::strtol(end + 1, nullptr, 10));
  return static_cast<int>(a);
}

// The integer right before `key` in `line`, or -1.
int number_before(const std::string &line, const std::string &key) {
  size_t k = line.find(key);
  if (k == std::string::npos || k == 0) return -1;
  size_t b = k;
  while (b > 0 && std::isdigit(static_cast<unsigned char>(line[b - 1]))) --b;
  return b == k ? -1 : std::atoi(line.c_str() + b);
}

bool song_counts(SongCounts *c) {
  std::istringstream doc(afmtest::read_file(afmtest::shared_data("SOURCES.md")));
  std::string line;
  while (std::getline(doc, line) && line.find("faces/song/") == std::string::npos) {
  }
  c->parts = number_before(line, " IndexedFaceSet parts");
  c->total = number_before(line, " vertices: head");
  c->head = number_after(line, "head ");
  c->hair = number_after(line, "hair ");
  c->eye_a = number_after(line, "eyeballs ", &c->eye_b);
  c->tongue = number_after(line, "tongue ");
  c->strip_upper = number_after(line, "strips ", &c->strip_lower);
  c->throat = number_after(line, "throat ");
  c->teeth_a = number_after(line, "teeth ", &c->teeth_b);
  for (int v : {c->parts, c->total, c->head, c->hair, c->eye_a, c->eye_b, c->tongue, c->strip_upper,
                c->strip_lower, c->throat, c->teeth_a, c->teeth_b})
    if (v <= 0) return false;
  return true;
}

int rows(const Scene &s, const char *name) {
  int i = s.find_part(name);
  return i < 0 ? -1 : static_cast<int>(s.parts[i].V.rows());
}

// ---- Song ----------------------------------------------------------------------

TEST(Vrml, SongPartsMatchSourcesMd) {
  AFM_REQUIRE_SHARED_DATA();
  SongCounts c;
  ASSERT_TRUE(song_counts(&c)) << "SOURCES.md no longer states the Song counts in the expected words";
  auto scene = afmb::read_vrml(afmtest::shared_data("faces/song/song.WRL"));
  ASSERT_TRUE(scene) << scene.status().message();
  EXPECT_EQ(static_cast<int>(scene->parts.size()), c.parts);
  EXPECT_EQ(static_cast<int>(scene->vertex_count()), c.total);
  EXPECT_EQ(rows(*scene, "song_head"), c.head);
  EXPECT_EQ(rows(*scene, "song_hair3"), c.hair);
  EXPECT_EQ(rows(*scene, "song_eyeball_left") + rows(*scene, "song_eyeball_right"), c.eye_a + c.eye_b);
  EXPECT_EQ(rows(*scene, "song_eyeball_left"), c.eye_a);
  EXPECT_EQ(rows(*scene, "song_tongue"), c.tongue);
  EXPECT_EQ(rows(*scene, "song_eyeblow_upper"), c.strip_upper);
  EXPECT_EQ(rows(*scene, "song_eyeblow_lower"), c.strip_lower);
  EXPECT_EQ(rows(*scene, "song_throat"), c.throat);
  EXPECT_EQ(rows(*scene, "song_teeth_upper"), c.teeth_a);
  EXPECT_EQ(rows(*scene, "song_teeth_lower"), c.teeth_b);
  EXPECT_EQ(scene->name, "song");
}

TEST(Vrml, SongMatchesIndependentTextScan) {
  AFM_REQUIRE_SHARED_DATA();
  const std::string path = afmtest::shared_data("faces/song/song.WRL");
  const std::vector<TextPart> text = scan_song(afmtest::read_file(path));
  auto scene = afmb::read_vrml(path);
  ASSERT_TRUE(scene) << scene.status().message();
  ASSERT_EQ(text.size(), scene->parts.size());
  for (size_t i = 0; i < text.size(); ++i) {
    const afmb::Part &p = scene->parts[i];
    SCOPED_TRACE(text[i].name);
    EXPECT_EQ(p.name, text[i].name);
    EXPECT_EQ(p.V.rows(), text[i].points);
    EXPECT_EQ(p.F.rows(), text[i].triangles);
    EXPECT_EQ(p.texture, text[i].url);
    EXPECT_EQ(p.TC.rows(), text[i].texcoords);
    EXPECT_EQ(p.FTC.rows(), p.F.rows());
    // The IndexedFaceSet's DEF is an alias (XfaceEd FDP files use it).
    EXPECT_EQ(scene->find_part(text[i].name + "-FACES"), static_cast<int>(i));
    ASSERT_GT(p.V.rows(), 0);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(p.V(0, k), text[i].first[k]);
    // Every texture the file names is beside it.
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(path).parent_path() / p.texture)) << p.texture;
    EXPECT_LE(p.F.maxCoeff(), p.V.rows() - 1);
    EXPECT_GE(p.F.minCoeff(), 0);
  }
  const int head = scene->find_part("song_head");
  ASSERT_GE(head, 0);
  EXPECT_GT(scene->parts[head].TC.rows(), 0);
  EXPECT_EQ(scene->parts[head].texture, "front.tga");
}

TEST(Vrml, SongKindsFromNames) {
  AFM_REQUIRE_SHARED_DATA();
  auto scene = afmb::read_vrml(afmtest::shared_data("faces/song/song.WRL"));
  ASSERT_TRUE(scene) << scene.status().message();
  auto kind = [&](const char *n) { return scene->parts[scene->find_part(n)].kind; };
  EXPECT_EQ(kind("song_head"), PartKind::Skin);
  EXPECT_EQ(kind("song_eyeball_left"), PartKind::EyeLeft);
  EXPECT_EQ(kind("song_eyeball_right"), PartKind::EyeRight);
  EXPECT_EQ(kind("song_teeth_upper"), PartKind::TeethUpper);
  EXPECT_EQ(kind("song_teeth_lower"), PartKind::TeethLower);
  EXPECT_EQ(kind("song_tongue"), PartKind::Tongue);
  EXPECT_EQ(kind("song_hair3"), PartKind::Hair);
  EXPECT_EQ(kind("song_eyeblow_upper"), PartKind::Eyelid);
  EXPECT_EQ(kind("song_eyeblow_lower"), PartKind::Eyelid);
  EXPECT_EQ(kind("song_throat"), PartKind::Mouth);
}

TEST(Vrml, SongParsesQuickly) {
  AFM_REQUIRE_SHARED_DATA();
  const std::string text = afmtest::read_file(afmtest::shared_data("faces/song/song.WRL"));
  const auto t0 = std::chrono::steady_clock::now();
  auto scene = afmb::parse_vrml(text, "song.WRL");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(scene) << scene.status().message();
  RecordProperty("song_parse_ms", std::to_string(s * 1000));
  std::printf("song.WRL (%zu bytes) parsed in %.1f ms\n", text.size(), s * 1000);
#if defined(NDEBUG) && !defined(__SANITIZE_ADDRESS__)
  EXPECT_LT(s, 0.5);
#else
  EXPECT_LT(s, 30.0);
#endif
}

TEST(Vrml, SongRoundTrip) {
  AFM_REQUIRE_SHARED_DATA();
  auto a = afmb::read_vrml(afmtest::shared_data("faces/song/song.WRL"));
  ASSERT_TRUE(a) << a.status().message();
  const std::string out = afmtest::temp_dir("vrml_song_round_trip") + "/song_out.wrl";
  ASSERT_TRUE(afmb::write_vrml(*a, out)) << "write failed";
  auto b = afmb::read_vrml(out);
  ASSERT_TRUE(b) << b.status().message();
  ASSERT_EQ(a->parts.size(), b->parts.size());
  for (size_t i = 0; i < a->parts.size(); ++i) {
    const afmb::Part &p = a->parts[i], &q = b->parts[i];
    SCOPED_TRACE(p.name);
    EXPECT_EQ(p.name, q.name);
    ASSERT_FALSE(q.aliases.empty());
    EXPECT_EQ(p.aliases[0], q.aliases[0]);
    EXPECT_EQ(p.kind, q.kind);
    EXPECT_EQ(p.texture, q.texture);
    EXPECT_EQ(p.diffuse, q.diffuse);
    EXPECT_EQ(p.V, q.V);  // shortest exact decimal form: bit for bit
    EXPECT_EQ(p.F, q.F);
    EXPECT_EQ(p.TC, q.TC);
    EXPECT_EQ(p.FTC, q.FTC);
  }
  // Nothing left behind by the atomic write.
  int files = 0;
  for (const auto &e : std::filesystem::directory_iterator(std::filesystem::path(out).parent_path())) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
}

// ---- small scenes ----------------------------------------------------------------

const char *kTriangle = R"(#VRML V2.0 utf8
# a comment, then commas as whitespace
DEF tri Transform {
  children [
    Shape {
      geometry IndexedFaceSet {
        coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] }
        coordIndex [ 0, 1, 2, -1 ]
      }
    }
  ]
}
)";

TEST(Vrml, TransformsApplyInVrmlOrder) {
  // translation 10 0 0, rotation 90 degrees about z, scale 2: (1,0,0) -> scale
  // (2,0,0) -> rotate (0,2,0) -> translate (10,2,0). Nested in a parent that
  // moves by 0 0 5.
  const char *text = R"(#VRML V2.0 utf8
Transform { translation 0 0 5 children [
  DEF inner Transform {
    translation 10 0 0
    rotation 0 0 1 1.5707963267948966
    scale 2 2 2
    children Shape { geometry IndexedFaceSet {
      coord Coordinate { point [ 0 0 0  1 0 0  0 1 0 ] }
      coordIndex [ 0 1 2 ]
    } }
  }
] }
)";
  auto s = afmb::parse_vrml(text, "t.wrl");
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 1u);
  const auto &V = s->parts[0].V;
  EXPECT_EQ(s->parts[0].name, "inner");
  EXPECT_NEAR((V.row(0) - Eigen::RowVector3d(10, 0, 5)).norm(), 0, 1e-12);
  EXPECT_NEAR((V.row(1) - Eigen::RowVector3d(10, 2, 5)).norm(), 0, 1e-12);
  EXPECT_NEAR((V.row(2) - Eigen::RowVector3d(8, 0, 5)).norm(), 0, 1e-12);
  // A missing final -1 still closes the polygon.
  EXPECT_EQ(s->parts[0].F.rows(), 1);
}

TEST(Vrml, CenterAndScaleOrientation) {
  // center 1 0 0 with rotation 180 degrees about z: (0,0,0) -> (2,0,0).
  // scale 3 1 1 along an axis rotated 90 degrees about z scales y by 3.
  const char *text = R"(#VRML V2.0 utf8
DEF a Transform { center 1 0 0 rotation 0 0 1 3.141592653589793
  children Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 1 1 0 ] } coordIndex [ 0 1 2 -1 ] } } }
DEF b Transform { scale 3 1 1 scaleOrientation 0 0 1 1.5707963267948966
  children Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 1 0, 1 0 0, 0 0 1 ] } coordIndex [ 0 1 2 -1 ] } } }
)";
  auto s = afmb::parse_vrml(text, "t.wrl");
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 2u);
  EXPECT_NEAR((s->parts[0].V.row(0) - Eigen::RowVector3d(2, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((s->parts[0].V.row(1) - Eigen::RowVector3d(1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((s->parts[1].V.row(0) - Eigen::RowVector3d(0, 3, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((s->parts[1].V.row(1) - Eigen::RowVector3d(1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((s->parts[1].V.row(2) - Eigen::RowVector3d(0, 0, 1)).norm(), 0, 1e-12);
}

TEST(Vrml, PolygonsCcwColoursAndTexcoords) {
  const char *text = R"(#VRML V2.0 utf8
DEF quad Transform { children [ Shape {
  appearance Appearance {
    material Material { diffuseColor 0.25 0.5 1 }
    texture ImageTexture { url [ "skin.png" "other.png" ] repeatS FALSE }
  }
  geometry DEF quad-FACES IndexedFaceSet {
    ccw FALSE
    solid FALSE
    creaseAngle 0.5
    coord Coordinate { point [ 0 0 0, 1 0 0, 1 1 0, 0 1 0 ] }
    coordIndex [ 0 1 2 3 -1 ]
    texCoord TextureCoordinate { point [ 0 0, 1 0, 1 1, 0 1 ] }
    texCoordIndex [ 3 2 1 0 -1 ]
    color Color { color [ 1 0 0, 0 1 0, 0 0 1, 1 1 1 ] }
    normal Normal { vector [ 0 0 1 ] }
  }
} ] }
)";
  auto s = afmb::parse_vrml(text, "q.wrl");
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 1u);
  const afmb::Part &p = s->parts[0];
  EXPECT_EQ(p.name, "quad");
  EXPECT_EQ(p.aliases, std::vector<std::string>{"quad-FACES"});
  EXPECT_EQ(p.texture, "skin.png");
  EXPECT_EQ(p.diffuse, Eigen::Vector3d(0.25, 0.5, 1));
  // Fan from the first corner, flipped for ccw FALSE.
  Eigen::MatrixXi F(2, 3), FTC(2, 3);
  F << 0, 2, 1, 0, 3, 2;
  FTC << 3, 1, 2, 3, 0, 1;
  EXPECT_EQ(p.F, F);
  EXPECT_EQ(p.FTC, FTC);
  ASSERT_EQ(p.C.rows(), 4);
  EXPECT_EQ(p.C.row(2), Eigen::RowVector3d(0, 0, 1));
}

TEST(Vrml, DefUseUnknownNodesProtosRoutes) {
  const char *text = R"(#VRML V2.0 utf8
WorldInfo { title "x" info [ "a { b" "c ] d" ] }
NavigationInfo { type [ "EXAMINE", "ANY" ] }
PROTO Thing [ field SFFloat size 1 ] { Group { children [ ] } }
EXTERNPROTO Far [ field SFFloat s ] [ "far.wrl#Far" ]
Thing { size 2 }
DEF clock TimeSensor { cycleInterval 3 }
Script { field SFNode n DEF hidden Material { } url "javascript: function f() { }" }
DEF shared Shape { geometry DEF mesh IndexedFaceSet {
  coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } }
DEF left Transform { translation -1 0 0 children [ USE shared ] }
DEF right Transform { translation 1 0 0 children [ USE shared ] }
Shape { appearance Appearance { material USE hidden } geometry IndexedFaceSet {
  coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } }
Shape { geometry IndexedFaceSet {
  coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } }
ROUTE clock.fraction_changed TO left.set_translation
)";
  auto s = afmb::parse_vrml(text, "dir/model.wrl");
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 5u);
  // The DEF'd Shape at top level, then its two instances under their
  // Transforms, then two un-DEF'd meshes named "<file>_<N>" XfaceEd-style.
  EXPECT_EQ(s->parts[0].name, "mesh");
  EXPECT_EQ(s->parts[1].name, "left");
  EXPECT_EQ(s->parts[2].name, "right");
  EXPECT_EQ(s->parts[1].V(1, 0), 0.0);
  EXPECT_EQ(s->parts[2].V(1, 0), 2.0);
  EXPECT_EQ(s->parts[3].name, "shape3");
  EXPECT_TRUE(s->parts[3].matches("model.wrl_0"));
  EXPECT_TRUE(s->parts[4].matches("model.wrl_1"));
  EXPECT_EQ(s->find_part("model.wrl_2"), -1);
}

TEST(Vrml, KeepsUnreferencedPointsForFdpIndices) {
  const char *text = R"(#VRML V2.0 utf8
Shape { geometry DEF m IndexedFaceSet { coord Coordinate { point [ 0 0 0, 5 5 5, 1 0 0, 0 1 0 ] } coordIndex [ 0 2 3 -1 ] } }
)";
  auto s = afmb::parse_vrml(text, "u.wrl");
  ASSERT_TRUE(s) << s.status().message();
  EXPECT_EQ(s->parts[0].V.rows(), 4);
  EXPECT_EQ(s->parts[0].V(1, 0), 5.0);
}

// ---- bad input -------------------------------------------------------------------

int line_of(const std::string &text, const std::string &needle) {
  size_t at = text.find(needle);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

TEST(VrmlErrors, CoordIndexOutOfRangeNamesFileAndLine) {
  const std::string text = std::string(kTriangle).replace(std::string(kTriangle).find("0, 1, 2, -1"), 11,
                                                          "0, 1,\n 9999, -1");
  auto s = afmb::parse_vrml(text, "bad.wrl");
  ASSERT_FALSE(s);
  const std::string want = "bad.wrl:" + std::to_string(line_of(text, "9999")) +
                           ": coordIndex 9999 out of range (3 points)";
  EXPECT_EQ(s.status().message(), want);
}

TEST(VrmlErrors, UnterminatedBracketNamesWhereItOpened) {
  const std::string text = "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\n"
                           "  coord Coordinate { point [ 0 0 0, 1 0 0,\n  0 1 0\n";
  auto s = afmb::parse_vrml(text, "open.wrl");
  ASSERT_FALSE(s);
  EXPECT_NE(s.status().message().find("open.wrl:3:"), std::string::npos) << s.status().message();
  EXPECT_NE(s.status().message().find("never closed"), std::string::npos) << s.status().message();
}

TEST(VrmlErrors, MismatchedBracketNamesLine) {
  const std::string text = "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\n"
                           "  coord Coordinate { point [ 0 0 0, 1 0 0 }\n} }\n";
  auto s = afmb::parse_vrml(text, "mm.wrl");
  ASSERT_FALSE(s);
  EXPECT_NE(s.status().message().find("mm.wrl:3:"), std::string::npos) << s.status().message();
}

TEST(VrmlErrors, OthersNameFileAndLine) {
  struct Case {
    const char *text;
    const char *want;
  } cases[] = {
      {"#VRML V1.0 ascii\nSeparator { }\n", "v1.wrl:1: VRML 1.0 is not supported"},
      {"solid x\n", "v1.wrl:1: not a VRML97 file"},
      {"#VRML V2.0 utf8\n\nTransform { children [ USE nothing ] }\n", "v1.wrl:3: USE of undefined name 'nothing'"},
      {"#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0 1 ] } } }\n",
       "v1.wrl:2: Coordinate point has 4 numbers, not a multiple of 3"},
      {"#VRML V2.0 utf8\nWorldInfo { title \"never closed }\n", "v1.wrl:2: string opened here is never closed"},
      {"#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\n coord Coordinate { point [ 0 0 0, 1 0 0 ] }\n"
       " coordIndex [ 0 1 -1 ] } }\n",
       "v1.wrl:4: polygon of 2 in coordIndex"},
      {"#VRML V2.0 utf8\nTransform { translation 1 2 3x }\n", "v1.wrl:2: malformed number '3x'"},
      {"#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coordIndex [ 0 1 2 ] } }\n",
       "v1.wrl:2: IndexedFaceSet has no Coordinate"},
      {"#VRML V2.0 utf8\nGroup { children [\n Inline { url \"head.wrl\" } ] }\n",
       "v1.wrl:3: Inline is not supported"},
      {"#VRML V2.0 utf8\nViewpoint { position 0 0 10 }\n", "v1.wrl: no IndexedFaceSet in the scene"},
  };
  for (const Case &c : cases) {
    auto s = afmb::parse_vrml(c.text, "v1.wrl");
    ASSERT_FALSE(s) << c.text;
    EXPECT_EQ(s.status().message().rfind(c.want, 0), 0u) << s.status().message();
  }
}

TEST(VrmlErrors, MissingFile) {
  const std::string path = afmtest::temp_dir("vrml_missing") + "/nope.wrl";
  auto s = afmb::read_vrml(path);
  ASSERT_FALSE(s);
  EXPECT_NE(s.status().message().find(path), std::string::npos) << s.status().message();
}

TEST(Vrml, WriteRoundTripSmallWithColoursAndOddNames) {
  Scene s;
  s.name = "small";
  afmb::Part p;
  p.name = "my part 1";  // not a VRML identifier: written as my_part_1
  p.V.resize(3, 3);
  p.V << 0.1, 0.2, 0.3, 1e-7, -2.5, 1e10, 0, 1, 0;
  p.F.resize(1, 3);
  p.F << 0, 1, 2;
  p.C.resize(3, 3);
  p.C << 1, 0, 0, 0, 1, 0, 0, 0, 1;
  p.texture = "a \"quoted\" name.png";
  s.parts.push_back(p);
  const std::string out = afmtest::temp_dir("vrml_small") + "/small.wrl";
  ASSERT_TRUE(afmb::write_vrml(s, out));
  auto r = afmb::read_vrml(out);
  ASSERT_TRUE(r) << r.status().message();
  ASSERT_EQ(r->parts.size(), 1u);
  EXPECT_EQ(r->parts[0].name, "my_part_1");
  EXPECT_EQ(r->parts[0].V, p.V);
  EXPECT_EQ(r->parts[0].F, p.F);
  EXPECT_EQ(r->parts[0].C, p.C);
  EXPECT_EQ(r->parts[0].texture, p.texture);
  EXPECT_EQ(r->parts[0].TC.rows(), 0);
}

TEST(Vrml, WriteFailsCleanlyInMissingDirectory) {
  Scene s;
  const std::string out = afmtest::temp_dir("vrml_nodir") + "/no/such/dir/x.wrl";
  afmb::Status st = afmb::write_vrml(s, out);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find(out), std::string::npos) << st.message();
}

}  // namespace
