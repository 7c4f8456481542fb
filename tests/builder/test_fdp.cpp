// FDP ids, sets, binding, and the three FDP file forms of formats/fdp.md.
#include "core/fdp.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "../common/csv.h"
#include "../common/test_paths.h"
#include "io/fdp_io.h"
#include "test_fdp_helpers.h"

namespace {

using afmb::FdpFormat;
using afmb::FdpId;
using afmb::FdpPoint;
using afmb::FdpSet;
using afmb::Scene;

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

FdpPoint vertex_point(int g, int i, const std::string &part, int vertex, int line = 0) {
  FdpPoint p;
  p.id = FdpId{g, i};
  p.part_name = part;
  p.vertex = vertex;
  p.line = line;
  return p;
}

FdpPoint free_point(int g, int i, double x, double y, double z, int line = 0) {
  FdpPoint p;
  p.id = FdpId{g, i};
  p.pos = Eigen::Vector3d(x, y, z);
  p.line = line;
  return p;
}

Scene small_scene() {
  Scene s;
  s.name = "small";
  s.source = "/some/dir/small.wrl";
  s.parts.push_back(fdptest::numbered_part("head", 10, {"head-FACES", "small.wrl_0"}));
  s.parts.push_back(fdptest::numbered_part("eye_l", 4, {"eye_l-FACES"}));
  s.parts.push_back(fdptest::numbered_part("teeth", 6));
  return s;
}

// "<entries>" of an FDP set as "vertex@part" per FDP, like the reference CSV.
std::map<std::string, std::multiset<std::string>> entries_of(const FdpSet &set) {
  std::map<std::string, std::multiset<std::string>> out;
  for (const FdpPoint &p : set.points) out[p.id.str()].insert(std::to_string(p.vertex) + "@" + p.part_name);
  return out;
}

// ---- FdpId, FdpSet -------------------------------------------------------------

TEST(FdpId, ParsesAndPrintsStandardNames) {
  auto id = FdpId::parse("2.10");
  ASSERT_TRUE(id);
  EXPECT_EQ(id->group, 2);
  EXPECT_EQ(id->index, 10);
  EXPECT_EQ(id->str(), "2.10");
  EXPECT_EQ(FdpId::parse("11.6")->str(), "11.6");
  for (const char *bad : {"2.0", "2.15", "12.1", "13.1", "2.99", "2.1x", "", " 2.1", "2.01"})
    EXPECT_FALSE(FdpId::parse(bad)) << bad;
  EXPECT_TRUE((FdpId{2, 1} < FdpId{2, 10}));
  EXPECT_TRUE((FdpId{2, 14} < FdpId{3, 1}));
  EXPECT_TRUE((FdpId{3, 1} != FdpId{3, 2}));
}

TEST(FdpSet, FindPrefersThePartAndCountsDistinctIds) {
  FdpSet set;
  set.points.push_back(vertex_point(2, 1, "head", 3));
  set.points.push_back(vertex_point(2, 1, "teeth", 2));
  set.points.push_back(vertex_point(3, 5, "eye_l", 0));
  set.points[0].part = 0;
  set.points[1].part = 2;
  set.points[2].part = 1;
  EXPECT_EQ(set.distinct_count(), 2u);
  EXPECT_EQ(set.find(FdpId{2, 1}), &set.points[0]);
  EXPECT_EQ(set.find(FdpId{2, 1}, 2), &set.points[1]);
  EXPECT_EQ(set.find(FdpId{2, 1}, 1), &set.points[0]);  // none on part 1: the first
  EXPECT_EQ(set.find(FdpId{9, 15}), nullptr);
  EXPECT_EQ(FdpSet().distinct_count(), 0u);
}

// ---- bind_fdps -----------------------------------------------------------------

TEST(BindFdps, ResolvesNamesAliasesIndicesAndKeepsFreePoints) {
  Scene scene = small_scene();
  FdpSet set;
  set.source = "t.fdp";
  set.points.push_back(vertex_point(2, 1, "head", 7, 1));
  set.points.push_back(vertex_point(3, 5, "eye_l-FACES", 3, 2));
  set.points.push_back(vertex_point(2, 3, "small.wrl_0", 1, 3));
  set.points.push_back(vertex_point(2, 2, "@2", 5, 4));
  set.points.push_back(free_point(7, 1, 0.5, -1.5, 2.5, 5));
  afmb::Status s = afmb::bind_fdps(set, scene);
  ASSERT_TRUE(s) << s.message();
  EXPECT_EQ(set.points[0].part, 0);
  EXPECT_EQ(set.points[0].pos, Eigen::Vector3d(7, 14, 21));
  EXPECT_EQ(set.points[1].part, 1);
  EXPECT_EQ(set.points[1].pos, Eigen::Vector3d(3, 6, 9));
  EXPECT_EQ(set.points[2].part, 0);
  EXPECT_EQ(set.points[3].part, 2);
  EXPECT_EQ(set.points[3].pos, Eigen::Vector3d(5, 10, 15));
  EXPECT_EQ(set.points[4].part, -1);
  EXPECT_EQ(set.points[4].vertex, -1);
  EXPECT_EQ(set.points[4].pos, Eigen::Vector3d(0.5, -1.5, 2.5));
}

TEST(BindFdps, ErrorsNameFileLineFdpPartAndVertexCount) {
  Scene scene = small_scene();
  FdpSet set;
  set.source = "song.fdp";
  set.points.push_back(vertex_point(2, 1, "head", 1, 56));
  set.points.push_back(vertex_point(2, 2, "foo", 1, 57));
  afmb::Status s = afmb::bind_fdps(set, scene);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message().rfind("song.fdp:57: FDP 2.2: part 'foo' not in small.wrl", 0), 0u) << s.message();
  EXPECT_TRUE(contains(s.message(), "head, eye_l, teeth")) << s.message();

