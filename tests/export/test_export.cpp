// The exporters (builder/export) on the analytic reference head: what the
// VRML97 AFM and the OBJ files hold, read back through the project's own
// VRML importer and a plain OBJ line reader, against the AFM's own arrays;
// the player's rigid transforms (afm_rigid_pose) against the vertices the
// player moves; the JSON writer. The glTF file is checked by
// tests/cli/test_export.sh (Khronos validator, three.js in Chromium).
#include <afm/mpeg4.h>
#include <afm/player.h>
#include <afm/render.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <array>

#include "afm/analytic_targets.h"
#include "export/export_model.h"
#include "export/gltf_export.h"
#include "export/json_writer.h"
#include "export/obj_export.h"
#include "export/vrml_export.h"
#include "io/mesh_io.h"
#include "io/vrml.h"
#include "../common/synthetic_doc.h"
#include "../common/test_paths.h"

namespace {

namespace fs = std::filesystem;

// The reference head with analytic targets (FAPs, a negative-side FAP,
// visemes, expressions) and rigid eyes, jaw and head, decoded.
const afm_doc &reference_doc() {
  static afmb::AfmDocPtr doc = [] {
    afmb::Expected<std::vector<uint8_t>> bytes = afmb::analytic_reference_afm(1000);
    EXPECT_TRUE(bytes) << bytes.status().message();
    afm_doc *d = nullptr;
    EXPECT_EQ(afm_doc_read_alloc(bytes->data(), bytes->size(), nullptr, nullptr, &d), AFM_OK);
    return afmb::AfmDocPtr(d);
  }();
  return *doc;
}

// Model-unit position of vertex v plus `delta` quanta, straight from the
// format's definition (model = origin + quanta * step).
Eigen::Vector3d model_position(const afm_geometry &g, uint32_t v, const int delta[3]) {
  return {g.origin[0] + (double(g.px[v]) + delta[0]) * g.step, g.origin[1] + (double(g.py[v]) + delta[1]) * g.step,
          g.origin[2] + (double(g.pz[v]) + delta[2]) * g.step};
}

// A target's deltas by vertex (walking its runs): vertex -> dx, dy, dz.
std::map<uint32_t, std::array<int, 3>> deltas_by_vertex(const afm_target &t) {
  std::map<uint32_t, std::array<int, 3>> out;
  uint32_t k = 0;
  for (uint32_t r = 0; r < t.run_count; ++r)
    for (uint32_t j = 0; j < t.runs[r].length; ++j, ++k)
      if (t.dx[k] || t.dy[k] || t.dz[k]) out[t.runs[r].start + j] = {t.dx[k], t.dy[k], t.dz[k]};
  return out;
}

// `v x y z` lines of an OBJ file, in order.
std::vector<Eigen::Vector3d> obj_vertices(const std::string &path) {
  std::ifstream in(path);
  std::vector<Eigen::Vector3d> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream s(line.substr(2));
    Eigen::Vector3d p;
    s >> p[0] >> p[1] >> p[2];
    out.push_back(p);
  }
  return out;
}

TEST(ExportNames, FollowTheMpeg4Tables) {
  afm_target t{};
  t.kind = AFM_TARGET_FAP, t.number = 3, t.reference = 1024;
  EXPECT_EQ(afmb::target_name(t), "open_jaw");
  t.number = 31, t.reference = -256;
  EXPECT_EQ(afmb::target_name(t), "raise_l_i_eyebrow_neg");
  t.kind = AFM_TARGET_VISEME, t.number = 10, t.reference = 63;
  EXPECT_EQ(afmb::target_name(t), "viseme_A");
  t.kind = AFM_TARGET_EXPRESSION, t.number = 1;
  EXPECT_EQ(afmb::target_name(t), "expression_joy");
  const std::vector<std::string> names = afmb::target_names(reference_doc());
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size()) << "names not unique";
}

// In-betweens (formats/export.md): a FAP side's target nearest zero keeps the
// plain name, the farther ones add their |reference|, in any file order.
TEST(ExportNames, InBetweensAddTheirReference) {
  afmtest::SyntheticDoc s;
  afmtest::SyntheticOptions o;
  o.in_betweens = true;
  const afm_doc &doc = *afmtest::make_synthetic_doc(s, o);
  const std::vector<std::string> names = afmb::target_names(doc);
  std::map<int32_t, std::string> fap12, fap31;
  for (uint32_t i = 0; i < doc.target_count; ++i) {
    if (doc.targets[i].kind != AFM_TARGET_FAP) continue;
    if (doc.targets[i].number == 12) fap12[doc.targets[i].reference] = names[i];
    if (doc.targets[i].number == 31) fap31[doc.targets[i].reference] = names[i];
  }
  const std::string smile = afm_fap(12)->name, brow = afm_fap(31)->name;
  EXPECT_EQ(fap12, (std::map<int32_t, std::string>{{512, smile}, {1024, smile + "_1024"}, {1800, smile + "_1800"}}));
  EXPECT_EQ(fap31, (std::map<int32_t, std::string>{{256, brow}, {-256, brow + "_neg"}, {-700, brow + "_neg_700"}}));
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size()) << "names not unique";
}

TEST(ExportVrml, NeutralFaceIsWhatAViewerShows) {
  const afm_doc &doc = reference_doc();
  const afm_geometry &g = doc.geometry;
  afmb::Expected<std::string> text = afmb::vrml_afm_text(doc, "reference");
  ASSERT_TRUE(text) << text.status().message();
  // A plain read, as a viewer: the Switch with whichChoice -1 shows nothing.
  afmb::Expected<afmb::Scene> scene = afmb::parse_vrml(*text, "face.wrl");
  ASSERT_TRUE(scene) << scene.status().message();
  ASSERT_EQ(scene->parts.size(), g.part_count);
  const int zero[3] = {0, 0, 0};
  for (uint32_t pi = 0; pi < g.part_count; ++pi) {
    const afm_part &ap = g.parts[pi];
    const afmb::Part &p = scene->parts[pi];
    EXPECT_EQ(p.name, ap.name);
    ASSERT_EQ(p.V.rows(), Eigen::Index(ap.vertex_count)) << ap.name;
    ASSERT_EQ(p.F.rows(), Eigen::Index(ap.triangle_count)) << ap.name;
    double worst = 0;
    for (uint32_t i = 0; i < ap.vertex_count; ++i)
      worst = std::max(worst, (p.V.row(i).transpose() - model_position(g, ap.first_vertex + i, zero)).cwiseAbs().maxCoeff());
    EXPECT_LE(worst, 0.1 * g.step) << ap.name << ": positions off the AFM's by more than a tenth of a quantum";
    for (uint32_t t = 0; t < ap.triangle_count; ++t)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(uint32_t(p.F(t, c)) + ap.first_vertex, g.triangles[3 * size_t(ap.first_triangle + t) + c]);
    EXPECT_EQ(p.C.rows(), g.rgba ? Eigen::Index(ap.vertex_count) : 0) << "vertex colours";
    EXPECT_EQ(p.TC.rows(), g.u ? Eigen::Index(ap.vertex_count) : 0) << "texture coordinates";
  }
}