  set.points[1] = vertex_point(3, 6, "eye_l", 4, 58);
  s = afmb::bind_fdps(set, scene);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.message(), "song.fdp:58: FDP 3.6: vertex 4 out of range: part 'eye_l' has 4 vertices");

  set.points[1] = vertex_point(3, 6, "@3", 0, 59);  // only 3 parts
  s = afmb::bind_fdps(set, scene);
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "song.fdp:59: FDP 3.6: part '@3' not in small.wrl")) << s.message();
}

// ---- Free points attached to the mesh ------------------------------------------

// A skin with a closed mouth's two coincident inner-lip vertices (1 above the
// slit's line, 2 below: each has its own triangle), an eye part whose front
// vertex lies just behind a lid vertex, and a second skin vertex at vertex 3's
// place that no triangle uses.
Scene lips_scene() {
  Scene s;
  afmb::Part skin;
  skin.name = "face";
  skin.V.resize(7, 3);
  skin.V << 0, 0, 0,  //
      1, 0, 0,        // upper inner lip
      1, 0, 0,        // lower inner lip, same place
      0, 5, 0,        //
      0, -5, 0,       //
      3, 3, 1,        // a lid vertex
      0, 5, 0;        // vertex 3 again, unused
  skin.F.resize(2, 3);
  skin.F << 0, 1, 3,  // above: the upper lip's triangle
      0, 4, 2;        // below: the lower lip's
  skin.kind = afmb::PartKind::Skin;
  afmb::Part eye;
  eye.name = "eye_left";
  eye.kind = afmb::PartKind::EyeLeft;
  eye.V.resize(2, 3);
  eye.V << 3, 3, 0.99,  // 0.01 behind the lid vertex
      3, 3, 0;
  s.parts = {skin, eye};
  return s;
}