TEST(ExportVrml, EveryTargetDecodesToTheAfmDeltas) {
  const afm_doc &doc = reference_doc();
  const afm_geometry &g = doc.geometry;
  afmb::Expected<std::string> text = afmb::vrml_afm_text(doc, "reference");
  ASSERT_TRUE(text) << text.status().message();
  afmb::VrmlReadOptions all;
  all.all_switch_choices = true;
  afmb::Expected<afmb::Scene> scene = afmb::parse_vrml(*text, "face.wrl", all);
  ASSERT_TRUE(scene) << scene.status().message();
  ASSERT_GT(doc.target_count, 60u);
  size_t shapes = 0;
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    const std::string name = afmb::target_name(doc.targets[t]);
    const std::map<uint32_t, std::array<int, 3>> want = deltas_by_vertex(doc.targets[t]);
    ASSERT_FALSE(want.empty()) << name;
    for (uint32_t pi = 0; pi < g.part_count; ++pi) {
      const afm_part &ap = g.parts[pi];
      const auto lo = want.lower_bound(ap.first_vertex), hi = want.lower_bound(ap.first_vertex + ap.vertex_count);
      const int index = scene->find_part(name + "__" + ap.name);
      if (lo == hi) {
        EXPECT_LT(index, 0) << name << " stores part " << ap.name << ", which it does not move";
        continue;
      }
      ASSERT_GE(index, 0) << name << " does not store part " << ap.name;
      ++shapes;
      const afmb::Part &moved = scene->parts[index];
      const afmb::Part &neutral = scene->parts[pi];
      ASSERT_EQ(moved.V.rows(), neutral.V.rows()) << name;
      for (uint32_t i = 0; i < ap.vertex_count; ++i) {
        const auto it = want.find(ap.first_vertex + i);
        for (int c = 0; c < 3; ++c) {
          const long got = std::lround((moved.V(i, c) - neutral.V(i, c)) / g.step);
          ASSERT_EQ(got, it == want.end() ? 0 : it->second[c]) << name << " vertex " << i << " axis " << c;
        }
      }
      EXPECT_GT(moved.F.rows(), 0) << name << ": no faces to show the moved patch";
    }
  }
  EXPECT_EQ(scene->parts.size(), g.part_count + shapes) << "parts beyond the neutral face and the targets";
}

TEST(ExportObj, TargetMinusNeutralIsTheAfmDeltas) {
  const afm_doc &doc = reference_doc();
  const afm_geometry &g = doc.geometry;
  const std::string dir = afmtest::temp_dir("export_obj") + "/obj";
  afmb::ObjExportStats stats;
  ASSERT_TRUE(afmb::export_obj(doc, dir, {}, &stats));
  EXPECT_EQ(stats.files, size_t(doc.target_count) + 1);
  const std::vector<Eigen::Vector3d> neutral = obj_vertices(dir + "/neutral.obj");
  ASSERT_EQ(neutral.size(), g.vertex_count);
  const int zero[3] = {0, 0, 0};
  for (uint32_t v = 0; v < g.vertex_count; ++v)
    ASSERT_LE((neutral[v] - model_position(g, v, zero)).cwiseAbs().maxCoeff(), 0.1 * g.step) << "vertex " << v;
  for (uint32_t t = 0; t < doc.target_count; ++t) {
    const std::string name = afmb::target_name(doc.targets[t]);
    const std::vector<Eigen::Vector3d> moved = obj_vertices(dir + "/" + name + ".obj");
    ASSERT_EQ(moved.size(), g.vertex_count) << name;
    const std::map<uint32_t, std::array<int, 3>> want = deltas_by_vertex(doc.targets[t]);
    for (uint32_t v = 0; v < g.vertex_count; ++v) {
      const auto it = want.find(v);
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(std::lround((moved[v][c] - neutral[v][c]) / g.step), it == want.end() ? 0 : it->second[c])
            << name << " vertex " << v << " axis " << c;
    }
  }
}

// Every OBJ names materials.mtl; each part's material, named as the part,
// carries its colour and texture, as the OBJ reader reads them back.
TEST(ExportObj, MaterialsCarryEachPartsColourAndTexture) {
  afm_doc doc = reference_doc();  // a shallow copy whose first part gets a texture
  std::vector<afm_part> parts(doc.geometry.parts, doc.geometry.parts + doc.geometry.part_count);
  parts[0].texture = "skin map.png";
  doc.geometry.parts = parts.data();
  const std::string dir = afmtest::temp_dir("export_obj_mtl") + "/obj";
  ASSERT_TRUE(afmb::export_obj(doc, dir));
  EXPECT_TRUE(fs::exists(dir + "/materials.mtl"));
  for (const char *file : {"/neutral.obj", "/open_jaw.obj"}) {
    afmb::Expected<afmb::Scene> back = afmb::read_scene(dir + file);
    ASSERT_TRUE(back) << back.status().message();
    EXPECT_TRUE(back->notes.empty()) << back->notes[0];
    ASSERT_EQ(back->parts.size(), size_t(doc.geometry.part_count));
    for (uint32_t i = 0; i < doc.geometry.part_count; ++i) {
      const afmb::Part &p = back->parts[i];
      EXPECT_EQ(p.name, parts[i].name);
      EXPECT_EQ(p.texture, parts[i].texture) << p.name;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.diffuse[c], parts[i].diffuse[c] / 255.0, 1e-4) << p.name;
    }
  }
}

TEST(ExportObj, RefusesAPathThatIsAFile) {
  const std::string dir = afmtest::temp_dir("export_obj_file");
  std::ofstream(dir + "/file") << "x";
  const afmb::Status s = afmb::export_obj(reference_doc(), dir + "/file");
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("file"), std::string::npos) << s.message();
}