TEST(AttachFreeFdps, PutsEachOnTheVertexOfItsOwnPartAndSide) {
  const Scene scene = lips_scene();
  FdpSet set;
  set.points.push_back(free_point(2, 3, 1, 0, 1e-7, 1));       // the lower lip's point, printed to 7 places
  set.points.push_back(free_point(2, 2, 1, 0, 0, 2));          // the upper lip's, at the same place
  set.points.push_back(free_point(3, 1, 3, 3, 0.995, 3));      // a lid point: the skin, though the eye is as near
  set.points.push_back(free_point(3, 5, 3, 3, 1, 4));          // the pupil: the eye, though the skin is nearer
  set.points.push_back(free_point(7, 1, 0, 0, -3, 5));         // the spine, inside: stays free
  set.points.push_back(free_point(9, 3, 0, 5, 0.001, 6));      // vertex 3, not its unused copy 6
  set.points.push_back(vertex_point(2, 1, "face", 0, 7));      // 2.1 already on the skin...
  set.points.push_back(free_point(2, 1, 0, 0, 0, 8));          // ...so this one stays free
  ASSERT_TRUE(afmb::bind_fdps(set, scene));
  const afmb::FreeFdpAttachment a = afmb::attach_free_fdps(set, scene, 0.05);
  EXPECT_EQ(a.attached, 5);
  auto on = [&](size_t k, int part, int vertex) {
    EXPECT_EQ(set.points[k].part, part) << set.points[k].id.str();
    EXPECT_EQ(set.points[k].vertex, vertex) << set.points[k].id.str();
    if (part >= 0) {
      EXPECT_EQ(set.points[k].part_name, scene.parts[static_cast<size_t>(part)].name);
      EXPECT_EQ(set.points[k].pos, scene.parts[static_cast<size_t>(part)].V.row(vertex).transpose())
          << "an attached point takes its vertex's own position";
    }
  };
  on(0, 0, 2);
  on(1, 0, 1);
  on(2, 0, 5);
  on(3, 1, 0);
  on(4, -1, -1);
  on(5, 0, 3);
  on(7, -1, -1);
  ASSERT_EQ(a.free.size(), 2u);
  EXPECT_EQ(a.free[0]->id.str(), "7.1");
  EXPECT_EQ(a.free[1]->id.str(), "2.1");
  EXPECT_NEAR(a.farthest, 0.01, 1e-12);  // the pupil, in front of its eye's vertex
  ASSERT_TRUE(a.at);
  EXPECT_EQ(a.at->id.str(), "3.5");
  // Beyond the tolerance nothing is attached, and a scene without kinds
  // offers every part: the pupil then takes the nearest vertex, the skin's.
  FdpSet far;
  far.points.push_back(free_point(2, 2, 1, 0, 0.2, 1));
  EXPECT_EQ(afmb::attach_free_fdps(far, scene, 0.1).attached, 0);
  Scene plain = scene;
  for (afmb::Part &p : plain.parts) p.kind = afmb::PartKind::Other;
  FdpSet pupil;
  pupil.points.push_back(free_point(3, 5, 3, 3, 1, 1));
  EXPECT_EQ(afmb::attach_free_fdps(pupil, plain, 0.05).attached, 1);
  EXPECT_EQ(pupil.points[0].part, 0);
  EXPECT_EQ(pupil.points[0].vertex, 5);
}

// ---- XfaceEd files: the real song.fdp and alice.fdp ------------------------------