// The player's rigid transform moves each rigid part's vertices exactly as
// the player itself does.
TEST(RigidPose, MatchesThePlayersVertices) {
  const afm_doc &doc = reference_doc();
  size_t bytes = 0;
  ASSERT_EQ(afm_player_measure(&doc, nullptr, &bytes), AFM_OK);
  std::vector<uint64_t> buffer(bytes / 8 + 1);
  afm_player *player = nullptr;
  ASSERT_EQ(afm_player_init(&doc, nullptr, buffer.data(), buffer.size() * 8, &player), AFM_OK);
  afm_fap_state state;
  afm_fap_state_reset(&state);
  afm_rigid_transform x;
  for (uint32_t r = 0; r < doc.rigid_count; ++r) {
    ASSERT_EQ(afm_rigid_pose(&doc.rigids[r], &state, nullptr, 0, &x), AFM_OK);
    for (int k = 0; k < 9; ++k) EXPECT_EQ(x.rotation[k], k % 4 == 0 ? AFM_Q14_ONE : 0) << "neutral: not the identity";
  }
  state.value[23] = 20000, state.value[25] = -8000, state.value[3] = 500, state.value[15] = 100;
  ASSERT_EQ(afm_player_pose(player, &state, nullptr, 0), AFM_OK);
  const int32_t *pos = afm_player_positions(player);
  const afm_geometry &g = doc.geometry;
  int checked = 0;
  for (uint32_t r = 0; r < doc.rigid_count; ++r) {
    const afm_rigid &rg = doc.rigids[r];
    if (rg.kind == AFM_RIGID_HEAD) continue;  // the state leaves the head still
    ASSERT_EQ(afm_rigid_pose(&rg, &state, nullptr, 0, &x), AFM_OK);
    for (uint16_t k = 0; k < rg.part_count; ++k) {
      const afm_part &p = g.parts[rg.parts[k]];
      if (p.kind == AFM_PART_SKIN) continue;  // morph targets move the skin too
      for (uint32_t v = p.first_vertex; v < p.first_vertex + p.vertex_count; ++v) {
        const int64_t q[3] = {g.px[v], g.py[v], g.pz[v]};
        for (int i = 0; i < 3; ++i) {
          const int64_t s = x.rotation[3 * i] * q[0] + x.rotation[3 * i + 1] * q[1] + x.rotation[3 * i + 2] * q[2];
          ASSERT_EQ(pos[3 * size_t(v) + i], x.translation[i] + ((s + 8192) >> 14)) << p.name << " vertex " << v;
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_EQ(afm_rigid_pose(nullptr, &state, nullptr, 0, &x), AFM_ERR_ARGUMENT);
  EXPECT_EQ(afm_rigid_pose(&doc.rigids[0], &state, &state, AFM_Q16_ONE + 1, &x), AFM_ERR_ARGUMENT);
}

TEST(ExportGltf, GlbContainerAndNames) {
  const afm_doc &doc = reference_doc();
  afmb::GltfStats stats;
  afmb::Expected<std::vector<uint8_t>> glb = afmb::gltf_bytes(doc, "reference", {}, &stats);
  ASSERT_TRUE(glb) << glb.status().message();
  const std::vector<uint8_t> &b = *glb;
  auto u32 = [&b](size_t at) { return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24; };
  ASSERT_GT(b.size(), 28u);
  EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "glTF");
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), b.size());
  const uint32_t json_length = u32(12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(std::string(b.begin() + 16, b.begin() + 20), "JSON");
  EXPECT_EQ(std::string(b.begin() + 20 + json_length + 4, b.begin() + 20 + json_length + 8), std::string("BIN\0", 4));
  EXPECT_EQ(20 + json_length + 8 + u32(20 + json_length), b.size());
  const std::string json(b.begin() + 20, b.begin() + 20 + json_length);
  for (const std::string &name : afmb::target_names(doc))
    EXPECT_NE(json.find("\"" + name + "\""), std::string::npos) << name << " missing";
  EXPECT_EQ(stats.targets, doc.target_count);
  EXPECT_EQ(stats.meshes, doc.geometry.part_count);
  EXPECT_EQ(stats.frames, 0u);
  EXPECT_EQ(json.find("\"animations\""), std::string::npos) << "an animation without a stream";
}

// A part's PNG texture is embedded; a TGA one is left out with a note.
TEST(ExportGltf, EmbedsPngTexturesOnly) {
  afm_doc doc = reference_doc();  // a shallow copy whose part table we replace
  ASSERT_NE(doc.geometry.u, nullptr) << "the reference head has no texture coordinates";
  std::vector<afm_part> parts(doc.geometry.parts, doc.geometry.parts + doc.geometry.part_count);
  parts[0].texture = "skin.png";
  parts[1].texture = "eye.tga";
  doc.geometry.parts = parts.data();
  const std::string dir = afmtest::temp_dir("export_gltf_textures");
  const std::vector<uint8_t> rgba(4 * 4 * 4, 200);
  const afm_render_image image = {rgba.data(), 4, 4};
  ASSERT_EQ(afm_png_write((dir + "/skin.png").c_str(), &image), AFM_OK);
  std::ofstream(dir + "/eye.tga") << "not a PNG";
  afmb::GltfOptions options;
  options.texture_dirs = {dir};
  std::vector<std::string> notes;
  options.note = [&notes](const std::string &n) { notes.push_back(n); };
  afmb::GltfStats stats;
  afmb::Expected<std::vector<uint8_t>> glb = afmb::gltf_bytes(doc, "reference", options, &stats);
  ASSERT_TRUE(glb) << glb.status().message();
  EXPECT_EQ(stats.textures, 1u);
  const std::string all(glb->begin(), glb->end());
  EXPECT_NE(all.find("\"mimeType\":\"image/png\""), std::string::npos);
  EXPECT_NE(all.find("\"baseColorTexture\":{\"index\":0}"), std::string::npos);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("eye.tga is not PNG or JPEG"), std::string::npos) << notes[0];
}

TEST(JsonWriter, NestsEscapesAndRefusesNonFinite) {
  afmb::JsonWriter j;
  j.begin_object().field("a", "q\"\\\n\x01").key("b").begin_array().value(1).value(0.5).value(-0.0).end_array();
  j.field("c", true).key("d").begin_object().end_object().end_object();
  EXPECT_TRUE(j.complete());
  EXPECT_FALSE(j.failed());
  EXPECT_EQ(j.text(), R"({"a":"q\"\\\n\u0001","b":[1,0.5,0],"c":true,"d":{}})");
  afmb::JsonWriter bad;
  bad.begin_array().value(std::nan("")).end_array();
  EXPECT_TRUE(bad.failed());
}

}  // namespace