TEST(FdpXfaceEd, SongFdpHas53EntriesOn45FdpsAsTheReferenceLists) {
  AFM_REQUIRE_SHARED_DATA();
  AFM_REQUIRE_SHARED_REFERENCE();
  const std::string path = afmtest::shared_data("faces/song/song.fdp");
  auto r = afmb::read_fdp(path);
  ASSERT_TRUE(r) << r.status().message();
  const FdpSet &set = *r;
  EXPECT_EQ(set.source, path);
  EXPECT_EQ(set.points.size(), 53u);
  EXPECT_EQ(set.distinct_count(), 45u);

  // Stored FAPU: exactly the numbers the file's <fapu> element states.
  const std::string text = afmtest::read_file(path);
  ASSERT_TRUE(set.stored_fapu);
  EXPECT_EQ(set.stored_fapu->es0, std::strtod(fdptest::first_attribute(text, "fapu", "ES0").c_str(), nullptr));
  EXPECT_EQ(set.stored_fapu->irisd0, std::strtod(fdptest::first_attribute(text, "fapu", "IRISD0").c_str(), nullptr));
  EXPECT_EQ(set.stored_fapu->ens0, std::strtod(fdptest::first_attribute(text, "fapu", "ENS0").c_str(), nullptr));
  EXPECT_EQ(set.stored_fapu->mns0, std::strtod(fdptest::first_attribute(text, "fapu", "MNS0").c_str(), nullptr));
  EXPECT_EQ(set.stored_fapu->mw0, std::strtod(fdptest::first_attribute(text, "fapu", "MW0").c_str(), nullptr));
  EXPECT_GT(set.stored_fapu->es0, 0);

  // Every entry names one of the 10 IndexedFaceSets of song.WRL.
  std::set<std::string> parts =
      fdptest::vrml_face_set_names(afmtest::read_file(afmtest::shared_data("faces/song/song.WRL")));
  EXPECT_EQ(parts.size(), 10u);
  for (const FdpPoint &p : set.points) {
    EXPECT_TRUE(parts.count(p.part_name)) << p.id.str() << " on " << p.part_name;
    EXPECT_GT(p.line, 20);  // after the header, and known
    EXPECT_EQ(p.part, -1);  // unbound
  }

  // Entry by entry, the reference list (compiled independently of this code).
  auto want = fdptest::reference_entries("song_fdp_entries(index@submesh)");
  EXPECT_EQ(entries_of(set), want);

  // Line numbers point at the <fdp> element: 2.2 is the first one.
  EXPECT_EQ(set.points[0].id.str(), "2.2");
  size_t at = text.find("<fdp name=\"2.2\"");
  EXPECT_EQ(set.points[0].line, 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n')));
}

TEST(FdpXfaceEd, AliceFdpParsesAsTheReferenceLists) {
  AFM_REQUIRE_SHARED_DATA();
  AFM_REQUIRE_SHARED_REFERENCE();
  const std::string path = afmtest::shared_data("fdp/alice.fdp");
  auto r = afmb::read_fdp(path);
  ASSERT_TRUE(r) << r.status().message();
  const std::string text = afmtest::read_file(path);
  size_t elements = 0;
  for (size_t at = 0; (at = text.find("<fdp ", at)) != std::string::npos; ++at) ++elements;
  EXPECT_EQ(r->points.size(), elements);
  EXPECT_EQ(r->points.size(), 35u);
  EXPECT_EQ(entries_of(*r), fdptest::reference_entries("alice_fdp_entries(index@submesh)"));
  ASSERT_TRUE(r->stored_fapu);
  EXPECT_EQ(r->stored_fapu->ens0, std::strtod(fdptest::first_attribute(text, "fapu", "ENS0").c_str(), nullptr));
  EXPECT_EQ(r->stored_fapu->mw0, std::strtod(fdptest::first_attribute(text, "fapu", "MW0").c_str(), nullptr));
}

// ---- the text form ---------------------------------------------------------------

TEST(FdpText, ParsesVertexAndFreePointsCommentsAndFapu) {
  const char *text =
      "# a comment\r\n"
      "\n"
      "fapu 35.5 5.25 25 14 25.125   # trailing comment\r\n"
      "2.1 head 7\n"
      "  3.5\teye_l-FACES 3\n"
      "7.1 0.5 -1.5e-1 2\n";
  auto r = afmb::parse_fdp(text, "t.fdp");
  ASSERT_TRUE(r) << r.status().message();
  ASSERT_EQ(r->points.size(), 3u);
  ASSERT_TRUE(r->stored_fapu);
  EXPECT_EQ(r->stored_fapu->es0, 35.5);
  EXPECT_EQ(r->stored_fapu->irisd0, 5.25);
  EXPECT_EQ(r->stored_fapu->mw0, 25.125);
  EXPECT_EQ(r->points[0].id.str(), "2.1");
  EXPECT_EQ(r->points[0].part_name, "head");
  EXPECT_EQ(r->points[0].vertex, 7);
  EXPECT_EQ(r->points[0].line, 4);
  EXPECT_EQ(r->points[1].part_name, "eye_l-FACES");
  EXPECT_EQ(r->points[2].part_name, "");
  EXPECT_EQ(r->points[2].vertex, -1);
  EXPECT_EQ(r->points[2].pos, Eigen::Vector3d(0.5, -0.15, 2));
  EXPECT_EQ(r->points[2].line, 6);
}

TEST(FdpText, RoundTripsThroughWriteFdpText) {
  Scene scene = small_scene();
  FdpSet set;
  set.source = "orig.fdp";
  set.points.push_back(vertex_point(2, 1, "head-FACES", 7));
  set.points.push_back(vertex_point(2, 1, "@2", 5));
  set.points.push_back(vertex_point(3, 5, "eye_l", 3));
  set.points.push_back(free_point(7, 1, 0.1, -1.0 / 3.0, 1e-7));
  ASSERT_TRUE(afmb::bind_fdps(set, scene));
  afmb::Fapu fapu{32.72, 5.652, 25.18, 9.25, 25.48 + 1e-9};
  std::string dir = afmtest::temp_dir("fdp_text_roundtrip");
  std::string path = dir + "/out.fdp";
  afmb::Status s = afmb::write_fdp_text(set, scene, path, &fapu);
  ASSERT_TRUE(s) << s.message();
  auto r = afmb::read_fdp(path);
  ASSERT_TRUE(r) << r.status().message();
  ASSERT_EQ(r->points.size(), set.points.size());
  // Bound points come back under the scene's part names; free points exactly.
  const char *names[] = {"head", "teeth", "eye_l", ""};
  for (size_t k = 0; k < set.points.size(); ++k) {
    EXPECT_EQ(r->points[k].id, set.points[k].id);
    EXPECT_EQ(r->points[k].part_name, names[k]);
    EXPECT_EQ(r->points[k].vertex, set.points[k].vertex);
  }
  EXPECT_EQ(r->points[3].pos, set.points[3].pos);
  ASSERT_TRUE(r->stored_fapu);
  EXPECT_EQ(r->stored_fapu->es0, fapu.es0);
  EXPECT_EQ(r->stored_fapu->mw0, fapu.mw0);
  ASSERT_TRUE(afmb::bind_fdps(*r, scene));
  for (size_t k = 0; k < set.points.size(); ++k) EXPECT_EQ(r->points[k].pos, set.points[k].pos);
  // No fapu line unless asked; nothing else left beside the file.
  ASSERT_TRUE(afmb::write_fdp_text(set, scene, path));
  EXPECT_FALSE(afmb::read_fdp(path)->stored_fapu);
  EXPECT_FALSE(contains(afmtest::read_file(path), "fapu"));
}

TEST(FdpText, SongFdpRoundTripsEntryByEntry) {
  AFM_REQUIRE_SHARED_DATA();
  auto song = afmb::read_fdp(afmtest::shared_data("faces/song/song.fdp"));
  ASSERT_TRUE(song) << song.status().message();
  // A stand-in scene with one part per affects name, so binding needs no VRML.
  Scene scene;
  for (const FdpPoint &p : song->points)
    if (scene.find_part(p.part_name) < 0) scene.parts.push_back(fdptest::numbered_part(p.part_name, 3000));
  ASSERT_TRUE(afmb::bind_fdps(*song, scene));
  std::string path = afmtest::temp_dir("fdp_song_roundtrip") + "/song.txt";
  ASSERT_TRUE(afmb::write_fdp_text(*song, scene, path, &*song->stored_fapu));
  auto back = afmb::read_fdp(path);
  ASSERT_TRUE(back) << back.status().message();
  EXPECT_EQ(entries_of(*back), entries_of(*song));
  EXPECT_EQ(back->stored_fapu->ens0, song->stored_fapu->ens0);
}

// ---- the visage line form ------------------------------------------------------

TEST(FdpVisage, ReadsHeaderPointsMeshVertexAndTrailer) {
  const char *text =
      "# FDP file\n"
      "1.0 model.fdp 0 0 0 0 0 0\n"
      "    2.1 0 -1.5 0.25 0.10\n"
      "    2.10 0 -0.8 0.15 0.9\n"
      "    3.5 0.3 0.17 -0.03 2.134\n"
      "\t7.1 0 -0.84 -0.46\n"
      "\t12.1 0.0 0.17 0 0.136\n"
      "NUL  0\r\n"
      "NLL  0\n";
  auto r = afmb::parse_fdp(text, "v.fdp");
  ASSERT_TRUE(r) << r.status().message();
  ASSERT_EQ(r->points.size(), 4u);  // 12.1 is visage's own point: skipped
  EXPECT_FALSE(r->stored_fapu);
  EXPECT_EQ(r->points[0].id.str(), "2.1");
  EXPECT_EQ(r->points[0].part_name, "@0");
  EXPECT_EQ(r->points[0].vertex, 10);  // "0.10" is vertex 10, not 1
  EXPECT_EQ(r->points[0].pos, Eigen::Vector3d(0, -1.5, 0.25));
  EXPECT_EQ(r->points[0].line, 3);
  EXPECT_EQ(r->points[1].vertex, 9);
  EXPECT_EQ(r->points[2].part_name, "@2");
  EXPECT_EQ(r->points[2].vertex, 134);
  EXPECT_EQ(r->points[3].part_name, "");  // no MESH.VERTEX: a free point
  EXPECT_EQ(r->points[3].pos, Eigen::Vector3d(0, -0.84, -0.46));
  // Forcing the form gives the same.
  auto forced = afmb::parse_fdp(text, "v.fdp", FdpFormat::Visage);
  ASSERT_TRUE(forced);
  EXPECT_EQ(forced->points.size(), 4u);
  // A header whose version looks like a point name is still the header.
  auto v2 = afmb::parse_fdp("2.0 model.fdp 0 0 0 0 0 0\n 2.1 0 0 0 0.1\n", "v2.fdp");
  ASSERT_TRUE(v2) << v2.status().message();
  EXPECT_EQ(v2->points.size(), 1u);
  // No header at all.
  auto bare = afmb::parse_fdp(" 2.1 0 0 0 0.1\n 2.2 0 0 0 0.2\n", "bare.fdp");
  ASSERT_TRUE(bare) << bare.status().message();
  EXPECT_EQ(bare->points.size(), 2u);
}

// A visage-form file written here from the real Candide-3 model and the
// reference list's Candide vertex numbers: read, bind, write as text, read.
TEST(FdpVisage, CandideFileRoundTripsThroughTheTextForm) {
  AFM_REQUIRE_SHARED_DATA();
  AFM_REQUIRE_SHARED_REFERENCE();
  auto V = fdptest::obj_vertices(afmtest::shared_data("faces/candide3/candide3.wfm.obj"));
  ASSERT_EQ(V.size(), 113u);
  afmtest::CsvTable t = afmtest::read_csv(afmtest::shared_reference("mpeg4-fdp-list.csv"));
  ASSERT_EQ(t.error, "");
  std::string file = "# written by test_fdp.cpp\n1.0 candide3 0 0 0 0 0 0\n";
  std::map<std::string, int> want;
  for (auto &row : t.rows) {
    const std::string &cv = row["candide3_vertex"];
    if (cv.empty() || cv.find_first_not_of("0123456789") != std::string::npos) continue;
    int v = std::stoi(cv);
    char line[160];
    std::snprintf(line, sizeof line, "    %s %.9g %.9g %.9g 0.%d\n", row["fdp"].c_str(), V[v][0], V[v][1],
                  V[v][2], v);
    file += line;
    want[row["fdp"]] = v;
  }
  file += "\t12.1 0 0 0 0.1\nNUL  0\nNLL  0\n";
  auto r = afmb::parse_fdp(file, "candide3.fdp");
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_EQ(r->points.size(), want.size());
  EXPECT_GT(want.size(), 60u);

  Scene scene;
  scene.source = "candide3.wfm.obj";
  afmb::Part part;
  part.name = "candide";
  part.V.resize(static_cast<Eigen::Index>(V.size()), 3);
  for (size_t i = 0; i < V.size(); ++i) part.V.row(static_cast<Eigen::Index>(i)) << V[i][0], V[i][1], V[i][2];
  scene.parts.push_back(part);
  FdpSet set = *r;
  ASSERT_TRUE(afmb::bind_fdps(set, scene));
  for (size_t k = 0; k < set.points.size(); ++k) {
    const FdpPoint &p = set.points[k];
    EXPECT_EQ(p.vertex, want[p.id.str()]) << p.id.str();
    // The file's own coordinates and the bound vertex agree (to the 9 digits written).
    EXPECT_LT((p.pos - r->points[k].pos).norm(), 1e-8) << p.id.str();
  }
  std::string path = afmtest::temp_dir("fdp_visage_roundtrip") + "/candide3.txt";
  ASSERT_TRUE(afmb::write_fdp_text(set, scene, path));
  auto back = afmb::read_fdp(path);
  ASSERT_TRUE(back) << back.status().message();
  ASSERT_EQ(back->points.size(), set.points.size());
  ASSERT_TRUE(afmb::bind_fdps(*back, scene));
  for (size_t k = 0; k < set.points.size(); ++k) {
    EXPECT_EQ(back->points[k].id, set.points[k].id);
    EXPECT_EQ(back->points[k].part_name, "candide");
    EXPECT_EQ(back->points[k].vertex, set.points[k].vertex);
    EXPECT_EQ(back->points[k].pos, set.points[k].pos);
  }
}

// ---- auto-detection --------------------------------------------------------------

TEST(FdpRead, DetectsTheForm) {
  auto x = afmb::parse_fdp("  \n<xfdp><fdp name=\"2.1\" index=\"3\" affects=\"head\"/></xfdp>", "a");
  ASSERT_TRUE(x) << x.status().message();
  EXPECT_EQ(x->points[0].part_name, "head");
  auto t = afmb::parse_fdp("# c\n2.1 head 3\n", "b");
  ASSERT_TRUE(t) << t.status().message();
  EXPECT_EQ(t->points[0].part_name, "head");
  auto v = afmb::parse_fdp("# c\n2.1 0 1 2 0.3\n", "c");
  ASSERT_TRUE(v) << v.status().message();
  EXPECT_EQ(v->points[0].part_name, "@0");
  // Forced forms parse by their own rules.
  EXPECT_FALSE(afmb::parse_fdp("2.1 head 3\n", "d", FdpFormat::XfaceEd));
  EXPECT_FALSE(afmb::parse_fdp("2.1 0 1 2 0.3\n", "e", FdpFormat::Text));
}

// ---- bad input -----------------------------------------------------------------

struct BadCase {
  const char *name;      // file name given as the source
  const char *text;
  const char *where;     // "name:line: " the message must start with
  const char *fdp;       // FDP text the message must contain ("" for none)
  const char *expect;    // more text the message must contain
  FdpFormat format = FdpFormat::Auto;
};

TEST(FdpRead, BadInputGivesFileLineAndFdp) {
  const BadCase cases[] = {
      // XfaceEd
      {"x1.fdp", "<xfdp>\n<fdp name=\"2.99\" index=\"1\" affects=\"h\"/>\n</xfdp>", "x1.fdp:2: ", "2.99",
       "unknown FDP"},
      {"x2.fdp", "<xfdp>\n\n<fdp name=\"13.1\" index=\"1\" affects=\"h\"/></xfdp>", "x2.fdp:3: ", "13.1",
       "unknown FDP"},
      {"x3.fdp", "<xfdp>\n<fdp name=\"2.2\" affects=\"h\"/></xfdp>", "x3.fdp:2: ", "FDP 2.2",
       "no 'index' attribute"},
      {"x4.fdp", "<xfdp>\n<fdp name=\"2.2\" index=\"1\"/></xfdp>", "x4.fdp:2: ", "FDP 2.2",
       "no 'affects' attribute"},
      {"x5.fdp", "<xfdp>\n<fdp name=\"2.2\"\n index=\"1x\" affects=\"h\"/></xfdp>", "x5.fdp:3: ", "FDP 2.2",
       "index='1x' is not a vertex index"},
      {"x6.fdp", "<xfdp>\n<fdp index=\"1\" affects=\"h\"/></xfdp>", "x6.fdp:2: ", "", "no 'name' attribute"},
      {"x7.fdp", "<xfdp><head>\n<fapu ES0=\"1\" IRISD0=\"1\" ENS0=\"1\" MNS0=\"1\"/></head></xfdp>", "x7.fdp:2: ",
       "", "<fapu> has no MW0 attribute"},
      {"x8.fdp", "<xfdp><head>\n<fapu ES0=\"1\" IRISD0=\"abc\" ENS0=\"1\" MNS0=\"1\" MW0=\"1\"/></head></xfdp>",
       "x8.fdp:2: ", "", "IRISD0='abc' is not a positive number"},
      {"x9.fdp", "<xfdp>\n<fdp name=\"2.2\" index=\"1\" affects=\"h\"/>\n<fdp name=\"2.2\" index=\"5\" affects=\"h\"/>"
       "</xfdp>", "x9.fdp:3: ", "FDP 2.2", "given twice on part 'h' (first at line 2)"},
      {"x10.fdp", "<fdp>\n</fdp>", "x10.fdp:1: ", "", "not <xfdp>"},
      {"x11.fdp", "<xfdp>\n<fdp name=\"2.2\" index=\"1\" affects=\"h\">\n</xfdp>", "x11.fdp:3: ", "",
       "</xfdp> closes <fdp> opened at line 2"},
      {"x12.fdp", "<xfdp>\n</xfdp>", "x12.fdp:1: ", "", "no <fdp> elements"},
      // text form
      {"t1.fdp", "# c\n2.99 head 3\n", "t1.fdp:2: ", "2.99", "unknown FDP"},
      {"t2.fdp", "2.1 head 3\n13.1 head 3\n", "t2.fdp:2: ", "13.1", "unknown FDP"},
      {"t3.fdp", "2.1 head 3\n\n3.5 1.0 2,5 3\n", "t3.fdp:3: ", "FDP 3.5", "coordinate y '2,5' is not a number"},
      {"t4.fdp", "2.1 head -3\n", "t4.fdp:1: ", "FDP 2.1", "vertex '-3' is not a vertex index"},
      {"t5.fdp", "2.1 head 3 4 5 6\n", "t5.fdp:1: ", "FDP 2.1", "found 6 fields", FdpFormat::Text},
      {"t6.fdp", "fapu 1 2 3 4\n2.1 head 3\n", "t6.fdp:1: ", "", "expected 'fapu ES0 IRISD0 ENS0 MNS0 MW0'"},
      {"t7.fdp", "fapu 1 2 3 4 0\n", "t7.fdp:1: ", "", "fapu MW0 '0' is not a positive number"},
      {"t8.fdp", "2.1 head 3\n2.1 head 4\n", "t8.fdp:2: ", "FDP 2.1", "given twice on part 'head' (first at line 1)"},
      {"t9.fdp", "2.1 1 nan 3\n", "t9.fdp:1: ", "FDP 2.1", "'nan' is not a number"},
      // visage form
      {"v1.fdp", "# FDP file\n1.0 m.fdp 0 0 0 0 0 0\n 2.99 0 0 0 0.1\n", "v1.fdp:3: ", "2.99", "unknown FDP"},
      {"v2.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 2.1 0 x 0 0.1\n", "v2.fdp:2: ", "FDP 2.1", "coordinate y 'x'"},
      {"v3.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 2.1 0 0 0 0.1x\n", "v3.fdp:2: ", "FDP 2.1", "not MESH.VERTEX"},
      {"v4.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 2.1 0 0 0 0.1\n 2.1 0 0 0 0.2\n", "v4.fdp:3: ", "FDP 2.1",
       "given twice (first at line 2)"},
      {"v5.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 2.1 0 0 0 0.1\nNUL 3\n", "v5.fdp:3: ", "", "NUL 3"},
      {"v6.fdp", "hello there world again ok\n", "v6.fdp:1: ", "", "expected the visage header"},
      {"v7.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 18.1 0 0 0 0.1\n", "v7.fdp:2: ", "18.1", "unknown FDP"},
      {"v8.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 2.1 0 0 0 0.1 7\n", "v8.fdp:2: ", "FDP 2.1", "found 6 fields"},
      {"v9.fdp", "1.0 m.fdp 0 0 0 0 0 0\n 2.1 0 0 0 0.1\n 1.0 m.fdp 0\n", "v9.fdp:3: ", "", "expected a feature point line"},
  };
  for (const BadCase &c : cases) {
    auto r = afmb::parse_fdp(c.text, c.name, c.format);
    ASSERT_FALSE(r) << c.name;
    const std::string &m = r.status().message();
    EXPECT_EQ(m.rfind(c.where, 0), 0u) << c.name << ": " << m;
    EXPECT_TRUE(contains(m, c.fdp)) << c.name << ": " << m;
    EXPECT_TRUE(contains(m, c.expect)) << c.name << ": " << m;
  }
}

// Damaged copies of the real files: every outcome is a result or an error
// that starts with the file name, never a crash (run under ASan/UBSan too).
TEST(FdpRead, DamagedFilesGiveErrorsNotCrashes) {
  AFM_REQUIRE_SHARED_DATA();
  std::vector<std::string> texts = {afmtest::read_file(afmtest::shared_data("faces/song/song.fdp")),
                                    afmtest::read_file(afmtest::shared_data("fdp/alice.fdp")),
                                    "# t\nfapu 1 2 3 4 5\n2.1 head 3\n3.5 1 2 3\n",
                                    "# FDP file\n1.0 m 0 0 0 0 0 0\n 2.1 0 -1 0.5 0.10\n\t12.1 0 0 0 0.1\nNUL 0\n"};
  uint32_t seed = 12345;
  auto next = [&seed] { return seed = seed * 1664525u + 1013904223u; };
  const char flips[] = {'<', '>', '"', '\'', '&', '/', '.', ' ', '\n', '#', '0', 'x', '\0', '-'};
  int errors = 0, results = 0;
  for (const std::string &text : texts) {
    ASSERT_FALSE(text.empty());
    size_t step = text.size() / 300 + 1;
    for (size_t cut = 0; cut < text.size(); cut += step) {
      auto r = afmb::parse_fdp(std::string_view(text).substr(0, cut), "cut.fdp");
      if (r) ++results;
      else {
        ++errors;
        EXPECT_EQ(r.status().message().rfind("cut.fdp", 0), 0u) << r.status().message();
      }
    }
    for (int k = 0; k < 300; ++k) {
      std::string damaged = text;
      damaged[next() % damaged.size()] = flips[next() % sizeof flips];
      auto r = afmb::parse_fdp(damaged, "flip.fdp");
      if (r) ++results;
      else {
        ++errors;
        EXPECT_EQ(r.status().message().rfind("flip.fdp", 0), 0u) << r.status().message();
      }
    }
  }
  EXPECT_GT(errors, 100);
  EXPECT_GT(results, 100);
}

TEST(FdpRead, EmptyAndUnreadableFiles) {
  auto e = afmb::parse_fdp("# only a comment\n", "empty.fdp");
  ASSERT_FALSE(e);
  EXPECT_EQ(e.status().message(), "empty.fdp: no feature points");
  std::string missing = afmtest::temp_dir("fdp_missing") + "/nope.fdp";
  auto r = afmb::read_fdp(missing);
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.status().message(), missing)) << r.status().message();
  EXPECT_TRUE(contains(r.status().message(), "cannot open")) << r.status().message();
}

TEST(FdpWrite, RefusesWhatTheTextFormCannotHold) {
  Scene scene = small_scene();
  scene.parts[0].name = "two words";
  FdpSet set;
  set.source = "s.fdp";
  set.points.push_back(vertex_point(2, 1, "head-FACES", 1, 4));
  ASSERT_TRUE(afmb::bind_fdps(set, scene));
  std::string dir = afmtest::temp_dir("fdp_write_bad");
  afmb::Status s = afmb::write_fdp_text(set, scene, dir + "/x.fdp");
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "s.fdp:4: FDP 2.1: part name 'two words'")) << s.message();
  std::ifstream none(dir + "/x.fdp");
  EXPECT_FALSE(none.good());  // nothing half-written
  scene.parts[0].name = "head";
  s = afmb::write_fdp_text(set, scene, dir + "/no/such/dir/x.fdp");
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "no/such/dir/x.fdp")) << s.message();
}

}  // namespace
