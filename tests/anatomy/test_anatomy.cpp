// The anatomical model: physical properties, not snapshots.
//
// Direction tests contract one muscle of an uncalibrated model at a fixed
// tension and solve on the whole skin (no dynamic set involved), then look at
// the FDPs anatomy says the muscle moves.
#include <afm/image.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "anatomy/face_model.h"
#include "anatomy/fdp_completion.h"
#include "anatomy/muscle_table.h"
#include "anatomy/sim_mesh.h"
#include "io/load_face.h"
#include "refhead/head_shape.h"
#include "refhead/refhead.h"
#include "render/anatomy_render.h"
#include "../common/reference_model.h"
#include "../common/test_paths.h"

using namespace afmb;

namespace {

using Built = afmtest::ReferenceModel;

// One reference head and its uncalibrated model, shared by the tests.
const Built &head_1k() {
  static std::unique_ptr<Built> b;
  if (!b) {
    FaceModelOptions fo;
    fo.calibrate = false;
    b = afmtest::build_reference_model(1000, fo);
  }
  return *b;
}

// The same on the tissue before the layered skin and the collapse floor
// (skin_model.h, unlayered_tissue), where strong pulls turn slabs through
// themselves: the case the floor and the layers are for.
const Built &unlayered_1k() {
  static std::unique_ptr<Built> b;
  if (!b) {
    FaceModelOptions fo;
    fo.calibrate = false;
    fo.tissue = unlayered_tissue();
    b = afmtest::build_reference_model(1000, fo);
  }
  return *b;
}

// The Song head and its FDPs from ../shared/data.
Expected<LoadedFace> load_song(const LoadOptions &lo = {}) {
  return load_face(afmtest::shared_data("faces/song/song.WRL"), afmtest::shared_data("faces/song/song.fdp"), lo,
                   nullptr);
}

// Song's model with only `muscle` calibrated and no jaw.
Expected<FaceModel> song_model(const LoadedFace &f, const std::string &muscle) {
  FaceModelOptions fo;
  fo.calibrate_only = {muscle};
  fo.calibrate_jaw = false;
  return build_face_model(f.scene, f.fdps, fo);
}

// The shared 1k head's model with only `muscles` calibrated and no jaw.
Expected<FaceModel> model_1k(const std::vector<std::string> &muscles) {
  FaceModelOptions fo;
  fo.calibrate_only = muscles;
  fo.calibrate_jaw = false;
  return build_face_model(head_1k().head.scene, head_1k().head.fdps, fo);
}

// The set without FDP `id`.
FdpSet without(FdpSet f, const std::string &id) {
  f.points.erase(std::remove_if(f.points.begin(), f.points.end(), [&](const FdpPoint &p) { return p.id.str() == id; }),
                 f.points.end());
  return f;
}

std::vector<int> all_vertices(const SkinModel &s) {
  std::vector<int> v;
  for (int i = 0; i < s.n; ++i)
    if (s.in_mesh[static_cast<size_t>(i)]) v.push_back(i);
  return v;
}

// A solve on `set` from rest (X0 into X), with a cache of its own.
SolveStats solve_from_rest(const FaceModel &model, const std::vector<int> &set, const ForceField &f,
                           const SolverOptions &so, Eigen::MatrixXd &X) {
  X = model.tissue.X0;
  FactorCache cache;
  return solve_equilibrium(model.tissue, set, f, model.tissue.X0, X, so, &cache);
}

// Contracts muscle `name` at signed tension t on the whole skin.
Eigen::MatrixXd contract(const FaceModel &model, const std::string &name, double t, SolveStats *stats = nullptr,
                         SolverKind kind = SolverKind::Newton) {
  const int i = model.find(name);
  EXPECT_GE(i, 0) << name;
  const Muscle &m = model.muscles[static_cast<size_t>(i)];
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) { return muscle_load(model.tissue, m, t, X, F, K); };
  Eigen::MatrixXd X;
  SolverOptions so = model.solver;
  so.kind = kind;
  SolveStats st = solve_from_rest(model, all_vertices(model.tissue), f, so, X);
  EXPECT_TRUE(st.converged) << name << ": " << st.message;
  if (stats) *stats = st;
  return X;
}

Eigen::Vector3d moved(const FaceModel &model, const Eigen::MatrixXd &X, const char *fdp) {
  const FdpPoint *p = model.fdps.find(*FdpId::parse(fdp), model.skin);
  EXPECT_TRUE(p && p->part == model.skin) << fdp;
  return X.row(p->vertex) - model.tissue.X0.row(p->vertex);
}

double mm(double metres) { return metres * 1000; }

// How far the skin went into its eyeballs, model units: the largest depth of an epidermal
// node below its sphere grown by the node's clearance (skin_model.h:
// min(distance at rest, a hundredth of the radius)), over every skin vertex
// outside the sphere at rest within 1.5 radii of its centre (the lids and
// the skin around them, whichever way they face). Negative when none.
double deepest_in_eyes(const FaceModel &m, const Eigen::MatrixXd &X) {
  double d = -1;
  for (const EyeSphere &s : m.tissue.eyes)
    for (int v = 0; v < m.tissue.n; ++v) {
      if (!m.tissue.in_mesh[static_cast<size_t>(v)]) continue;
      const double rest = (m.tissue.X0.row(v).transpose() - s.centre).norm();
      if (rest < s.radius || rest > 1.5 * s.radius) continue;
      const double held = s.radius + std::min(rest - s.radius, 0.01 * s.radius);
      d = std::max(d, held - (X.row(v).transpose() - s.centre).norm());
    }
  return d;
}

// How far the skin between two epidermal nodes near an eyeball (an edge's
// midpoint) goes into it (model units; negative: it stays outside).
double deepest_chord_in_eyes(const FaceModel &m, const Eigen::MatrixXd &X) {
  double d = -1;
  for (const EyeSphere &s : m.tissue.eyes)
    for (int f = 0; f < m.tissue.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = m.tissue.F(f, k), b = m.tissue.F(f, (k + 1) % 3);
        bool near = true;
        for (int v : {a, b}) {
          const double rest = (m.tissue.X0.row(v).transpose() - s.centre).norm();
          near = near && rest >= s.radius && rest <= 1.5 * s.radius;
        }
        if (!near) continue;
        const Eigen::Vector3d mid = 0.5 * (X.row(a) + X.row(b)).transpose();
        d = std::max(d, s.radius - (mid - s.centre).norm());
      }
  return d;
}

// Every element keeps the sign of each of its tetrahedra.
// Tetrahedra seen nearly edge-on from the centre (under a thousandth of the
// mean volume) are not judged: their sign says nothing.
int inverted_elements(const SkinModel &s, const Eigen::MatrixXd &X) {
  double mean = 0;
  for (int f = 0; f < s.F.rows(); ++f) {
    double r[9];
    element_tet_volumes(s, s.X0, f, r);
    for (double v : r) mean += std::abs(v) / (9.0 * static_cast<double>(s.F.rows()));
  }
  int bad = 0;
  for (int f = 0; f < s.F.rows(); ++f) {
    double r[9], c[9];
    element_tet_volumes(s, s.X0, f, r);
    element_tet_volumes(s, X, f, c);
    for (int k = 0; k < 9; ++k)
      if (std::abs(r[k]) > 1e-3 * mean && r[k] * c[k] <= 0) {
        ++bad;
        break;
      }
  }
  return bad;
}

// Nodes of bone-tied vertices below their skull node's tangent plane.
int penetrating_nodes(const SkinModel &s, const Eigen::MatrixXd &X, double slack) {
  int bad = 0;
  for (int v = 0; v < s.n; ++v) {
    if (!s.in_mesh[static_cast<size_t>(v)] || !skull_rejects(s, v)) continue;
    const Eigen::Vector3d n = s.normal.row(v), skull = X.row(s.node(kSkull, v));
    for (int l = 0; l < kSkull; ++l)
      if ((X.row(s.node(l, v)).transpose() - skull).dot(n) < -slack) ++bad;
  }
  return bad;
}

}  // namespace

TEST(MuscleTable, TwentyFiveMusclesWithParsableKeyPoints) {
  const auto &t = muscle_table();
  ASSERT_EQ(t.size(), 44u) << "the paper's 25, four lid drivers, two lip protrusion drivers, two nostril dilators, "
                               "two cheek puffs, the chin raiser, two depressores supercilii, two depressores labii, "
                               "the nose's four tip drivers";
  // The last rows: mentalis' pull on the chin's skin and the inner brows'
  // depressors, linear muscles that pull along the bone, then the lower
  // lip's depressors, which pull toward their attachment on the chin's skin,
  // and the nose's tip drivers, which pull the tip toward a point beside,
  // above or below it.
  struct Puller {
    const char *name, *insertion;
    PullLine line;
  };
  const Puller pullers[] = {{"chin_raiser", "2.10", PullLine::Surface},
                            {"depressor_supercilii_left", "4.1", PullLine::Surface},
                            {"depressor_supercilii_right", "4.2", PullLine::Surface},
                            {"depressor_labii_left", "8.7", PullLine::Key},
                            {"depressor_labii_right", "8.8", PullLine::Key},
                            {"nose_bend_left", "9.3", PullLine::Key},
                            {"nose_bend_right", "9.3", PullLine::Key},
                            {"nose_raise", "9.3", PullLine::Key},
                            {"nose_lower", "9.3", PullLine::Key}};
  const long first_puller = static_cast<long>(t.size()) - static_cast<long>(std::size(pullers));
  int linear = 0, sphincter = 0;
  for (const MuscleDef &d : t) {
    const long row = &d - t.data();
    const bool paper = row < kPaperMuscles, lid = row >= kPaperMuscles && row < kPaperMuscles + 4;
    EXPECT_EQ(d.kind == MuscleKind::Lid, lid) << d.name;
    EXPECT_EQ(d.corner_outer != nullptr, lid) << d.name;
    const std::string name = d.name;
    if (row >= first_puller) {
      const Puller &p = pullers[row - first_puller];
      EXPECT_EQ(name, p.name);
      EXPECT_EQ(d.kind, MuscleKind::Linear) << name;
      EXPECT_EQ(d.sense, +1) << name;
      EXPECT_EQ(d.line, p.line) << name;
      EXPECT_STREQ(d.insertion_or_minor, p.insertion) << name;
    } else if (!paper && !lid) {
      // The lip protrusion drivers, the nostril dilators and the cheek
      // puffs: linear muscles that push (like mentalis) from a key point, on
      // the tissue's whole thickness.
      EXPECT_EQ(d.kind, MuscleKind::Linear) << name;
      EXPECT_EQ(d.sense, -1) << name;
      EXPECT_EQ(d.line, PullLine::Key) << name;
      EXPECT_TRUE(d.whole_thickness) << name;
      EXPECT_TRUE(name.rfind("lip_protrusion_", 0) == 0 || name.rfind("dilator_naris_", 0) == 0 ||
                  name.rfind("cheek_puff_", 0) == 0)
          << name;
    }
    if (paper) (d.kind == MuscleKind::Linear ? linear : sphincter)++;
    for (const char *text : {d.attachment_or_major, d.insertion_or_minor, d.epicentre, d.corner_outer, d.corner_inner}) {
      if (!text) continue;
      Expected<Keypoint> k = parse_keypoint(text);
      ASSERT_TRUE(k.is_ok()) << d.name << ": " << k.status().message();
    }
    EXPECT_EQ(find_muscle(d.name), &d - t.data());
  }
  EXPECT_EQ(linear, 22);
  EXPECT_EQ(sphincter, 3);
}

TEST(MuscleTable, ParserFollowsThePaperArithmetic) {
  Expected<Keypoint> k = parse_keypoint("11.1 + 1/6 (11.3 - 11.1)");
  ASSERT_TRUE(k.is_ok());
  ASSERT_EQ(k->terms.size(), 2u);
  EXPECT_EQ(k->terms[0].first.str(), "11.1");
  EXPECT_NEAR(k->terms[0].second, 5.0 / 6.0, 1e-12);
  EXPECT_NEAR(k->terms[1].second, 1.0 / 6.0, 1e-12);
  // Mentalis: 2.1 + (2.1 - m), m = 8.4 + (8.4 - 9.2) -> 2 x 2.1 - 2 x 8.4 + 9.2.
  k = parse_keypoint("2.1 + (2.1 - (8.4 + (8.4 - 9.2)))");
  ASSERT_TRUE(k.is_ok());
  ASSERT_EQ(k->terms.size(), 3u);
  EXPECT_NEAR(k->terms[0].second, 2.0, 1e-12);
  EXPECT_NEAR(k->terms[1].second, -2.0, 1e-12);
  EXPECT_NEAR(k->terms[2].second, 1.0, 1e-12);
  for (const char *bad : {"", "2.1 +", "1/0 (2.1)", "12.1", "2.1 - 2.2", "(2.1"})
    EXPECT_FALSE(parse_keypoint(bad).is_ok()) << bad;
  EXPECT_NE(parse_keypoint("2.1 - 2.2").status().message().find("not a point"), std::string::npos);
}

TEST(MuscleTable, DecisionsOnThePapersSlips) {
  // frontalis_inner_right uses the right hairline 11.2; risorius starts level
  // with its corner, half the mouth's width beyond it, not at the paper's 5.1
  // (left) and 5.4 (right: zygomaticus major's fibre).
  const MuscleDef &fr = muscle_table()[static_cast<size_t>(find_muscle("frontalis_inner_right"))];
  EXPECT_NE(std::string(fr.attachment_or_major).find("11.2"), std::string::npos);
  EXPECT_EQ(std::string(fr.attachment_or_major).find("11.3"), std::string::npos);
  const MuscleDef &rl = muscle_table()[static_cast<size_t>(find_muscle("risorius_left"))];
  const MuscleDef &rr = muscle_table()[static_cast<size_t>(find_muscle("risorius_right"))];
  EXPECT_STREQ(rl.attachment_or_major, "8.3 + 1/2 (8.3 - 8.4)");
  EXPECT_STREQ(rr.attachment_or_major, "8.4 + 1/2 (8.4 - 8.3)");
  EXPECT_STRNE(rr.attachment_or_major,
               muscle_table()[static_cast<size_t>(find_muscle("zygomaticus_major_right"))].attachment_or_major);
}

TEST(SkinModel, FourScaledSurfacesAndResolutionFreeStiffness) {
  const FaceModel &m = head_1k().model;
  const SkinModel &s = m.tissue;
  // Each inner node lies on the line to the centre, at its depth.
  for (int v = 0; v < s.n; v += 37) {
    const Eigen::Vector3d p0 = s.X0.row(v).transpose() - s.centre;
    for (int l = 1; l < kTissueLayers; ++l) {
      const Eigen::Vector3d p = s.X0.row(s.node(l, v)).transpose() - s.centre;
      EXPECT_LT((p.normalized() - p0.normalized()).norm(), 1e-12);
      EXPECT_LT(p.norm(), p0.norm());
    }
    EXPECT_NEAR((s.X0.row(s.node(kSkull, v)).transpose() - s.centre).norm(), s.params.skull_scale * p0.norm(), 1e-12);
  }
  int kinds[3] = {0, 0, 0};
  for (const Spring &sp : s.springs) {
    kinds[static_cast<int>(sp.kind)]++;
    EXPECT_GT(sp.k, 0);
    EXPECT_GT(sp.rest, 0);
  }
  // Per vertex: connecting springs to the three layers below.
  EXPECT_EQ(kinds[static_cast<int>(SpringKind::Connecting)], 3 * static_cast<int>(all_vertices(s).size()));
  EXPECT_GT(kinds[static_cast<int>(SpringKind::Crossed)], kinds[static_cast<int>(SpringKind::Layer)]);
  // Under the lips and cheeks the bone ties have zero stiffness.
  int freed = 0;
  for (const Spring &sp : s.springs) {
    if (sp.slab != 2 || sp.kind == SpringKind::Layer) continue;
    const int hypo = s.layer_of(sp.a) == kHypodermis ? sp.a : sp.b;
    if (s.skull_free[static_cast<size_t>(s.vertex_of(hypo))]) {
      EXPECT_EQ(s.stiffness(sp), 0.0);
      ++freed;
    }
  }
  EXPECT_GT(freed, 0);
}

// Each node pair that a prism's edges join (its two triangles' edges, the
// bone's left out, the connecting and the crossed ones) is one spring, and
// no other pair is; the surfaces alone (SkinBuild::Surfaces, for the
// muscles' key vertices before the decimation) are the whole tissue's
// surfaces, and the muscles land on the same nodes and areas on both.
TEST(SkinModel, EachNodePairIsOneSpringAndTheSurfacesAloneAreTheTissues) {
  const Built &b = head_1k();
  const Scene &scene = b.head.scene;
  const int part = b.model.skin;
  Expected<SkinModel> whole = build_skin_model(scene, part, b.model.tissue.params);
  Expected<SkinModel> surfaces = build_skin_model(scene, part, b.model.tissue.params, SkinBuild::Surfaces);
  ASSERT_TRUE(whole) << whole.status().message();
  ASSERT_TRUE(surfaces) << surfaces.status().message();
  std::set<std::pair<int, int>> pairs;
  auto join = [&](int a, int c) { pairs.insert({std::min(a, c), std::max(a, c)}); };
  for (int f = 0; f < whole->F.rows(); ++f)
    for (int slab = 0; slab < 3; ++slab)
      for (int k = 0; k < 3; ++k) {
        const int u = whole->F(f, k), w = whole->F(f, (k + 1) % 3);
        join(whole->node(slab, u), whole->node(slab, w));
        if (slab < 2) join(whole->node(slab + 1, u), whole->node(slab + 1, w));
        join(whole->node(slab, u), whole->node(slab + 1, u));
        join(whole->node(slab, u), whole->node(slab + 1, w));
        join(whole->node(slab, w), whole->node(slab + 1, u));
      }
  std::set<std::pair<int, int>> springs;
  for (const Spring &sp : whole->springs) {
    EXPECT_TRUE(springs.insert({std::min(sp.a, sp.b), std::max(sp.a, sp.b)}).second) << sp.a << "-" << sp.b;
  }
  EXPECT_EQ(whole->springs.size(), pairs.size());
  EXPECT_TRUE(springs == pairs);
  for (size_t i = 0; i < whole->node_springs.size(); ++i)
    for (int q : whole->node_springs[i]) {
      const Spring &sp = whole->springs[static_cast<size_t>(q)];
      EXPECT_TRUE(sp.a == static_cast<int>(i) || sp.b == static_cast<int>(i));
    }

  EXPECT_TRUE(surfaces->springs.empty());
  EXPECT_TRUE(surfaces->node_springs.empty());
  EXPECT_EQ(surfaces->mass.size(), 0);
  EXPECT_TRUE(surfaces->X0 == whole->X0);
  EXPECT_TRUE(surfaces->normal == whole->normal);
  EXPECT_TRUE(surfaces->thickness == whole->thickness);
  EXPECT_TRUE(surfaces->neighbours == whole->neighbours);
  EXPECT_TRUE(surfaces->eye_of == whole->eye_of);
  EXPECT_TRUE(surfaces->eye_near == whole->eye_near);
  EXPECT_TRUE(surfaces->skull_free == whole->skull_free);
  int placed = 0;
  for (size_t d = 0; d < muscle_table().size(); ++d) {
    Expected<Muscle> on_whole = place_muscle(*whole, b.model.fdps, static_cast<int>(d));
    Expected<Muscle> on_surfaces = place_muscle(*surfaces, b.model.fdps, static_cast<int>(d));
    ASSERT_EQ(static_cast<bool>(on_whole), static_cast<bool>(on_surfaces)) << muscle_table()[d].name;
    if (!on_whole) continue;
    ++placed;
    EXPECT_EQ(on_whole->node_a, on_surfaces->node_a) << on_whole->name;
    EXPECT_EQ(on_whole->node_b, on_surfaces->node_b) << on_whole->name;
    EXPECT_EQ(on_whole->influence, on_surfaces->influence) << on_whole->name;
  }
  EXPECT_GE(placed, 25);
}

// turned_slabs() finds a layer pushed through itself, and leaves out the
// bone slab under skin that is not tied to the bone (nothing lies there).
TEST(SkinModel, TurnedSlabsFindsALayerPushedThroughItself) {
  const SkinModel &s = head_1k().model.tissue;
  EXPECT_TRUE(turned_slabs(s, s.X0).empty());
  // Pushes every corner of triangle f from `from` layer's surface through the
  // next one, to as far below it again.
  auto pushed = [&s](int f, int from) {
    Eigen::MatrixXd X = s.X0;
    for (int k = 0; k < 3; ++k) {
      const int v = s.F(f, k);
      X.row(s.node(from, v)) = 2 * s.X0.row(s.node(from + 1, v)) - s.X0.row(s.node(from, v));
    }
    return X;
  };
  auto tied = [&s](int f) {
    for (int k = 0; k < 3; ++k)
      if (s.skull_free[static_cast<size_t>(s.F(f, k))]) return false;
    return true;
  };
  // Slabs with a volume at rest (not seen edge-on: at least half of their
  // depth's share of the nominal volume, a margin over turned_slabs' quarter).
  auto upright = [&s](int f) {
    double r[9];
    element_tet_volumes(s, s.X0, f, r);
    const double share[3] = {s.params.dermis_depth, s.params.hypodermis_depth - s.params.dermis_depth,
                             1 - s.params.hypodermis_depth};
    for (int slab = 0; slab < 3; ++slab)
      if (std::abs(r[3 * slab] + r[3 * slab + 1] + r[3 * slab + 2]) < 0.5 * share[slab] * s.nominal_volume[f])
        return false;
    return true;
  };
  int f_tied = -1, f_free = -1;
  for (int f = 0; f < s.F.rows() && (f_tied < 0 || f_free < 0); ++f)
    if (upright(f)) (tied(f) ? f_tied : f_free) = f;
  ASSERT_GE(f_tied, 0);
  ASSERT_GE(f_free, 0);
  // The epidermis pushed through the dermis turns slab 0 (and its
  // neighbours' where two of their corners went), nothing deeper.
  const std::vector<std::pair<int, int>> e = turned_slabs(s, pushed(f_tied, 0));
  EXPECT_NE(std::find(e.begin(), e.end(), std::make_pair(f_tied, 0)), e.end());
  for (const auto &[f, slab] : e) EXPECT_EQ(slab, 0) << f;
  // The hypodermis pushed through the skull turns the bone slab where the
  // skin is tied to the bone, and is not counted where it is not.
  const std::vector<std::pair<int, int>> t = turned_slabs(s, pushed(f_tied, 2)), u = turned_slabs(s, pushed(f_free, 2));
  EXPECT_NE(std::find(t.begin(), t.end(), std::make_pair(f_tied, 2)), t.end());
  EXPECT_EQ(std::find(u.begin(), u.end(), std::make_pair(f_free, 2)), u.end());
}

// `afm-build --pose` draws the skin red over the slabs a pose turns through
// itself (render_pose_png): no red at rest; with every epidermal node pushed
// through the dermis, most of the face red.
TEST(SkinModel, ThePosePictureIsRedOverTheTurnedSlabsOnly) {
  const Built &b = head_1k();
  const SkinModel &s = b.model.tissue;
  AnatomyPictureOptions po;
  po.width = 240, po.height = 288, po.front_only = true;
  const std::string dir = afmtest::temp_dir("pose_picture");
  // Pixels of the hue kHiRed (anatomy_render.cpp) shaded: red well over
  // green and blue; and those of any skin-like warm tone, red over blue.
  auto count = [&](const Eigen::MatrixXd &X, const char *name, int *skin) {
    Pose pose;
    pose.X = X;
    const std::string path = dir + "/" + name + ".png";
    const Status st = render_pose_png(b.head.scene, b.model, pose, Eigen::Affine3d::Identity(), path, po);
    EXPECT_TRUE(st.ok()) << st.message();
    afm_image im{};
    if (afm_png_read(path.c_str(), &im) != AFM_OK) {
      ADD_FAILURE() << "cannot read " << path;
      return -1;
    }
    int red = 0;
    *skin = 0;
    for (int i = 0; i < im.width * im.height; ++i) {
      const int r = im.rgba[4 * i], g = im.rgba[4 * i + 1], bl = im.rgba[4 * i + 2];
      red += r > 60 && r > 3 * g && r > 3 * bl;
      *skin += r > 60 && r > bl + 20;
    }
    afm_image_free(&im);
    return red;
  };
  int skin_rest = 0, skin_pushed = 0;
  EXPECT_EQ(count(s.X0, "rest", &skin_rest), 0);
  Eigen::MatrixXd X = s.X0;
  for (int v = 0; v < s.n; ++v)
    X.row(s.node(kEpidermis, v)) = 2 * s.X0.row(s.node(kDermis, v)) - s.X0.row(s.node(kEpidermis, v));
  ASSERT_GT(turned_slabs(s, X).size(), static_cast<size_t>(s.F.rows() / 2));
  const int red = count(X, "pushed", &skin_pushed);
  EXPECT_GT(red, skin_pushed / 2) << "of " << skin_pushed << " warm pixels";
  EXPECT_GT(skin_rest, 1000) << "the face fills the picture";
}

TEST(SkinModel, VolumeHessianMatchesFiniteDifferences) {
  const SkinModel &s = head_1k().model.tissue;
  // A deformed state, so that no term vanishes by symmetry.
  Eigen::MatrixXd X = s.X0;
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    X.row(i) += 1e-3 * Eigen::RowVector3d(std::sin(3.0 * i), std::cos(5.0 * i), std::sin(7.0 * i + 1));
  for (int f = 0; f < s.F.rows(); f += 97) {
    VolumeHessian VH;
    element_volume_hessian(s, X, f, &VH);
    Eigen::Matrix<double, 27, 27> H;
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j) H.block<3, 3>(3 * i, 3 * j) = VH.block(i, j);
    EXPECT_EQ(H, H.transpose());
    const double h = 1e-6;
    for (int row = 0; row < 9; ++row)
      for (int k = 0; k < 3; ++k) {
        const int node = s.node(row / 3, s.F(f, row % 3));
        Eigen::MatrixXd Xp = X, Xm = X;
        Xp(node, k) += h, Xm(node, k) -= h;
        Eigen::Matrix<double, 9, 3> gp, gm;
        element_volume(s, Xp, f, &gp);
        element_volume(s, Xm, f, &gm);
        const Eigen::Matrix<double, 9, 3> fd = (gp - gm) / (2 * h);
        for (int r = 0; r < 9; ++r)
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(H(3 * r + c, 3 * row + k), fd(r, c), 1e-9 + 1e-6 * std::abs(fd(r, c))) << f;
      }
  }
}

// The Hessian a muscle load reports is the derivative of minus its force,
// for every kind of load: the contracting sphincter's turns with the nodes,
// the others (dead loads) have none.
TEST(Muscles, LoadHessianMatchesFiniteDifferences) {
  const FaceModel &m = head_1k().model;
  Eigen::MatrixXd X = m.tissue.X0;
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    X.row(i) += 1e-3 * Eigen::RowVector3d(std::sin(3.0 * i), std::cos(5.0 * i), std::sin(7.0 * i + 1));
  for (const char *name : {"orbicularis_oris", "orbicularis_oculi_left", "zygomaticus_major_left"})
    for (double t : {0.3, -0.3}) {
      const Muscle &mu = m.muscles[static_cast<size_t>(m.find(name))];
      NodeBlocks blocks;
      Eigen::MatrixXd F0 = Eigen::MatrixXd::Zero(X.rows(), 3);
      muscle_load(m.tissue, mu, t, X, &F0, &blocks);
      std::map<int, Eigen::Matrix3d> H;
      for (const auto &[node, B] : blocks) H.emplace(node, Eigen::Matrix3d::Zero()).first->second += B;
      const bool turns = mu.kind == MuscleKind::Sphincter && t * mu.sense > 0;
      EXPECT_EQ(!H.empty(), turns) << name << " " << t;
      const double h = 1e-7;
      int checked = 0;
      const size_t step = std::max<size_t>(1, mu.influence.size() / 12);
      for (size_t i = 0; i < mu.influence.size(); i += step) {
        const int node = m.tissue.node(mu.force_layer, mu.influence[i]);
        for (int k = 0; k < 3; ++k) {
          Eigen::MatrixXd Xp = X, Xm = X;
          Xp(node, k) += h, Xm(node, k) -= h;
          Eigen::MatrixXd Fp = Eigen::MatrixXd::Zero(X.rows(), 3), Fm = Fp;
          muscle_load(m.tissue, mu, t, Xp, &Fp);
          muscle_load(m.tissue, mu, t, Xm, &Fm);
          const Eigen::Vector3d fd = -(Fp.row(node) - Fm.row(node)).transpose() / (2 * h);
          const Eigen::Vector3d an = H.count(node) ? Eigen::Vector3d(H[node].col(k)) : Eigen::Vector3d::Zero();
          EXPECT_LT((an - fd).norm(), 1e-6 * (1 + fd.norm())) << name << " " << t << " node " << node;
          ++checked;
        }
      }
      EXPECT_GE(checked, 30) << name;
    }
}

TEST(Muscles, AllPlacedSymmetricallyOnTheReferenceHead) {
  const FaceModel &m = head_1k().model;
  EXPECT_EQ(m.muscles.size(), muscle_table().size());
  EXPECT_TRUE(m.warnings.empty());
  for (const Muscle &mu : m.muscles) {
    EXPECT_FALSE(mu.influence.empty()) << mu.name;
    const std::string n = mu.name;
    if (n.size() > 5 && n.compare(n.size() - 5, 5, "_left") == 0) {
      const int r = m.find(n.substr(0, n.size() - 5) + "_right");
      ASSERT_GE(r, 0) << n;
      // The reference head is symmetric vertex for vertex.
      EXPECT_EQ(mu.influence.size(), m.muscles[static_cast<size_t>(r)].influence.size()) << n;
      EXPECT_NEAR(mu.length, m.muscles[static_cast<size_t>(r)].length, 1e-9) << n;
    }
    if (mu.kind == MuscleKind::Linear) {
      EXPECT_EQ(m.tissue.layer_of(mu.node_a), kSkull) << n;
      EXPECT_EQ(m.tissue.layer_of(mu.node_b), kDermis) << n;
    } else if (mu.kind == MuscleKind::Sphincter) {
      EXPECT_EQ(m.tissue.layer_of(mu.node_a), kHypodermis) << n;
      EXPECT_EQ(m.tissue.layer_of(mu.node_b), kHypodermis) << n;
    } else {
      EXPECT_EQ(m.tissue.layer_of(mu.node_a), kEpidermis) << n;  // the lid's margin
      EXPECT_EQ(mu.eye, n.find("_left") != std::string::npos ? 0 : 1) << n;
    }
  }
}

// The reference head is symmetric vertex for vertex: every skin vertex has
// its image (anatomy/mirror.h), the images pair up both ways, and each lies
// within the tolerance of the reflection. A vertex moved off it loses its
// image, and a skin with a fifth of its vertices moved is not symmetric.
TEST(Mirror, TheReferenceHeadsSkinPairsUpAndAMovedVertexLosesItsImage) {
  const FaceModel &m = head_1k().model;
  ASSERT_TRUE(m.mirror.symmetric());
  const SkinModel &s = m.tissue;
  const Eigen::MatrixXd V = s.X0.topRows(s.n);
  const FdpPoint *l = m.fdps.find(FdpId{3, 5}), *r = m.fdps.find(FdpId{3, 6});
  ASSERT_TRUE(l && r);
  const double tolerance = kMirrorTolerance * (l->pos - r->pos).norm();
  int paired = 0, used = 0;
  for (int v = 0; v < s.n; ++v) {
    if (!s.in_mesh[static_cast<size_t>(v)]) continue;
    ++used;
    const int u = m.mirror.image[static_cast<size_t>(v)];
    if (u < 0) continue;
    ++paired;
    EXPECT_EQ(m.mirror.image[static_cast<size_t>(u)], v);
    Eigen::Vector3d reflected = V.row(v).transpose();
    reflected.x() = 2 * m.mirror.mid - reflected.x();
    EXPECT_LE((reflected - V.row(u).transpose()).norm(), tolerance) << v;
  }
  EXPECT_EQ(paired, used);

  // Vertex 0 moved by ten tolerances across the face: neither it nor its
  // old image pairs.
  Eigen::MatrixXd W = V;
  const int old_image = m.mirror.image[0];
  W(0, 0) += 10 * tolerance;
  const SkinMirror moved = skin_mirror(W, s.in_mesh, m.mirror.mid, tolerance);
  ASSERT_TRUE(moved.symmetric());
  EXPECT_EQ(moved.image[0], -1);
  if (old_image != 0) {
    EXPECT_EQ(moved.image[static_cast<size_t>(old_image)], -1);
  }
  // Every fifth vertex moved: not symmetric.
  for (int v = 0; v < s.n; v += 5) W(v, 1) += 10 * tolerance;
  EXPECT_FALSE(skin_mirror(W, s.in_mesh, m.mirror.mid, tolerance).symmetric());
  // Mirrored twice, a displacement of every node comes back.
  Eigen::MatrixXd X = s.X0;
  for (Eigen::Index g = 0; g < X.rows(); ++g)
    X.row(g) += Eigen::RowVector3d(std::sin(1.0 * g), std::cos(2.0 * g), std::sin(3.0 * g));
  const Eigen::MatrixXd back = mirrored_nodes(m, mirrored_nodes(m, X));
  EXPECT_LT((back - X).cwiseAbs().maxCoeff(), 1e-9);
  // Once, a node takes its image's motion with x turned.
  const Eigen::MatrixXd once = mirrored_nodes(m, X);
  const int u = m.mirror.image[0], g = s.node(kDermis, 0), h = s.node(kDermis, u);
  EXPECT_NEAR(once(g, 0) - s.X0(g, 0), -(X(h, 0) - s.X0(h, 0)), 1e-12);
  EXPECT_NEAR(once(g, 1) - s.X0(g, 1), X(h, 1) - s.X0(h, 1), 1e-12);
}

// A right muscle calibrated from its left twin's poses mirrored
// (face_model.h) meets the table's action as one calibrated from rest does:
// the same tensions to a thousandth, the same key-node action to the
// tolerance, the same pose to a quantum.
TEST(Physics, ARightMuscleCalibratedFromItsTwinMatchesOneCalibratedFromRest) {
  FaceModelOptions both, alone;
  both.calibrate_only = {"zygomaticus_major_left", "zygomaticus_major_right"};
  alone.calibrate_only = {"zygomaticus_major_right"};
  both.calibrate_jaw = alone.calibrate_jaw = false;
  const std::unique_ptr<Built> a = afmtest::build_reference_model(1000, both);
  const std::unique_ptr<Built> b = afmtest::build_reference_model(1000, alone);
  ASSERT_TRUE(a && b);
  const Muscle &ma = a->model.muscles[static_cast<size_t>(a->model.find("zygomaticus_major_right"))];
  const Muscle &mb = b->model.muscles[static_cast<size_t>(b->model.find("zygomaticus_major_right"))];
  ASSERT_GT(ma.tension_max, 0);
  EXPECT_NEAR(ma.tension_max / mb.tension_max, 1, 1e-3);
  EXPECT_NEAR(ma.tension_min / mb.tension_min, 1, 1e-3);
  const SkinModel &s = a->model.tissue;
  for (bool maximum : {true, false}) {
    const NodeDisplacement &ra = maximum ? ma.response_max : ma.response_min;
    const NodeDisplacement &rb = maximum ? mb.response_max : mb.response_min;
    Eigen::MatrixXd Xa = s.X0, Xb = s.X0;
    for (size_t i = 0; i < ra.nodes.size(); ++i) Xa.row(ra.nodes[i]) += ra.displacement.row(static_cast<Eigen::Index>(i));
    for (size_t i = 0; i < rb.nodes.size(); ++i) Xb.row(rb.nodes[i]) += rb.displacement.row(static_cast<Eigen::Index>(i));
    const double target = muscle_action_target(ma, maximum);
    EXPECT_NEAR(muscle_action(s, ma, Xa, nullptr), target, a->model.solver.tolerance) << maximum;
    EXPECT_NEAR(muscle_action(s, mb, Xb, nullptr), target, a->model.solver.tolerance) << maximum;
    const double apart = (Xa - Xb).rowwise().norm().maxCoeff() / a->model.quantum;
    EXPECT_LT(apart, 1) << "quanta apart, side " << maximum;
    EXPECT_GT(apart, 0) << "started from the twin, not from rest as the other";
    std::printf("  %s: %.3f quanta apart, tensions %.6g / %.6g\n", maximum ? "+100 %" : "-100 %", apart,
                maximum ? ma.tension_max : ma.tension_min, maximum ? mb.tension_max : mb.tension_min);
  }
}

// Equations 1 and 2 on Song, whose lips are closed and whose eye openings
// face down-forward at their rims: orbicularis oris covers both lips (the
// midpoints 8.1, 8.2 and the corners 8.3, 8.4) and each orbicularis oculi
// both lids (3.1 or 3.2 above, 3.3 or 3.4 below). With the ellipse taken on
// the hypodermis (traced
// toward the centre of gravity) and the normal of the rim vertex nearest
// the epicentre, the mouth's area held the lower lip only (the upper lip rose
// out of an ellipse 0.86 units high) and FAP 17 could not be made.
TEST(Muscles, SphinctersCoverBothLipsAndBothLidsOnSong) {
  AFM_REQUIRE_SHARED_DATA();
  Expected<LoadedFace> f = load_song();
  ASSERT_TRUE(f.is_ok()) << f.status().message();
  FaceModelOptions fo;
  fo.calibrate = false;
  Expected<FaceModel> m = build_face_model(f->scene, f->fdps, fo);
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  auto covers = [&](const char *muscle, const char *fdp) {
    const Muscle &mu = m->muscles[static_cast<size_t>(m->find(muscle))];
    const FdpPoint *p = m->fdps.find(*FdpId::parse(fdp), m->skin);
    EXPECT_TRUE(p && p->part == m->skin) << fdp;
    return p && std::binary_search(mu.influence.begin(), mu.influence.end(), p->vertex);
  };
  for (const char *fdp : {"8.1", "8.2", "8.3", "8.4"}) EXPECT_TRUE(covers("orbicularis_oris", fdp)) << fdp;
  for (const char *fdp : {"3.1", "3.3"}) EXPECT_TRUE(covers("orbicularis_oculi_left", fdp)) << fdp;
  for (const char *fdp : {"3.2", "3.4"}) EXPECT_TRUE(covers("orbicularis_oculi_right", fdp)) << fdp;
}

TEST(Muscles, MouthWindowSearchKeepsTheLipsApart) {
  const FaceModel &m = head_1k().model;
  const FdpPoint *upper = m.fdps.find(*FdpId::parse("8.1"), m.skin);
  const FdpPoint *lower = m.fdps.find(*FdpId::parse("8.2"), m.skin);
  ASSERT_TRUE(upper && lower);
  auto has = [](const Muscle &mu, int v) {
    return std::binary_search(mu.influence.begin(), mu.influence.end(), v);
  };
  for (const char *name : {"mentalis_left", "mentalis_right"})
    EXPECT_FALSE(has(m.muscles[static_cast<size_t>(m.find(name))], upper->vertex)) << name;
  for (const char *name : {"upper_lip_left", "upper_lip_right"})
    EXPECT_FALSE(has(m.muscles[static_cast<size_t>(m.find(name))], lower->vertex)) << name;
  // The jaw carries the chin and the lower lip, not the upper lip.
  const Jaw &j = m.jaw;
  auto in_jaw = [&](const char *fdp) {
    const FdpPoint *p = m.fdps.find(*FdpId::parse(fdp), m.skin);
    return std::binary_search(j.vertices.begin(), j.vertices.end(), p->vertex);
  };
  EXPECT_TRUE(in_jaw("2.1"));
  EXPECT_TRUE(in_jaw("2.10"));
  EXPECT_TRUE(in_jaw("8.2"));
  EXPECT_FALSE(in_jaw("8.1"));
  EXPECT_FALSE(in_jaw("9.3"));
}

TEST(Physics, EachMuscleMovesItsRegionTheWayAnatomySays) {
  const FaceModel &m = head_1k().model;
  const double t = 0.05;  // a modest tension: millimetres of motion
  {
    const Eigen::MatrixXd X = contract(m, "zygomaticus_major_left", t);
    const Eigen::Vector3d d = moved(m, X, "8.3");
    const Eigen::Vector3d towards = m.fdps.find(*FdpId::parse("5.3"))->pos - m.tissue.X0.row(
        m.fdps.find(*FdpId::parse("8.3"), m.skin)->vertex).transpose();
    EXPECT_GT(d.y(), 0.2e-3) << "raises the corner";
    EXPECT_GT(d.normalized().dot(towards.normalized()), 0.7) << "toward the cheekbone";
    EXPECT_GT(mm(d.norm()), 10 * mm(moved(m, X, "8.4").norm())) << "the other corner stays";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0);
    EXPECT_EQ(penetrating_nodes(m.tissue, X, 1e-9), 0);
    EXPECT_TRUE(X.allFinite());
  }
  {
    const Eigen::MatrixXd X = contract(m, "frontalis_major_left", t);
    EXPECT_GT(moved(m, X, "4.3").y(), 0.2e-3) << "frontalis raises the brow";
  }
  {
    const Eigen::MatrixXd X = contract(m, "corrugator_left", t);
    const int v = m.tissue.vertex_of(m.muscles[static_cast<size_t>(m.find("corrugator_left"))].node_b);
    const Eigen::Vector3d d = X.row(v) - m.tissue.X0.row(v);
    EXPECT_LT(d.x(), -0.1e-3) << "corrugator pulls the (left) brow toward the midline";
    EXPECT_GT(m.tissue.X0(v, 0), 0.0);
    // The inner brow goes with it, in and down (a frown, FACS AU 4). With the
    // paper's fibre (4.3 -> 4.3 + (4.3 - 4.1)) 4.1 lay behind the attachment,
    // out of its influence area (docs/anatomy.md).
    const Eigen::Vector3d inner = moved(m, X, "4.1");
    EXPECT_LT(inner.x(), -0.1e-3) << "corrugator draws the inner brow toward the midline";
    EXPECT_LT(inner.y(), 0.0) << "and down";
  }
  {
    const Eigen::MatrixXd X = contract(m, "mentalis_left", t);
    const Eigen::Vector3d d = moved(m, X, "8.2");
    EXPECT_GT(d.y(), 0.1e-3) << "mentalis raises the lower lip";
    // Up more than out: its push runs from the attachment's key point, on
    // the chin's surface. From the skull node, a tissue's depth behind it,
    // the push also came forward out of the face (docs/anatomy.md).
    // Measured: 0.14 of the rise back (0.534 mm up); from the skull node
    // 0.33 forward (0.443 mm up).
    std::printf("mentalis: the lower lip's middle up %.3f mm, forward %.3f mm\n", mm(d.y()), mm(d.z()));
    EXPECT_LT(std::abs(d.z()), 0.25 * d.y()) << "mentalis pushes the lip up, not out";
  }
  {
    // The chin raiser takes the chin boss (2.10) up along the chin, more up
    // than in or out, and barely moves the upper lip (docs/anatomy.md,
    // "Chin raiser").
    const Eigen::MatrixXd X = contract(m, "chin_raiser", t);
    const Eigen::Vector3d d = moved(m, X, "2.10"), upper = moved(m, X, "8.1");
    std::printf("chin_raiser: 2.10 up %.3f mm, forward %.3f mm, sideways %.3f mm; 8.1 moves %.3f mm\n", mm(d.y()),
                mm(d.z()), mm(d.x()), mm(upper.norm()));
    EXPECT_GT(d.y(), 0.2e-3) << "the chin raiser raises the chin";
    EXPECT_LT(std::abs(d.z()), 0.5 * d.y()) << "up the chin, not into or out of it";
    EXPECT_LT(std::abs(d.x()), 0.1 * d.y()) << "on the midline";
    EXPECT_LT(upper.norm(), 0.2 * d.y()) << "the upper lip stays";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0);
    EXPECT_EQ(penetrating_nodes(m.tissue, X, 1e-9), 0);
    EXPECT_TRUE(X.allFinite());
  }
  // A depressor takes its FDP down, more down than sideways, leaves the
  // FDPs `near` and `far` (at most `near_share` and `far_share` of the
  // drop) and sends no node into the skull. Returns the FDP's motion and
  // the pose.
  auto depressor = [&](const char *name, const char *fdp, const char *near, double near_share, const char *far,
                       double far_share, Eigen::MatrixXd *pose) {
    *pose = contract(m, name, t);
    const Eigen::MatrixXd &X = *pose;
    const Eigen::Vector3d d = moved(m, X, fdp);
    const double n = moved(m, X, near).norm(), f = moved(m, X, far).norm();
    std::printf("%s: %s down %.3f mm, sideways %.3f mm, forward %.3f mm; %s moves %.3f mm, %s %.3f mm\n", name, fdp,
                mm(-d.y()), mm(d.x()), mm(d.z()), near, mm(n), far, mm(f));
    EXPECT_LT(d.y(), -0.2e-3) << name << " lowers " << fdp;
    EXPECT_LT(std::abs(d.x()), 0.5 * -d.y()) << name << ": down, not sideways";
    EXPECT_LT(n, near_share * -d.y()) << name << ": " << near << " stays";
    EXPECT_LT(f, far_share * -d.y()) << name << ": " << far << " stays";
    EXPECT_EQ(penetrating_nodes(m.tissue, X, 1e-9), 0) << name;
    EXPECT_TRUE(X.allFinite()) << name;
    return d;
  };
  {
    // Depressor supercilii takes the inner brow (4.1) down, not back, and
    // leaves the outer brow (4.5) and the other side (docs/anatomy.md,
    // "Depressor supercilii").
    Eigen::MatrixXd X;
    const Eigen::Vector3d d = depressor("depressor_supercilii_left", "4.1", "4.5", 0.2, "4.2", 0.1, &X);
    EXPECT_LT(std::abs(d.z()), 0.5 * -d.y()) << "down the brow, not into or out of it";
    // Not inverted_elements: on this head the slabs in the crease between
    // the inner brow and the eye (1-5 % of the mean tetrahedron) turn under
    // any pull that lowers the brow, at tenths of a millimetre: 5 here, 6
    // for frontalis driven backwards, 4 for corrugator at this tension.
    // WithTheCollapseFloorNoSlabTurnsAtTheFullRange checks it with the
    // floor, as for every muscle.
  }
  {
    // Depressor labii inferioris takes the lower lip's left middle (8.7)
    // down and leaves the upper lip (8.1) and, mostly, the lower lip's
    // other side (8.8) (docs/anatomy.md, "Depressor labii inferioris"). It
    // pulls toward its attachment on the chin's skin, which stands forward
    // of the lip's lower edge: the lip turns out a little as it comes down
    // (measured: forward 0.64 of the drop; along the bone it went back into
    // the mouth).
    Eigen::MatrixXd X;
    const Eigen::Vector3d d = depressor("depressor_labii_left", "8.7", "8.1", 0.2, "8.8", 0.5, &X);
    EXPECT_GT(d.z(), 0.0) << "the lip turns out, not into the mouth";
    EXPECT_LT(d.z(), 0.8 * -d.y()) << "down more than out";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0);
  }
  {
    const Eigen::MatrixXd X = contract(m, "depressor_anguli_left", t);
    EXPECT_LT(moved(m, X, "8.3").y(), -0.2e-3) << "depressor anguli lowers the corner";
  }
  {
    const Eigen::MatrixXd X = contract(m, "orbicularis_oris", t);
    EXPECT_LT(moved(m, X, "8.3").x(), -0.2e-3) << "the left corner moves in";
    EXPECT_GT(moved(m, X, "8.4").x(), 0.2e-3) << "the right corner moves in";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0);
  }
  // The lip protrusion drivers push their lip's middle out of the face, more
  // out than up or down, and leave the other lip (docs/anatomy.md, "Lip
  // protrusion"). Orbicularis oris, which MPEG-4's push_b_lip and push_t_lip
  // had before, moved 8.1 and 8.2 up and down more than out.
  for (const auto &[name, own, other] : {std::array<const char *, 3>{"lip_protrusion_lower", "8.2", "8.1"},
                                         std::array<const char *, 3>{"lip_protrusion_upper", "8.1", "8.2"}}) {
    const Eigen::MatrixXd X = contract(m, name, t);
    const Eigen::Vector3d d = moved(m, X, own), o = moved(m, X, other);
    std::printf("%s: %s out %.3f mm, up %.3f mm; %s moves %.3f mm\n", name, own, mm(d.z()), mm(d.y()), other,
                mm(o.norm()));
    EXPECT_GT(d.z(), 0.1e-3) << name << " pushes its lip out";
    EXPECT_LT(std::abs(d.y()), 0.5 * d.z()) << name << " pushes its lip out more than up or down";
    EXPECT_LT(o.norm(), 0.5 * d.z()) << name << " leaves the other lip";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0) << name;
    EXPECT_TRUE(X.allFinite()) << name;
  }
  {
    // The left nostril dilator flares the left wing of the nose (9.1) out,
    // more out than up, and leaves the right one (docs/anatomy.md).
    const Eigen::MatrixXd X = contract(m, "dilator_naris_left", t);
    const Eigen::Vector3d d = moved(m, X, "9.1"), o = moved(m, X, "9.2");
    std::printf("dilator_naris_left: 9.1 out %.3f mm, up %.3f mm; 9.2 moves %.3f mm\n", mm(d.x()), mm(d.y()),
                mm(o.norm()));
    EXPECT_GT(d.x(), 0.1e-3) << "the left wing goes out (+x)";
    EXPECT_LT(std::abs(d.y()), 0.5 * d.x()) << "out more than up or down";
    EXPECT_LT(o.norm(), 0.2 * d.x()) << "the right wing stays";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0);
  }
  // The left cheek puff (air pressure in the mouth) bulges the left cheek
  // out through its surface, and -100 % draws it in: the cheek's FDP (5.1)
  // goes out (+x) or in, more sideways than up or down, its area moves
  // along its rest normals, out or in, the other cheek (5.2) and the mouth's
  // middle (8.1, 8.2) stay, and sucked in, no node goes into the skull
  // (docs/anatomy.md, "Cheek puff").
  for (const double sign : {+1.0, -1.0}) {
    const char *name = "cheek_puff_left";
    const Eigen::MatrixXd X = contract(m, name, sign * t);
    const Eigen::Vector3d d = moved(m, X, "5.1"), o = moved(m, X, "5.2");
    const Muscle &mu = m.muscles[static_cast<size_t>(m.find(name))];
    double along = 0, total = 0;  // the influence area's motion along its rest normals, and its length
    for (int v : mu.influence) {
      const Eigen::Vector3d u = X.row(v) - m.tissue.X0.row(v);
      along += u.dot(m.tissue.normal.row(v));
      total += u.norm();
    }
    const double lips = std::max(moved(m, X, "8.1").norm(), moved(m, X, "8.2").norm());
    std::printf("%s %+.0f: 5.1 sideways %.3f mm, up %.3f mm, forward %.3f mm; along the normals %.2f of its "
                "area's motion; 5.2 moves %.3f mm, the lips' middles %.3f mm\n",
                name, sign, mm(d.x()), mm(d.y()), mm(d.z()), along / total, mm(o.norm()), mm(lips));
    EXPECT_GT(sign * d.x(), 0.1e-3) << name << " moves the cheek out (+x) at +, in at -";
    EXPECT_LT(std::abs(d.y()), 0.5 * std::abs(d.x())) << name << " sideways more than up or down";
    EXPECT_GT(sign * along, 0.5 * total) << name << " moves its area along its rest normals";
    EXPECT_LT(o.norm(), 0.1 * std::abs(d.x())) << name << ": the right cheek stays";
    EXPECT_LT(lips, 0.3 * std::abs(d.x())) << name << ": the lips' middles stay";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0) << name;
    EXPECT_EQ(penetrating_nodes(m.tissue, X, 1e-9), 0) << name;
    EXPECT_TRUE(X.allFinite()) << name;
  }
  // The nose's tip drivers move the tip (9.3) their own way, the left
  // bender to the face's left (+x), the raiser up, the lowerer down, more
  // along it than across, and leave the wings (9.1, 9.2) and the upper
  // lip's middle (8.1) mostly in place (docs/anatomy.md, "Nose tip
  // drivers"). Nasalis, which FAPs 63 and 64 had, takes the wing back and
  // up.
  for (const auto &[name, axis, sign] : {std::tuple<const char *, int, double>{"nose_bend_left", 0, +1},
                                         std::tuple<const char *, int, double>{"nose_raise", 1, +1},
                                         std::tuple<const char *, int, double>{"nose_lower", 1, -1}}) {
    const Eigen::MatrixXd X = contract(m, name, t);
    const Eigen::Vector3d d = moved(m, X, "9.3");
    const double own = sign * d[axis], across = (d - d[axis] * Eigen::Vector3d::Unit(axis)).norm();
    const double wings = std::max(moved(m, X, "9.1").norm(), moved(m, X, "9.2").norm()),
                 lip = moved(m, X, "8.1").norm();
    std::printf("%s: 9.3 along %.3f mm, across %.3f mm; the wings move %.3f mm, 8.1 %.3f mm\n", name, mm(own),
                mm(across), mm(wings), mm(lip));
    EXPECT_GT(own, 0.1e-3) << name;
    EXPECT_LT(across, 0.15 * own) << name << ": along its axis, not across";
    EXPECT_LT(wings, 0.2 * own) << name << ": the wings stay";
    EXPECT_LT(lip, 0.1 * own) << name << ": the upper lip stays";
    EXPECT_EQ(inverted_elements(m.tissue, X), 0) << name;
    EXPECT_EQ(penetrating_nodes(m.tissue, X, 1e-9), 0) << name;
    EXPECT_TRUE(X.allFinite()) << name;
  }
  {
    const Eigen::MatrixXd X = contract(m, "orbicularis_oculi_left", t);
    const double before = m.fdps.find(*FdpId::parse("3.1"))->pos.y() - m.fdps.find(*FdpId::parse("3.3"))->pos.y();
    const double after = before + moved(m, X, "3.1").y() - moved(m, X, "3.3").y();
    EXPECT_LT(after, before - 0.2e-3) << "orbicularis oculi narrows the eye";
  }
}

// The muscles that lie along the bone (PullLine::Surface) move the
// skin along its surface: the skin's motion at the insertion is mostly
// tangent to it. Pulled straight toward an attachment on the skull, as
// Waters' vector muscle does, the skin went into the face as much as along
// it (docs/anatomy.md, "Muscles"), and the FAPs' FDPs with it.
TEST(Physics, MusclesAlongTheBoneMoveTheSkinAlongItsSurface) {
  const FaceModel &m = head_1k().model;
  for (const char *name : {"frontalis_inner_left", "frontalis_major_left", "frontalis_outer_left", "corrugator_left",
                           "zygomaticus_major_left", "risorius_left", "depressor_anguli_left"}) {
    const Muscle &mu = m.muscles[static_cast<size_t>(m.find(name))];
    ASSERT_EQ(muscle_table()[static_cast<size_t>(mu.def)].line, PullLine::Surface) << name;
    const Eigen::MatrixXd X = contract(m, name, 0.05);
    const int v = m.tissue.vertex_of(mu.node_b);
    const Eigen::Vector3d d = X.row(v) - m.tissue.X0.row(v), n = m.tissue.normal.row(v);
    std::printf("%-24s insertion moved %.3f mm, %.2f of it along the normal\n", name, mm(d.norm()),
                std::abs(d.dot(n)) / d.norm());
    EXPECT_GT(mm(d.norm()), 0.2) << name;
    // Measured: 0.03-0.21 (risorius, whose insertion is the mouth's corner,
    // where the skin turns into the lips); 0.25-0.71 with the straight pull.
    EXPECT_LT(std::abs(d.dot(n)), 0.25 * d.norm()) << name;
  }
}

// The collapse floor (TissueParams::collapse_modulus, solver.h): at a
// tension that moves the brow or the upper lip about 10 mm on the 1k head,
// the tissue without the floor and the layered skin turns slabs through
// themselves near the insertion; with the floor (at 0.3, the layers still
// off) none turns, and the skin moves nearly as far.
TEST(Physics, TheCollapseFloorKeepsEverySlabUpright) {
  const FaceModel &m = unlayered_1k().model;
  FaceModelOptions fo;
  fo.calibrate = false;
  fo.tissue = unlayered_tissue();
  fo.tissue.collapse_modulus = 0.3;
  std::unique_ptr<Built> floored = afmtest::build_reference_model(1000, fo);
  const FaceModel &f = floored->model;
  for (const char *name : {"frontalis_inner_left", "upper_lip_left"}) {
    SolveStats a, b;
    const Eigen::MatrixXd X = contract(m, name, 0.5, &a), Y = contract(f, name, 0.5, &b);
    const size_t without = turned_slabs(m.tissue, X).size(), with = turned_slabs(f.tissue, Y).size();
    const double reach = (X - m.tissue.X0).rowwise().norm().maxCoeff(),
                 floored_reach = (Y - f.tissue.X0).rowwise().norm().maxCoeff();
    std::printf("%s at 0.5: %zu slabs turned (%d Newton iterations, %.1f mm), with the floor %zu (%d, %.1f mm)\n", name,
                without, a.iterations, mm(reach), with, b.iterations, mm(floored_reach));
    EXPECT_GT(without, 0u) << name << ": the case the floor is for";
    EXPECT_EQ(with, 0u) << name;
    EXPECT_TRUE(b.converged) << name << ": " << b.message;
    EXPECT_TRUE(Y.allFinite());
    EXPECT_EQ(penetrating_nodes(f.tissue, Y, 1e-9), 0) << name;
    EXPECT_NEAR(floored_reach, reach, 0.1 * reach) << name;
  }
}

// The same at the full range: every muscle at -100 % and +100 % of its
// calibrated range, and the jaw wide open, turn no slab on the 1k head on
// the default tissue (the layered skin and the floor at kCollapseFloor). 56
// slabs turned over these poses on the tissue before the layers and the
// floor; the jaw turned 5 in front of its corners until the skin beside it
// took a share of its motion (jaw.h, "Followers"), 0 with the floor at 0.3.
TEST(Physics, NoSlabTurnsAtTheFullRange) {
  std::unique_ptr<Built> built = afmtest::build_reference_model(1000, FaceModelOptions());
  ASSERT_TRUE(built);
  const FaceModel &m = built->model;
  ASSERT_EQ(m.muscles.size(), muscle_table().size());
  std::vector<Activation> poses;
  for (size_t i = 0; i < m.muscles.size(); ++i)
    for (double pct : {-100.0, 100.0}) {
      Activation a;
      a.muscles = {{static_cast<int>(i), pct}};
      poses.push_back(a);
    }
  Activation jaw;
  jaw.jaw_open = 100;
  poses.push_back(jaw);
  size_t turned = 0, jaw_turned = 0;
  for (const Activation &a : poses) {
    FactorCache cache;
    Expected<Pose> p = solve_pose(m, a, &cache);
    const std::string what = a.muscles.empty() ? std::string("the jaw")
                                               : m.muscles[static_cast<size_t>(a.muscles[0].first)].name + " at " +
                                                     std::to_string(static_cast<int>(a.muscles[0].second)) + " %";
    ASSERT_TRUE(p.is_ok()) << what << ": " << p.status().message();
    const size_t t = turned_slabs(m.tissue, p->X).size();
    if (a.muscles.empty()) jaw_turned = t;
    EXPECT_EQ(t, 0u) << what;
    EXPECT_TRUE(p->X.allFinite()) << what;
    EXPECT_EQ(penetrating_nodes(m.tissue, p->X, 1e-9), 0) << what;
    turned += t;
  }
  std::printf("%zu poses at the full range: %zu slabs turned, %zu by the jaw\n", poses.size(), turned, jaw_turned);
}

// Each layer's own volume (TissueParams::layer_volume_modulus, solver.h):
// what it adds to the residual is minus the gradient of its energy, the sum
// over slabs that hold tissue of k_l (V_s - V_s0)^2 / (2 |V_s0|), here from
// element_volume by central differences; and it pushes back dermis nodes
// moved toward the epidermis, which thin the skin's slab by about what they
// thicken the fat's (the element's own volume barely changes).
TEST(SkinModel, EachLayersVolumeTermIsTheGradientOfItsEnergy) {
  const FaceModel &m = head_1k().model;
  SkinModel s = m.tissue;
  s.params.layer_volume_modulus = 0;
  SkinModel l = s;
  const double k = 0.02;
  l.params.layer_volume_modulus = k;
  const Eigen::Vector3d c = m.fdps.find(*FdpId::parse("5.1"))->pos;  // the left cheek
  Eigen::MatrixXd X = s.X0;
  std::vector<int> moved_nodes;
  for (int v = 0; v < s.n; ++v) {
    if (!s.in_mesh[static_cast<size_t>(v)] || (s.X0.row(v).transpose() - c).norm() > 0.025) continue;
    const int d = s.node(kDermis, v);
    X.row(d) += (s.X0.row(v) - s.X0.row(d)) / 3;
    moved_nodes.push_back(d);
  }
  ASSERT_GE(moved_nodes.size(), 10u);
  auto energy = [&](const Eigen::MatrixXd &P) {
    double e = 0;
    for (int f = 0; f < s.F.rows(); ++f)
      for (int sl = 0; sl < 3; ++sl) {
        if (!slab_holds_tissue(s, f, sl)) continue;
        const double v0 = element_volume(s, s.X0, f, nullptr, sl), dv = element_volume(s, P, f, nullptr, sl) - v0;
        e += 0.5 * k * dv * dv / std::abs(v0);
      }
    return e;
  };
  const std::vector<int> all = all_vertices(s);
  const Eigen::MatrixXd added = residual_forces(l, all, ForceField{}, s.X0, X) - residual_forces(s, all, ForceField{}, s.X0, X);
  int back = 0;
  double worst = 0;
  for (size_t i = 0; i < moved_nodes.size(); ++i) {
    const int node = moved_nodes[i];
    if ((s.X0.row(node) - X.row(node)).dot(added.row(node)) > 0) ++back;
    if (i % 3) continue;  // central differences on a third of them
    for (int a = 0; a < 3; ++a) {
      const double h = 1e-6;
      Eigen::MatrixXd P = X, M = X;
      P(node, a) += h, M(node, a) -= h;
      const double fd = -(energy(P) - energy(M)) / (2 * h);
      worst = std::max(worst, std::abs(added(node, a) - fd) / (added.row(node).norm() + 1e-30));
    }
  }
  std::printf("each layer's volume: %d of %zu moved dermis nodes pushed back; the force against central "
              "differences %.2g of its size at worst\n", back, moved_nodes.size(), worst);
  EXPECT_LT(worst, 1e-4);
  EXPECT_EQ(back, static_cast<int>(moved_nodes.size()));
}

// The layered skin (TissueParams::skin_load_share, layer_volume_modulus;
// docs/anatomy.md): a linear muscle's load goes on the epidermal and the
// dermal node of each influence vertex by the share, of the magnitude the
// dermis alone takes without it; and over the linear muscles pulling hard,
// far fewer slabs turn through themselves than on the tissue before it
// (unlayered_tissue; both without the collapse floor; measured: 19 against
// 4), the skin reaching about as far (0.8-0.95 times).
TEST(Physics, TheLayeredSkinTurnsFewerSlabs) {
  const FaceModel &m = unlayered_1k().model;
  FaceModelOptions fo;
  fo.calibrate = false;
  fo.tissue.collapse_modulus = 0;
  std::unique_ptr<Built> layered = afmtest::build_reference_model(1000, fo);
  ASSERT_TRUE(layered);
  const FaceModel &l = layered->model;
  {
    const Muscle &mu = l.muscles[static_cast<size_t>(l.find("zygomaticus_major_left"))];
    Eigen::MatrixXd F = Eigen::MatrixXd::Zero(l.tissue.X0.rows(), 3), G = F;
    muscle_load(l.tissue, mu, 0.3, l.tissue.X0, &F);
    muscle_load(m.tissue, m.muscles[static_cast<size_t>(m.find("zygomaticus_major_left"))], 0.3, m.tissue.X0, &G);
    for (size_t i = 0; i < mu.influence.size(); ++i) {
      const int v = mu.influence[i];
      const double whole = G.row(m.tissue.node(kDermis, v)).norm();
      EXPECT_NEAR(F.row(l.tissue.node(kEpidermis, v)).norm(), kLayeredSkinLoadShare * whole, 1e-12 * whole) << v;
      EXPECT_NEAR(F.row(l.tissue.node(kDermis, v)).norm(), (1 - kLayeredSkinLoadShare) * whole, 1e-12 * whole) << v;
      EXPECT_EQ(F.row(l.tissue.node(kHypodermis, v)).norm(), 0.0) << v;
      EXPECT_EQ(G.row(m.tissue.node(kEpidermis, v)).norm(), 0.0) << v;
    }
  }
  size_t without = 0, with = 0;
  for (size_t i = 0; i < m.muscles.size(); ++i) {
    const Muscle &mu = m.muscles[i];
    // One side: the head is mirror-symmetric.
    if (mu.kind != MuscleKind::Linear || muscle_table()[static_cast<size_t>(mu.def)].whole_thickness ||
        mu.name.find("_right") != std::string::npos)
      continue;
    SolveStats a, b;
    const Eigen::MatrixXd X = contract(m, mu.name, 0.5, &a), Y = contract(l, mu.name, 0.5, &b);
    const size_t t = turned_slabs(m.tissue, X).size(), u = turned_slabs(l.tissue, Y).size();
    const double reach = (X - m.tissue.X0).rowwise().norm().maxCoeff(),
                 layered_reach = (Y - l.tissue.X0).rowwise().norm().maxCoeff();
    std::printf("%s at 0.5: %zu slabs turned (%d Newton iterations, %.1f mm), layered %zu (%d, %.1f mm)\n",
                mu.name.c_str(), t, a.iterations, mm(reach), u, b.iterations, mm(layered_reach));
    EXPECT_TRUE(b.converged) << mu.name << ": " << b.message;
    EXPECT_TRUE(Y.allFinite()) << mu.name;
    EXPECT_EQ(penetrating_nodes(l.tissue, Y, 1e-9), 0) << mu.name;
    EXPECT_NEAR(layered_reach, reach, 0.3 * reach) << mu.name;
    without += t, with += u;
  }
  std::printf("the linear muscles at 0.5 (left and middle): %zu slabs turned, layered %zu\n", without, with);
  EXPECT_GT(without, 10u) << "the case the layered skin is for";
  EXPECT_LT(3 * with, without);
}

// The lids ride over the eyeballs (skin_model.h): spheres fitted to the eye
// parts, which the generator made as spheres of known centre and radius.
// Closing the eye hard presses the upper lid onto its eyeball; without the
// contact the same pull takes the lid into it.
TEST(Physics, TheLidsSlideOverTheEyeball) {
  const FaceModel &m = head_1k().model;
  const refhead::HeadDesign &design = refhead::head_design();
  ASSERT_EQ(m.tissue.eyes.size(), 2u);
  for (int e = 0; e < 2; ++e) {
    const EyeSphere &s = m.tissue.eyes[static_cast<size_t>(e)];
    const Eigen::Vector3d c(e == 0 ? design.eye_centre.x() : -design.eye_centre.x(), design.eye_centre.y(),
                            design.eye_centre.z());
    EXPECT_LT((s.centre - c).norm(), 0.01 * design.eye_radius) << "eye " << e;
    EXPECT_NEAR(s.radius, design.eye_radius, 0.01 * design.eye_radius) << "eye " << e;
  }
  const int top = m.fdps.find(*FdpId::parse("3.1"), m.skin)->vertex;  // the left upper lid
  EXPECT_EQ(m.tissue.eye_of[static_cast<size_t>(top)], 0) << "FDP 3.1 lies over the left eyeball";
  EXPECT_EQ(m.tissue.skull_free[static_cast<size_t>(top)], 1) << "a lid is not tied to the bone";

  auto deepest = [&m](const Eigen::MatrixXd &X) { return deepest_in_eyes(m, X); };
  const double t = 2;  // the upper lid comes down about 3 mm
  const Eigen::MatrixXd X = contract(m, "orbicularis_oculi_left", t);
  EXPECT_LT(moved(m, X, "3.1").y(), -1e-3) << "the upper lid comes down";
  EXPECT_LE(deepest(X), 1e-9) << "no lid enters its eyeball";
  EXPECT_TRUE(X.allFinite());
  // The skin between its nodes: each is held at least its longest edge's
  // chord dip off the ball, up to its rest distance, and more as its edges
  // stretch (eye_clearance_in). On the 1k head's coarse lid that keeps the
  // edges' midpoints 0.46 mm into the ball, as at rest (edges at the margin
  // already cut it there; the nodes are held at most at their rest distance
  // before they stretch), instead of 1.67 mm from 0.01 r off.
  FaceModel thin = m;
  for (int v = 0; v < thin.tissue.n; ++v)
    if (const int e = thin.tissue.eye_near[static_cast<size_t>(v)]; e >= 0) {
      const EyeSphere &ball = thin.tissue.eyes[static_cast<size_t>(e)];
      const double rest = (thin.tissue.X0.row(v).transpose() - ball.centre).norm() - ball.radius;
      thin.tissue.eye_clearance[static_cast<size_t>(v)] = std::clamp(rest, 0.0, kEyeClearance * ball.radius);
    }
  const Eigen::MatrixXd T = contract(thin, "orbicularis_oculi_left", t);
  std::printf("1k head, orbicularis oculi at tension %g: the lid's edges %.3f mm into the eyeball held at the chord "
              "dip, %.3f mm held at 0.01 r, %.3f mm at rest\n",
              t, 1e3 * deepest_chord_in_eyes(m, X), 1e3 * deepest_chord_in_eyes(thin, T),
              1e3 * deepest_chord_in_eyes(m, m.tissue.X0));
  EXPECT_LT(deepest_chord_in_eyes(m, X), 0.7 * deepest_chord_in_eyes(thin, T)) << "the lid's edges held farther out";
  // Held at their rest clearance, the stretched edges went 1.17 mm in.
  EXPECT_LE(deepest_chord_in_eyes(m, X), deepest_chord_in_eyes(m, m.tissue.X0) + 0.02e-3)
      << "the stretched lid's chords no deeper in than at rest";

  FaceModel free = m;  // the same model without the eyeballs
  free.tissue.eyes.clear();
  std::fill(free.tissue.eye_of.begin(), free.tissue.eye_of.end(), int8_t(-1));
  std::fill(free.tissue.eye_near.begin(), free.tissue.eye_near.end(), int8_t(-1));
  const Eigen::MatrixXd Y = contract(free, "orbicularis_oculi_left", t);
  EXPECT_GT(deepest(Y), 0.05 * design.eye_radius) << "without the contact the lid goes into the eye";
}

// A lid turned as a whole (face_model.h, place_turned_lid): the turn that
// shuts it is the one from its margin (FDP 3.1) to the other lid's (3.3)
// about the eyeball's horizontal axis; the tarsus turns about the
// eyeball's centre, so it comes no nearer the ball, and is held there; the
// skin outside the lid stays put. Solved, the shut lid has 3.1 down at
// 3.3's height and no lid skin inside the eyeball. A muscle that is not a
// lid driver, or a negative clearance, is refused.
TEST(Physics, ALidTurnedAsAWholeShutsOverTheEyeball) {
  const FaceModel &m = head_1k().model;
  const SkinModel &s = m.tissue;
  const int i = m.find("palpebral_upper_left");
  ASSERT_GE(i, 0);
  const Muscle &lid = m.muscles[static_cast<size_t>(i)];
  ASSERT_EQ(lid.turn_share.size(), lid.influence.size());
  const EyeSphere &ball = s.eyes[static_cast<size_t>(lid.eye)];
  const FdpPoint *upper = m.fdps.find(*FdpId::parse("3.1"), m.skin), *lower = m.fdps.find(*FdpId::parse("3.3"), m.skin);
  ASSERT_TRUE(upper && lower);
  auto yz = [&](int v) {
    const Eigen::Vector3d d = s.X0.row(v).transpose() - ball.centre;
    return std::atan2(d.y(), d.z());
  };
  const double opening = yz(upper->vertex) - yz(lower->vertex);
  EXPECT_NEAR(lid.closing_turn, opening, 0.05 * opening);

  LidTurn turn;
  turn.muscle = i;
  turn.angle = lid.closing_turn;
  Eigen::MatrixXd X = s.X0;
  std::vector<char> held;
  ASSERT_TRUE(place_turned_lid(m, turn, X, &held).is_ok());
  ASSERT_EQ(held.size(), static_cast<size_t>(s.n));
  std::vector<char> in_lid(static_cast<size_t>(s.n), 0), tarsus(static_cast<size_t>(s.n), 0);
  for (size_t k = 0; k < lid.influence.size(); ++k) {
    in_lid[static_cast<size_t>(lid.influence[k])] = 1;
    tarsus[static_cast<size_t>(lid.influence[k])] = lid.tarsus[k];
  }
  int on_tarsus = 0;
  for (int v = 0; v < s.n; ++v) {
    EXPECT_EQ(held[static_cast<size_t>(v)], tarsus[static_cast<size_t>(v)]) << v;
    on_tarsus += tarsus[static_cast<size_t>(v)];
    for (int l = 0; l < kSkull; ++l) {
      const int g = s.node(l, v);
      if (!in_lid[static_cast<size_t>(v)]) {
        EXPECT_EQ(X.row(g), s.X0.row(g)) << v;
      } else {
        EXPECT_GE((X.row(g).transpose() - ball.centre).norm(), (s.X0.row(g).transpose() - ball.centre).norm() - 1e-12)
            << v;
      }
    }
  }
  EXPECT_GT(on_tarsus, 3);

  Activation a;
  a.lids.push_back(turn);
  FactorCache cache;
  Expected<Pose> p = solve_pose(m, a, &cache);
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  const Eigen::MatrixXd &P = p->X;
  EXPECT_TRUE(P.allFinite());
  EXPECT_NEAR(P(upper->vertex, 1), s.X0(lower->vertex, 1), 0.05 * m.fapu.irisd0) << "shut";
  EXPECT_LE(deepest_in_eyes(m, P), 1e-9) << "no lid skin inside its eyeball";
  // The skin between its nodes no deeper than at rest, where edges at the
  // margin already cut the ball (Physics.TheLidsSlideOverTheEyeball).
  EXPECT_LE(deepest_chord_in_eyes(m, P), deepest_chord_in_eyes(m, s.X0) + 0.02e-3);
  for (int v = 0; v < s.n; ++v) {
    if (!held[static_cast<size_t>(v)]) continue;
    for (int l = 0; l < kSkull; ++l) EXPECT_EQ(P.row(s.node(l, v)), X.row(s.node(l, v))) << "held " << v;
  }

  LidTurn bad = turn;
  bad.muscle = m.find("zygomaticus_major_left");
  Eigen::MatrixXd Y = s.X0;
  EXPECT_FALSE(place_turned_lid(m, bad, Y, nullptr).is_ok());
  bad = turn;
  bad.clearance = -1;
  EXPECT_FALSE(place_turned_lid(m, bad, Y, nullptr).is_ok());
}

// The lid drivers (muscles.h) on Song's simulation mesh, as afm-build makes
// it: the upper lid comes down over the eyeball nine tenths of the opening
// at +100 % and opens at -100 %, the lower lid comes up, each moves only its
// own lid, no lid goes into its eyeball and the skin does not tear. With
// orbicularis oculi alone Song's upper lid margin buckled at a third of the
// way (docs/notes.md).
TEST(Physics, TheLidDriversCloseSongsLidsOverTheEyeball) {
  AFM_REQUIRE_SHARED_DATA();
  Expected<LoadedFace> f = load_song();  // texture orientation plays no part in the model
  ASSERT_TRUE(f.is_ok()) << f.status().message();
  FaceModelOptions fo;
  fo.calibrate_only = {"palpebral_upper_left", "palpebral_lower_left"};
  fo.calibrate_jaw = false;
  Expected<SimFaceModel> b = build_sim_face_model(f->scene, f->fdps, {kDefaultSimVertices}, fo);
  ASSERT_TRUE(b.is_ok()) << b.status().message();
  const FaceModel &m = b->model;
  for (const std::string &w : m.warnings) ADD_FAILURE() << w;
  const Eigen::Vector3d top = m.fdps.find(*FdpId::parse("3.1"), m.skin)->pos;
  const Eigen::Vector3d bottom = m.fdps.find(*FdpId::parse("3.3"), m.skin)->pos;
  const double opening = (top - bottom).norm();
  auto deepest = [&m](const Eigen::MatrixXd &X) { return deepest_in_eyes(m, X); };
  auto pose = [&m](const char *name, double pct) {
    Activation a;
    a.muscles = {{m.find(name), pct}};
    FactorCache cache;
    Expected<Pose> p = solve_pose(m, a, &cache);
    EXPECT_TRUE(p.is_ok()) << name << " " << pct << ": " << p.status().message();
    return p.is_ok() ? p->X : m.tissue.X0;
  };
  for (const char *name : {"palpebral_upper_left", "palpebral_lower_left"}) {
    const Muscle &mu = m.muscles[static_cast<size_t>(m.find(name))];
    EXPECT_EQ(mu.range_max, 1) << name << " reaches the table's whole range";
    EXPECT_EQ(mu.eye, 0) << name << " lies on the left eyeball";
  }
  const Eigen::MatrixXd closed = pose("palpebral_upper_left", 100);
  EXPECT_LT(moved(m, closed, "3.1").y(), -0.75 * opening) << "the upper lid comes most of the way down";
  EXPECT_LT(moved(m, closed, "3.3").norm(), 0.05 * opening) << "the lower lid stays";
  EXPECT_LE(deepest(closed), m.solver.tolerance) << "no lid enters its eyeball";
  EXPECT_FALSE(skin_faults(m, closed.topRows(m.tissue.n)).tears());
  EXPECT_TRUE(closed.allFinite());
  const Eigen::MatrixXd wide = pose("palpebral_upper_left", -100);
  EXPECT_GT(moved(m, wide, "3.1").y(), 0.15 * opening) << "levator palpebrae opens the lid";
  const Eigen::MatrixXd up = pose("palpebral_lower_left", 100);
  EXPECT_GT(moved(m, up, "3.3").y(), 0.3 * opening) << "the lower lid comes up";
  EXPECT_LT(moved(m, up, "3.1").norm(), 0.05 * opening) << "the upper lid stays";
  EXPECT_LE(deepest(up), m.solver.tolerance);
  EXPECT_FALSE(skin_faults(m, up.topRows(m.tissue.n)).tears());
}

// Lip-lip contact (anatomy/lip_contact.h). The pair energy: zero above s_on,
// C2 there, and its derivatives those of its value (central differences).
TEST(LipContact, ThePairEnergyIsSmoothAndItsDerivativesMatch) {
  LipPair p;
  p.on = 0.3;
  p.margin = 0.05;
  p.stiffness = 2.0;
  for (double s : {0.3, 0.31, 1.0}) {
    const LipContactValue v = lip_contact_energy(p, s);
    EXPECT_EQ(v.e, 0.0);
    EXPECT_EQ(v.d1, 0.0);
    EXPECT_EQ(v.d2, 0.0);
  }
  const double h = 1e-6;
  for (double s : {0.299, 0.28, 0.25, 0.2, 0.1, -0.2}) {
    const LipContactValue v = lip_contact_energy(p, s);
    const LipContactValue up = lip_contact_energy(p, s + h), down = lip_contact_energy(p, s - h);
    EXPECT_GT(v.e, 0.0);
    EXPECT_LT(v.d1, 0.0) << "pushes the upper vertex up";
    EXPECT_GT(v.d2, 0.0);
    EXPECT_NEAR((up.e - down.e) / (2 * h), v.d1, 1e-6 * (1 + std::abs(v.d1))) << s;
    EXPECT_NEAR((up.d1 - down.d1) / (2 * h), v.d2, 1e-5 * (1 + std::abs(v.d2))) << s;
  }
  // A crossing of one margin: the contact pressure's force k.
  EXPECT_NEAR(lip_contact_energy(p, p.on - p.margin).d1, -p.stiffness, 1e-12);
  // C2 at s_on: the value and both derivatives vanish as s rises to it.
  const LipContactValue near = lip_contact_energy(p, p.on - 1e-9);
  EXPECT_LT(near.e, 1e-20);
  EXPECT_LT(std::abs(near.d1), 1e-12);
  EXPECT_LT(near.d2, 1e-5);
}

// The generated head's lips were cut apart along the seam (refhead): its
// pairs are the seam's coincident vertices, one on each lip, and no others.
TEST(LipContact, OnTheReferenceHeadThePairsAreTheLipSeam) {
  const FaceModel &m = head_1k().model;
  const SkinModel &s = m.tissue;
  Expected<MouthLips> lips = mouth_lips(s, m.fdps);
  ASSERT_TRUE(lips) << lips.status().message();
  std::vector<std::pair<int, int>> seam;
  for (int a : lips->upper)
    for (int b : lips->lower)
      if ((s.X0.row(a) - s.X0.row(b)).norm() < 1e-9) seam.emplace_back(a, b);
  ASSERT_GE(seam.size(), 5u) << "the lips meet along a seam of coincident vertices";
  std::vector<std::pair<int, int>> pairs;
  for (const LipPair &p : s.lip_pairs) {
    pairs.emplace_back(s.vertex_of(p.upper), s.vertex_of(p.lower));
    EXPECT_EQ(s.layer_of(p.upper), kEpidermis);
    EXPECT_EQ(p.on, 0.0) << "lips that touch at rest are in contact at once";
    EXPECT_NEAR(p.margin, kLipMargin * m.fapu.mns0, 1e-15);
    EXPECT_GT(p.stiffness, 0.0);
  }
  std::sort(seam.begin(), seam.end());
  EXPECT_EQ(pairs, seam);
  // Nothing of it at rest.
  EXPECT_EQ(crossed_lip_pairs(s, s.X0, 0.0), 0);
  // A vertex both searches reached (round a mouth corner) is never paired
  // with itself.
  std::vector<int> both = lips->upper;
  both.insert(both.end(), lips->lower.begin(), lips->lower.begin() + 3);
  std::sort(both.begin(), both.end());
  const std::vector<LipPair> again =
      lip_pairs(s, both, lips->lower, 1.0, kLipBand * m.fapu.mns0, kLipMargin * m.fapu.mns0);
  EXPECT_GE(again.size(), seam.size());
  for (const LipPair &p : again) EXPECT_NE(p.upper, p.lower);
}

// Both mentalis muscles push the lower lip up into the upper one. Without
// contact it passes into it by more than a margin; with it the lips meet:
// none crosses by more than one margin, the upper lip is pushed up, and the
// solve converges with no NaN and no inverted element.
TEST(Physics, PressedLipsMeetAndDoNotPassIntoEachOther) {
  const FaceModel &m = head_1k().model;
  const SkinModel &s = m.tissue;
  const Muscle &left = m.muscles[static_cast<size_t>(m.find("mentalis_left"))];
  const Muscle &right = m.muscles[static_cast<size_t>(m.find("mentalis_right"))];
  const double t = 0.1;
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
    return muscle_load(s, left, t, X, F, K) + muscle_load(s, right, t, X, F, K);
  };
  auto press = [&](bool contact, SolveStats *st, SolverKind kind = SolverKind::Newton) {
    Eigen::MatrixXd X = s.X0;
    SolverOptions so = m.solver;
    so.kind = kind;
    so.lip_contact = contact;
    FactorCache cache;
    *st = solve_equilibrium(s, all_vertices(s), f, s.X0, X, so, &cache);
    EXPECT_TRUE(st->converged) << st->message;
    return X;
  };
  SolveStats free_st, met_st;
  const Eigen::MatrixXd apart = press(false, &free_st), met = press(true, &met_st);
  const double margin = kLipMargin * m.fapu.mns0;
  double deepest_free = 0, deepest_met = 0;
  for (const LipPair &p : s.lip_pairs) {
    deepest_free = std::max(deepest_free, p.on - (apart(p.upper, 1) - apart(p.lower, 1)));
    deepest_met = std::max(deepest_met, p.on - (met(p.upper, 1) - met(p.lower, 1)));
  }
  std::printf("lower lip pushed up: the deepest crossing %.2f margins without contact, %.2f with; "
              "8.1 up %.3f mm against %.3f mm; %d against %d Newton iterations\n",
              deepest_free / margin, deepest_met / margin, mm(moved(m, met, "8.1").y()),
              mm(moved(m, apart, "8.1").y()), met_st.iterations, free_st.iterations);
  ASSERT_GT(deepest_free, 2 * margin) << "the load must press the lips together";
  EXPECT_LT(deepest_met, margin);
  EXPECT_EQ(crossed_lip_pairs(s, met, margin), 0);
  EXPECT_GT(moved(m, met, "8.1").y(), moved(m, apart, "8.1").y() + 0.5 * margin) << "the lower lip lifts the upper";
  EXPECT_TRUE(met.allFinite());
  EXPECT_EQ(inverted_elements(s, met), inverted_elements(s, apart));
  // At the equilibrium the contact's forces balance: the residual with them
  // is small, without them it is not.
  const Eigen::MatrixXd with = residual_forces(s, all_vertices(s), f, s.X0, met, true);
  const Eigen::MatrixXd without = residual_forces(s, all_vertices(s), f, s.X0, met, false);
  double w = 0, wo = 0;
  for (const LipPair &p : s.lip_pairs) {
    w = std::max(w, with.row(p.upper).norm());
    wo = std::max(wo, without.row(p.upper).norm());
  }
  EXPECT_LT(w, 0.01 * wo);
  // Every solver takes the contact: the same equilibrium, each within its
  // tolerance (allow a few).
  for (SolverKind kind : {SolverKind::NewtonRest, SolverKind::ImplicitEuler, SolverKind::NewtonJacobi}) {
    SolveStats st;
    const Eigen::MatrixXd other = press(true, &st, kind);
    EXPECT_LT((other - met).cwiseAbs().maxCoeff(), 10 * m.solver.tolerance) << solver_name(kind);
  }
}

TEST(Physics, TheJawOpens) {
  const FaceModel &m = head_1k().model;
  Activation a;
  a.jaw_open = 50;
  FactorCache cache;
  Expected<Pose> p = solve_pose(m, a, &cache);
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  const Eigen::Vector3d chin = moved(m, p->X, "2.1");
  EXPECT_LT(chin.y(), -5e-3) << "the chin goes down";
  const double gap = (p->X.row(m.fdps.find(*FdpId::parse("2.2"), m.skin)->vertex) -
                      p->X.row(m.fdps.find(*FdpId::parse("2.3"), m.skin)->vertex)).norm();
  EXPECT_GT(gap, 5e-3) << "the mouth opens";
  EXPECT_LT(moved(m, p->X, "9.3").norm(), 0.1e-3) << "the nose stays";
  EXPECT_TRUE(p->X.allFinite());
  EXPECT_EQ(penetrating_nodes(m.tissue, p->X, 1e-9), 0);
  // The jaw holds the lower lip (the mouth-window search adds what the rays
  // miss), not the upper lip (it removes what they hit); below the chin
  // only its front and underside, not the neck (jaw.h).
  EXPECT_GT(m.jaw.added, 0);
  Expected<MouthLips> lips = mouth_lips(m.tissue, m.fdps);
  ASSERT_TRUE(lips.is_ok()) << lips.status().message();
  const double chin_bottom = m.fdps.find(*FdpId::parse("2.1"))->pos.y();
  auto on_jaw = [&](int v) { return std::binary_search(m.jaw.vertices.begin(), m.jaw.vertices.end(), v); };
  ASSERT_FALSE(lips->lower.empty());
  for (int v : lips->lower) {
    if (m.tissue.X0(v, 1) >= chin_bottom) {
      EXPECT_TRUE(on_jaw(v)) << "lower-lip vertex " << v;
    }
  }
  for (int v : lips->upper) EXPECT_FALSE(on_jaw(v)) << "upper-lip vertex " << v;
  std::printf("jaw: %zu vertices, %zu ray hits, %d removed, %d added\n", m.jaw.vertices.size(), m.jaw.ray_hits.size(),
              m.jaw.removed, m.jaw.added);
  int below = 0;
  for (int v : m.jaw.vertices) {
    if (std::binary_search(m.jaw.ray_hits.begin(), m.jaw.ray_hits.end(), v) || m.tissue.X0(v, 1) >= chin_bottom)
      continue;
    ++below;
    const Eigen::Vector3d n = m.tissue.normal.row(v);
    EXPECT_TRUE(n.z() > -n.y() || -n.y() > std::sqrt(3.0) / 2)
        << "vertex " << v << " added below the chin faces neither forward nor down: " << n.transpose();
  }
  // Not the neck: nothing added below the chin lies a chin's height under it.
  const double chin_height = m.fdps.find(*FdpId::parse("2.3"))->pos.y() - chin_bottom;
  for (int v : m.jaw.vertices) EXPECT_GT(m.tissue.X0(v, 1), chin_bottom - chin_height) << "vertex " << v;
  std::printf("jaw: %d vertices added below the chin\n", below);
}

TEST(Physics, AShareOfTheJawsMotionIsTheSameMotionScaled) {
  // jaw_share (jaw.h) takes a motion apart into its turn and translation;
  // the share must be the motion made from the percentages times the share.
  const Jaw &jaw = head_1k().model.jaw;
  for (const double w : {0.0, 0.25, 0.5, 1.0})
    for (const auto &[open, thrust, shift] : {std::array<double, 3>{100, 0, 0}, std::array<double, 3>{40, 30, -20},
                                              std::array<double, 3>{0, -50, 70}}) {
      const Eigen::Affine3d share = jaw_share(jaw, jaw_motion(jaw, open, thrust, shift), w);
      const Eigen::Affine3d scaled = jaw_motion(jaw, w * open, w * thrust, w * shift);
      EXPECT_LT((share.matrix() - scaled.matrix()).cwiseAbs().maxCoeff(), 1e-12)
          << "share " << w << " of " << open << ", " << thrust << ", " << shift;
    }
}

namespace {

// The largest change, in degrees, of the angle between two skin triangles
// that share an edge with a vertex in `region`, from A to B (#V x 3 each).
double worst_bend(const Eigen::MatrixXi &F, const Eigen::MatrixXd &A, const Eigen::MatrixXd &B,
                  const std::vector<char> &region) {
  std::map<std::pair<int, int>, std::vector<int>> faces;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      faces[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  auto normal = [&F](const Eigen::MatrixXd &X, int f) {
    const Eigen::Vector3d p = X.row(F(f, 0)), q = X.row(F(f, 1)), r = X.row(F(f, 2));
    return Eigen::Vector3d((q - p).cross(r - p).normalized());
  };
  auto angle = [&](const Eigen::MatrixXd &X, int f, int g) {
    return std::acos(std::clamp(normal(X, f).dot(normal(X, g)), -1.0, 1.0)) * 180 / 3.14159265358979323846;
  };
  double worst = 0;
  for (const auto &[edge, fs] : faces)
    if (fs.size() == 2 && (region[static_cast<size_t>(edge.first)] || region[static_cast<size_t>(edge.second)]))
      worst = std::max(worst, std::abs(angle(B, fs[0], fs[1]) - angle(A, fs[0], fs[1])));
  return worst;
}

}  // namespace

TEST(Physics, TheSkinUnderTheChinFollowsTheOpeningJaw) {
  // Below the jaw line the skin takes a share of the jaw's motion that falls
  // with the distance from the jaw (jaw.h, "Followers"), so an opening jaw
  // does not fold it into spikes along the jaw's last vertices. Measured on
  // this head with no followers: the skin below 2.1 bent by 21 degrees at
  // 50 % and 31 at 100 %; with them by 8 and 17. Beside the jaw, above the
  // lower lip, only skin beyond the mouth corners follows.
  const FaceModel &m = head_1k().model;
  const SkinModel &s = m.tissue;
  ASSERT_FALSE(m.jaw.followers.empty());
  EXPECT_GT(m.jaw.beside, 0);
  Expected<MouthLips> lips = mouth_lips(s, m.fdps);
  ASSERT_TRUE(lips.is_ok()) << lips.status().message();
  const double chin = m.fdps.find(*FdpId::parse("2.1"))->pos.y();
  const Eigen::Vector3d left = m.fdps.find(*FdpId::parse("2.4"))->pos, right = m.fdps.find(*FdpId::parse("2.5"))->pos;
  double nearest = 0;  // the largest share: next to the jaw's vertices
  for (const auto &[v, share] : m.jaw.followers) {
    EXPECT_GT(share, 0) << "vertex " << v;
    EXPECT_LT(share, 1) << "vertex " << v;
    EXPECT_FALSE(std::binary_search(m.jaw.vertices.begin(), m.jaw.vertices.end(), v)) << "vertex " << v;
    EXPECT_FALSE(std::binary_search(lips->upper.begin(), lips->upper.end(), v)) << "upper-lip vertex " << v;
    if (s.X0(v, 1) >= m.fdps.find(*FdpId::parse("2.3"))->pos.y()) {
      EXPECT_TRUE(s.X0(v, 0) > left.x() || s.X0(v, 0) < right.x())
          << "vertex " << v << " is above the lower lip between the mouth corners";
    }
    nearest = std::max(nearest, share);
  }
  EXPECT_GT(nearest, 0.5);
  std::vector<char> below(static_cast<size_t>(s.n), 0);
  for (int v = 0; v < s.n; ++v) below[static_cast<size_t>(v)] = s.X0(v, 1) < chin;
  FactorCache cache;
  for (const double open : {50.0, 100.0}) {
    Activation a;
    a.jaw_open = open;
    Expected<Pose> p = solve_pose(m, a, &cache);
    ASSERT_TRUE(p.is_ok()) << p.status().message();
    // Each follower's bone is where its share of the motion puts it.
    for (const auto &[v, share] : m.jaw.followers) {
      const int g = s.node(kSkull, v);
      const Eigen::Vector3d want = jaw_share(m.jaw, p->jaw, share) * Eigen::Vector3d(s.X0.row(g).transpose());
      EXPECT_LT((p->X.row(g).transpose() - want).norm(), 1e-12) << "vertex " << v;
    }
    const Eigen::MatrixXd E = pose_epidermis(m, *p);
    const double bend = worst_bend(s.F, s.X0.topRows(s.n), E, below);
    EXPECT_LT(bend, 20) << "jaw " << open << " %: the skin below the chin folds";
    for (int f : turned_faces(s.X0.topRows(s.n), s.F, E))
      EXPECT_FALSE(below[static_cast<size_t>(s.F(f, 0))] || below[static_cast<size_t>(s.F(f, 1))] ||
                   below[static_cast<size_t>(s.F(f, 2))])
          << "jaw " << open << " %: triangle " << f << " below the chin turns over";
    EXPECT_EQ(penetrating_nodes(s, p->X, 1e-9), 0);
    std::printf("jaw %.0f %%: %zu followers, the skin below the chin bends by %.1f degrees at most\n", open,
                m.jaw.followers.size(), bend);
  }
}

TEST(Physics, APoseStartedFromANearbyOneIsTheSameEquilibrium) {
  // The jaw's secant steps (fap_synthesis.h) start each solve from an earlier
  // pose: the jaw's vertices are carried from its motion to the new one.
  const FaceModel &m = head_1k().model;
  FactorCache cache;
  Activation a30, a50;
  a30.jaw_open = 30;
  a50.jaw_open = 50;
  Expected<Pose> p30 = solve_pose(m, a30, &cache);
  Expected<Pose> rest = solve_pose(m, a50, &cache);
  ASSERT_TRUE(p30.is_ok() && rest.is_ok());
  PoseOptions po;
  po.start = &*p30;
  Expected<Pose> warm = solve_pose(m, a50, &cache, po);
  ASSERT_TRUE(warm.is_ok()) << warm.status().message();
  EXPECT_LE((pose_epidermis(m, *warm) - pose_epidermis(m, *rest)).cwiseAbs().maxCoeff(), m.quantum);
  EXPECT_LT(warm->stats.iterations, rest->stats.iterations);
  EXPECT_TRUE(warm->jaw.isApprox(rest->jaw, 0));
  EXPECT_TRUE(std::includes(warm->dynamic.begin(), warm->dynamic.end(), p30->dynamic.begin(), p30->dynamic.end()));
  // The skull stays where the new jaw puts it, exactly (its followers' too).
  std::vector<int> carried = m.jaw.vertices;
  for (const auto &f : m.jaw.followers) carried.push_back(f.first);
  for (int v : carried) {
    const int g = m.tissue.node(kSkull, v);
    EXPECT_EQ(warm->X.row(g), rest->X.row(g)) << "vertex " << v;
  }
  EXPECT_EQ(penetrating_nodes(m.tissue, warm->X, 1e-9), 0);
  std::printf("jaw 50 %%: %d Newton iterations from rest, %d from the pose at 30 %%\n", rest->stats.iterations,
              warm->stats.iterations);
}

TEST(Physics, PosesStartedFromTheCalibratedPosesAddedAreTheSameEquilibria) {
  // The synthesis starts poses that combine muscles and the jaw from
  // superposed_pose.
  FaceModelOptions fo;
  fo.calibrate_only = {"zygomaticus_major_left", "risorius_left"};
  Expected<FaceModel> m = build_face_model(head_1k().head.scene, head_1k().head.fdps, fo);
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  const int zyg = m->find("zygomaticus_major_left"), ris = m->find("risorius_left");
  FactorCache cache;
  // One muscle at +100 %, or the jaw fully open: the guess is the
  // calibrated pose, already in equilibrium. A few iterations find its
  // eyeball contacts again: a lid node held at its clearance lies on that
  // sphere only to rounding, and is free until a step pushes it in (3
  // iterations since lid nodes are held up to their rest distance, 1
  // before). The jaw takes 9 on the default tissue, its pose 0.05 quanta
  // from the start (2 without the collapse floor, 12 with it at 0.3).
  Activation one, open;
  one.muscles = {{zyg, 100.0}};
  open.jaw_open = 100;
  PoseOptions po;
  for (const Activation &a : {one, open}) {
    const Pose alone = superposed_pose(*m, a);
    po.start = &alone;
    Expected<Pose> settled = solve_pose(*m, a, &cache, po);
    ASSERT_TRUE(settled.is_ok()) << settled.status().message();
    EXPECT_LE(settled->stats.iterations, a.jaw_open > 0 ? 10 : 3) << "jaw " << a.jaw_open;
    EXPECT_LE((settled->X - alone.X).cwiseAbs().maxCoeff(), m->quantum);
  }
  // Both at 70 % and -60 %, and both at 50 % with the jaw open 40 %: the same
  // equilibrium as from rest, in fewer iterations, or with the jaw no more
  // (5 and 5; 7 and 6 until the skin beside the jaw took a share of its
  // motion, jaw.h).
  for (double pct : {70.0, -60.0, 50.0}) {
    Activation two;
    two.muscles = {{zyg, pct}, {ris, pct}};
    if (pct == 50) two.jaw_open = 40;
    Expected<Pose> rest = solve_pose(*m, two, &cache);
    const Pose guess = superposed_pose(*m, two);
    po.start = &guess;
    Expected<Pose> warm = solve_pose(*m, two, &cache, po);
    ASSERT_TRUE(rest.is_ok() && warm.is_ok());
    EXPECT_LE((pose_epidermis(*m, *warm) - pose_epidermis(*m, *rest)).cwiseAbs().maxCoeff(), m->quantum) << pct;
    if (two.jaw_open > 0) {
      EXPECT_LE(warm->stats.iterations, rest->stats.iterations) << pct;
    } else {
      EXPECT_LT(warm->stats.iterations, rest->stats.iterations) << pct;
    }
    // Not the pose itself: the guess moves the corner further than the
    // muscles together do, but not twice as far.
    const int corner = m->fdps.find(*FdpId::parse("8.3"), m->skin)->vertex;
    const double guessed = (guess.X.row(corner) - m->tissue.X0.row(corner)).norm();
    const double solved = (rest->X.row(corner) - m->tissue.X0.row(corner)).norm();
    EXPECT_GT(guessed, 0.5 * solved) << pct;
    EXPECT_LT(guessed, 2.0 * solved) << pct;
    std::printf("both at %+.0f %%, the jaw open %.0f %%: %d Newton iterations from rest, %d from the calibrated poses "
                "added; the mouth corner moves %.4f, the guess %.4f\n",
                pct, two.jaw_open, rest->stats.iterations, warm->stats.iterations, solved, guessed);
  }
}

TEST(Physics, ResidualBelowToleranceAtTheEnd) {
  const FaceModel &m = head_1k().model;
  const int i = m.find("zygomaticus_major_left");
  const Muscle &mu = m.muscles[static_cast<size_t>(i)];
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) { return muscle_load(m.tissue, mu, 0.05, X, F, K); };
  SolveStats st;
  const Eigen::MatrixXd X = contract(m, "zygomaticus_major_left", 0.05, &st);
  EXPECT_LT(st.residual, m.solver.tolerance);
  // Independently: the net force on every free node is tiny next to the
  // muscle's largest nodal force (skull and eyeball contacts take their
  // normal part; a lid node may be held at its rest distance from the ball).
  Eigen::MatrixXd load = Eigen::MatrixXd::Zero(X.rows(), 3);
  muscle_load(m.tissue, mu, 0.05, X, &load);
  const Eigen::MatrixXd r = residual_forces(m.tissue, all_vertices(m.tissue), f, m.tissue.X0, X);
  double worst = 0;
  for (int g = 0; g < X.rows(); ++g) {
    Eigen::Vector3d rg = r.row(g);
    const int v = m.tissue.vertex_of(g);
    const Eigen::Vector3d n = m.tissue.normal.row(v);
    const double gap = (X.row(g) - X.row(m.tissue.node(kSkull, v))).dot(n);
    if (skull_rejects(m.tissue, v) && gap < 1e-9) rg -= n * std::min(0.0, rg.dot(n));
    if (const int e = m.tissue.eye_near[static_cast<size_t>(v)]; e >= 0 && g == m.tissue.node(kEpidermis, v)) {
      const EyeSphere &ball = m.tissue.eyes[static_cast<size_t>(e)];
      const Eigen::Vector3d q = X.row(g).transpose() - ball.centre;
      if (q.norm() - ball.radius - eye_clearance_in(m.tissue, v, X) < 1e-9)
        rg -= q.normalized() * std::min(0.0, rg.dot(q.normalized()));
    }
    worst = std::max(worst, rg.norm());
  }
  EXPECT_LT(worst, 1e-3 * load.rowwise().norm().maxCoeff());
}

TEST(Physics, InvariantUnderTranslationAndScalesWithTheHead) {
  RefHeadOptions o;
  o.skin_vertices = 1000;
  Expected<RefHead> h = make_reference_head(o);
  ASSERT_TRUE(h.is_ok());
  auto displacement = [&](const Eigen::Vector3d &shift, double scale) {
    Scene s = h->scene;
    FdpSet f = h->fdps;
    for (Part &p : s.parts) p.V = ((p.V * scale).rowwise() + shift.transpose()).eval();
    for (FdpPoint &p : f.points) p.pos = p.pos * scale + shift;
    FaceModelOptions fo;
    fo.calibrate = false;
    Expected<FaceModel> m = build_face_model(s, f, fo);
    EXPECT_TRUE(m.is_ok()) << m.status().message();
    const Eigen::MatrixXd X = contract(*m, "zygomaticus_major_left", 0.06);
    return Eigen::MatrixXd(X.topRows(m->tissue.n) - m->tissue.X0.topRows(m->tissue.n));
  };
  const Eigen::MatrixXd base = displacement(Eigen::Vector3d::Zero(), 1.0);
  const double q = head_1k().model.quantum;
  EXPECT_LT((displacement(Eigen::Vector3d(0.3, -0.2, 0.5), 1.0) - base).cwiseAbs().maxCoeff(), q);
  EXPECT_LT((displacement(Eigen::Vector3d::Zero(), 2.0) - 2.0 * base).cwiseAbs().maxCoeff(), 2 * q);
  EXPECT_GT(base.cwiseAbs().maxCoeff(), 100 * q) << "the muscle moved the face";
}

TEST(Physics, DynamicSetEqualsWholeMeshWithinOneQuantum) {
  Expected<FaceModel> m = model_1k({"zygomaticus_major_left"});
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  Activation a;
  a.muscles = {{m->find("zygomaticus_major_left"), 80.0}};
  FactorCache cache;
  Expected<Pose> dyn = solve_pose(*m, a, &cache);
  ASSERT_TRUE(dyn.is_ok()) << dyn.status().message();
  PoseOptions whole;
  whole.whole_mesh = true;
  Expected<Pose> all = solve_pose(*m, a, &cache, whole);
  ASSERT_TRUE(all.is_ok()) << all.status().message();
  EXPECT_LT(dyn->dynamic.size(), all->dynamic.size());
  const Eigen::MatrixXd d = pose_epidermis(*m, *dyn) - pose_epidermis(*m, *all);
  EXPECT_LE(d.cwiseAbs().maxCoeff(), m->quantum);
  // Calibration: +80 % moves the corner 80 % of the way to the target of +100 %.
  const Muscle &mu = m->muscles[static_cast<size_t>(m->find("zygomaticus_major_left"))];
  const double action = muscle_action(m->tissue, mu, dyn->X);
  EXPECT_GT(action, 0.6 * muscle_action_target(mu, true));
  EXPECT_LT(action, 1.0 * muscle_action_target(mu, true));
  // Uncalibrated muscles cannot be posed.
  Activation other;
  other.muscles = {{m->find("frontalis_major_left"), 50.0}};
  EXPECT_FALSE(solve_pose(*m, other, &cache).is_ok());
}

// A partial opening starts on the skin the full one's calibrated response,
// scaled to it, moves past half the wave threshold (face_model.h): a
// viseme's third of an opening solves on less than the full opening's set,
// and gets the whole mesh's pose within a quantum.
TEST(Physics, APartialJawOpeningSolvesOnLessSkinWithinOneQuantum) {
  FaceModelOptions fo;
  fo.calibrate_only = {"risorius_left"};
  Expected<FaceModel> m = build_face_model(head_1k().head.scene, head_1k().head.fdps, fo);
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  ASSERT_FALSE(m->jaw.dynamic.empty());
  Activation a;
  a.jaw_open = 30;
  FactorCache cache;
  Expected<Pose> dyn = solve_pose(*m, a, &cache);
  PoseOptions whole;
  whole.whole_mesh = true;
  Expected<Pose> all = solve_pose(*m, a, &cache, whole);
  ASSERT_TRUE(dyn.is_ok() && all.is_ok());
  EXPECT_LT(dyn->dynamic.size(), m->jaw.dynamic.size());
  EXPECT_TRUE(std::includes(dyn->dynamic.begin(), dyn->dynamic.end(), m->jaw.vertices.begin(), m->jaw.vertices.end()));
  const double diff = (pose_epidermis(*m, *dyn) - pose_epidermis(*m, *all)).cwiseAbs().maxCoeff();
  EXPECT_LE(diff, m->quantum);
  // The guess the synthesis starts from starts on the same smaller set.
  const Pose guess = superposed_pose(*m, a);
  EXPECT_LT(guess.dynamic.size(), m->jaw.dynamic.size());
  EXPECT_TRUE(std::includes(dyn->dynamic.begin(), dyn->dynamic.end(), guess.dynamic.begin(), guess.dynamic.end()));
  std::printf("jaw 30 %%: %zu of the full opening's %zu vertices, %.2f quanta from the whole mesh's pose\n",
              dyn->dynamic.size(), m->jaw.dynamic.size(), diff / m->quantum);
}

// The jaw's calibrated full opening is solved by newton whatever the model's
// solver, like the muscles' calibrations (face_model.h): implicit-euler found
// no equilibrium for it on Song's default tissue within its 2,000 steps, and
// a build with it failed there. The poses keep the model's solver.
TEST(Calibration, TheJawsFullOpeningIsSolvedByNewtonWhateverTheModelsSolver) {
  auto jaw_only = [](SolverKind kind) {
    FaceModelOptions fo;
    fo.calibrate_muscles = false;
    fo.solver.kind = kind;
    return build_face_model(head_1k().head.scene, head_1k().head.fdps, fo);
  };
  Expected<FaceModel> newton = jaw_only(SolverKind::Newton), euler = jaw_only(SolverKind::ImplicitEuler);
  ASSERT_TRUE(newton.is_ok()) << newton.status().message();
  ASSERT_TRUE(euler.is_ok()) << euler.status().message();
  EXPECT_EQ(euler->solver.kind, SolverKind::ImplicitEuler);
  EXPECT_EQ(euler->jaw.dynamic, newton->jaw.dynamic);
  EXPECT_EQ(euler->jaw.open_response.nodes, newton->jaw.open_response.nodes);
  EXPECT_TRUE(euler->jaw.open_response.displacement == newton->jaw.open_response.displacement)
      << "the same solver, the same numbers";
  // From that start, the model's implicit-euler finds the full opening's pose.
  Activation a;
  a.jaw_open = 100;
  FactorCache cache;
  Expected<Pose> pose = solve_pose(*euler, a, &cache);
  EXPECT_TRUE(pose.is_ok()) << pose.status().message();
}

TEST(Calibration, FullContractionMovesTheKeyNodeByItsTarget) {
  Expected<FaceModel> m = model_1k({"zygomaticus_major_left", "orbicularis_oris"});
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  for (const std::string name : {"zygomaticus_major_left", "orbicularis_oris"}) {
    const Muscle &mu = m->muscles[static_cast<size_t>(m->find(name))];
    EXPECT_GT(mu.tension_max, mu.tension_min) << name << ": pulling further takes more tension";
    for (double pct : {100.0, -100.0}) {
      Activation a;
      a.muscles = {{m->find(name), pct}};
      FactorCache cache;
      Expected<Pose> p = solve_pose(*m, a, &cache);
      ASSERT_TRUE(p.is_ok()) << p.status().message();
      // The calibration solved for the tension with the action as an
      // equation: the pose meets the target to within the solver tolerance.
      EXPECT_NEAR(muscle_action(m->tissue, mu, p->X), muscle_action_target(mu, pct > 0), 4 * m->solver.tolerance)
          << name << " at " << pct << " %";
    }
  }
}

// The generated heads' mouth is closed: the lip line has two vertices at
// each point, one per lip, and 2.8 (the lower lip) shares its place with 2.6
// (the upper one). Mentalis inserts at 2.8 and calibrates on it; by index
// order its key node had been 2.6's, on the upper lip, which the push hardly
// moves: the 2k head's mentalis calibrated to tension 6.1 (21 on its fibre
// from the chin), and 30 % of it lifted the lower lip 5 cm. At +100 % the
// lower lip rises by the calibrated action, give or take its off-axis share.
TEST(Calibration, MentalisMeasuresTheLowerLipWhereTheLipsMeet) {
  Expected<FaceModel> m = model_1k({"mentalis_left"});
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  const FdpPoint *upper = m->fdps.find(*FdpId::parse("2.6"), m->skin);
  const FdpPoint *lower = m->fdps.find(*FdpId::parse("2.8"), m->skin);
  ASSERT_TRUE(upper && lower);
  ASSERT_NE(upper->vertex, lower->vertex);
  ASSERT_EQ(m->tissue.X0.row(upper->vertex), m->tissue.X0.row(lower->vertex)) << "the lips meet: one place";
  const int i = m->find("mentalis_left");
  const Muscle &mu = m->muscles[static_cast<size_t>(i)];
  EXPECT_EQ(m->tissue.vertex_of(mu.node_b), lower->vertex) << "the insertion is the lower lip's";
  Activation a;
  a.muscles = {{i, 100.0}};
  FactorCache cache;
  Expected<Pose> p = solve_pose(*m, a, &cache);
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  const double target = muscle_action_target(mu, true);
  const Eigen::Vector3d d = p->X.row(lower->vertex) - m->tissue.X0.row(lower->vertex);
  EXPECT_GT(d.y(), 0.5 * target) << "the lower lip rises";
  EXPECT_LT(d.norm(), 2 * target) << "by about the calibrated action, not many times it";
}

namespace {

// Checks that non-essential muscle `name` was kept with a part of its +100 %
// range, with a warning beginning "`name`: `cause`" that says which part, and
// that its +100 % pose meets the part's target. Returns that pose.
Pose expect_calibrated_to_a_part(const FaceModel &m, const std::string &name, const std::string &cause) {
  const int i = m.find(name);
  EXPECT_GE(i, 0) << name << " kept, not skipped";
  if (i < 0) return Pose{};
  const Muscle &mu = m.muscles[static_cast<size_t>(i)];
  EXPECT_LT(mu.range_max, 1.0);
  EXPECT_GE(mu.range_max, 0.125);
  bool said = false;
  for (const std::string &w : m.warnings)
    said |= w.find(name + ": " + cause + " the table's +100 % (") == 0 && w.find("+100 % stands for a") != std::string::npos;
  EXPECT_TRUE(said) << name << ": " << cause;
  const MuscleDef &d = muscle_table()[static_cast<size_t>(mu.def)];
  EXPECT_NEAR(muscle_action_target(mu, true), d.max_fraction * mu.range_max * mu.length, 1e-12);
  Activation a;
  a.muscles = {{i, 100.0}};
  FactorCache cache;
  Expected<Pose> p = solve_pose(m, a, &cache);
  EXPECT_TRUE(p.is_ok()) << p.status().message();
  if (!p) return Pose{};
  EXPECT_NEAR(muscle_action(m.tissue, mu, p->X), muscle_action_target(mu, true), 4 * m.solver.tolerance);
  return *p;
}

}  // namespace

// A non-essential muscle whose tissue locks before its key node reaches the
// table's range calibrates to the part the tissue allows (a half, a
// quarter or an eighth), says so, and +100 % then meets that part. Here the
// 1k head's tissue stiffens a thousandfold beyond 3 % strain, and frontalis
// outer gets a part of its range. (Frontalis major did until the generator's
// lid rows; since, at knees of 2-3 %, its +100 % pose solved from rest
// misses the calibrated part's action by 10-16 microns, over the 9.8 allowed;
// not looked into.)
// (This was Song's eye sphincter on its whole skin, a
// 46 s test, until the sphincters' areas were found on the surface: it now
// cannot move its key node, estimated over bone, even an eighth, and is
// skipped with a warning.)
TEST(Calibration, AMuscleWhoseTissueLocksCalibratesToThePartItAllows) {
  FaceModelOptions fo;
  fo.calibrate_only = {"frontalis_outer_left"};
  fo.calibrate_jaw = false;
  for (SlabParams &slab : fo.tissue.slab) slab.knee = 0.03, slab.ratio = 1e3;
  Expected<FaceModel> m = build_face_model(head_1k().head.scene, head_1k().head.fdps, fo);
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  expect_calibrated_to_a_part(*m, "frontalis_outer_left", "its tissue locks before the key node reaches");
}

// A non-essential muscle whose table range has no equilibrium the solver
// can find calibrates to the part that has one, and says so. The generated
// heads' upper lids open as wide as the iris (MPEG-4's neutral face), so
// their driver must turn the lid 50 degrees over the eyeball at +100 %; on
// the 1k head Newton finds no equilibrium there, and the driver used to be
// skipped (FAP 19 then fell back to orbicularis oculi and reached 72 % of
// its reference on the 2k head at four times the table's contraction).
TEST(Calibration, AMuscleWithNoEquilibriumAtItsRangeCalibratesToThePartThatHasOne) {
  FaceModelOptions fo;
  fo.calibrate_only = {"palpebral_upper_left"};
  fo.calibrate_jaw = false;
  Expected<FaceModel> m = build_face_model(head_1k().head.scene, head_1k().head.fdps, fo);
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  const Pose p = expect_calibrated_to_a_part(*m, "palpebral_upper_left", "the solver finds no equilibrium with the key node at");
  const int i = m->find("palpebral_upper_left");
  ASSERT_GE(i, 0);
  const Muscle &mu = m->muscles[static_cast<size_t>(i)];
  EXPECT_EQ(mu.range_min, 1.0) << "opening the lid has an equilibrium at the table's range";
  // The margin comes down over the eye (the action is its turn), without a tear.
  EXPECT_GT(muscle_action_target(mu, true), 0.1 * mu.length);
  ASSERT_EQ(p.X.rows(), m->tissue.X0.rows());
  EXPECT_FALSE(skin_faults(*m, p.X.topRows(m->tissue.n)).tears());
  // Steered to the table's full turn, Newton cycles: the solve gives up once
  // it stops making progress (solver.h, "Stopping rule"), not after its 400
  // iterations (3.2 s of each upper and lower driver's 3.3 s on the 10k head).
  const double full = muscle_action_target(mu, true) / mu.range_max;
  PoseAction turn = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *g) { return muscle_action(m->tissue, mu, X, g); };
  FactorCache cache;
  double scale = 0;
  Expected<Pose> no = solve_pose_to(*m, {{i, 100.0}}, turn, full, &cache, &scale);
  ASSERT_FALSE(no.is_ok());
  EXPECT_NE(no.status().message().find("no progress in 60 iterations"), std::string::npos) << no.status().message();
}

TEST(Calibration, TheSameOnAnyNumberOfThreads) {
  const Built &b = head_1k();
  FaceModelOptions fo;
  fo.calibrate_only = {"corrugator_left", "risorius_right", "upper_lip_left"};
  fo.threads = 1;
  Expected<FaceModel> one = build_face_model(b.head.scene, b.head.fdps, fo);
  fo.threads = 3;
  Expected<FaceModel> three = build_face_model(b.head.scene, b.head.fdps, fo);
  ASSERT_TRUE(one.is_ok() && three.is_ok());
  ASSERT_EQ(one->muscles.size(), three->muscles.size());
  for (size_t i = 0; i < one->muscles.size(); ++i) {
    EXPECT_EQ(one->muscles[i].tension_max, three->muscles[i].tension_max) << one->muscles[i].name;
    EXPECT_EQ(one->muscles[i].tension_min, three->muscles[i].tension_min) << one->muscles[i].name;
    EXPECT_EQ(one->muscles[i].dynamic, three->muscles[i].dynamic) << one->muscles[i].name;
  }
  EXPECT_EQ(one->jaw.dynamic, three->jaw.dynamic);
  EXPECT_GT(one->muscles[static_cast<size_t>(one->find("risorius_right"))].tension_max, 0);
}

TEST(Solver, ThePapersSchemeReachesTheSameEquilibrium) {
  const FaceModel &m = head_1k().model;
  const Eigen::MatrixXd xn = contract(m, "depressor_anguli_left", 0.05, nullptr, SolverKind::Newton);
  const Eigen::MatrixXd xe = contract(m, "depressor_anguli_left", 0.05, nullptr, SolverKind::ImplicitEuler);
  const Eigen::MatrixXd xj = contract(m, "depressor_anguli_left", 0.05, nullptr, SolverKind::NewtonJacobi);
  const Eigen::MatrixXd xr = contract(m, "depressor_anguli_left", 0.05, nullptr, SolverKind::NewtonRest);
  // Each stops within its tolerance of the equilibrium; allow a few.
  EXPECT_LT((xn - xe).cwiseAbs().maxCoeff(), 10 * m.solver.tolerance);
  EXPECT_LT((xn - xj).cwiseAbs().maxCoeff(), 10 * m.solver.tolerance);
  EXPECT_LT((xn - xr).cwiseAbs().maxCoeff(), 10 * m.solver.tolerance);
}

TEST(Solver, NeverReportsAnUnconvergedResultAsConverged) {
  const FaceModel &m = head_1k().model;
  const Muscle &mu = m.muscles[static_cast<size_t>(m.find("zygomaticus_major_left"))];
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) { return muscle_load(m.tissue, mu, 0.05, X, F, K); };
  SolverOptions so = m.solver;
  so.max_iterations = 1;
  Eigen::MatrixXd X = m.tissue.X0;
  FactorCache cache;
  SolveStats st = solve_equilibrium(m.tissue, all_vertices(m.tissue), f, m.tissue.X0, X, so, &cache);
  EXPECT_FALSE(st.converged);
  EXPECT_NE(st.message.find("no equilibrium"), std::string::npos) << st.message;
  EXPECT_TRUE(X.allFinite());
}

TEST(Solver, TotalsAddUpTheWorkOfEverySolveThatSharesThem) {
  // afm-build --stats: every solve adds its counts to the options' totals
  // when it ends, a failed one too.
  const FaceModel &m = head_1k().model;
  const Muscle &mu = m.muscles[static_cast<size_t>(m.find("zygomaticus_major_left"))];
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) { return muscle_load(m.tissue, mu, 0.3, X, F, K); };
  SolveTotals totals;
  SolverOptions so = m.solver;
  so.totals = &totals;
  Eigen::MatrixXd X;
  const SolveStats a = solve_from_rest(m, all_vertices(m.tissue), f, so, X);
  ASSERT_TRUE(a.converged) << a.message;
  so.max_iterations = 1;
  const SolveStats b = solve_from_rest(m, all_vertices(m.tissue), f, so, X);
  ASSERT_FALSE(b.converged);
  // A tangent per Newton iteration at least (more where the full one is
  // indefinite), but for the chord steps (SolverOptions::keep_tangent), and
  // the line search measured energies.
  EXPECT_GE(a.assemblies + a.chord_steps, a.iterations);
  EXPECT_GT(a.energies, 0);
  EXPECT_GT(a.factorisations, 0);
  EXPECT_EQ(totals.solves.load(), 2);
  EXPECT_EQ(totals.failed.load(), 1);
  EXPECT_EQ(totals.iterations.load(), a.iterations + b.iterations);
  EXPECT_EQ(totals.cg_iterations.load(), a.cg_iterations + b.cg_iterations);
  EXPECT_EQ(totals.factorisations.load(), a.factorisations + b.factorisations);
  EXPECT_EQ(totals.assemblies.load(), a.assemblies + b.assemblies);
  EXPECT_EQ(totals.energies.load(), a.energies + b.energies);
  std::printf("two solves: %lld Newton iterations, %lld tangents, %lld energies, %lld factorisations\n",
              totals.iterations.load(), totals.assemblies.load(), totals.energies.load(),
              totals.factorisations.load());
}

TEST(Solver, ChordStepsReachTheSameEquilibriumWithFewerTangents) {
  // SolverOptions::keep_tangent: once Newton converges fast, a step after
  // one shorter than 10 tol is made on the last tangent and only the force
  // is assembled. Six muscles of the 1k head, each pulling at its calibrated
  // +100 % tension on its dynamic set, with chord steps and without: the
  // same equilibrium (within the tolerance of each), fewer tangents, and no
  // more Newton iterations. Switched off, the counts' checks fail; without
  // the bound on the step, the iterations' check (41 against 35).
  const std::vector<std::string> names = {"frontalis_inner_left", "corrugator_left",  "zygomaticus_major_left",
                                          "depressor_anguli_left", "orbicularis_oris", "mentalis_left"};
  Expected<FaceModel> model = model_1k(names);
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  const FaceModel &m = *model;
  int chords = 0, tangents[2] = {0, 0}, iterations[2] = {0, 0};
  for (const std::string &name : names) {
    const Muscle &mu = m.muscles[static_cast<size_t>(m.find(name))];
    ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
      return muscle_load(m.tissue, mu, mu.tension_max, X, F, K);
    };
    Eigen::MatrixXd X[2];
    for (int keep = 0; keep < 2; ++keep) {
      SolverOptions so = m.solver;
      so.keep_tangent = keep == 1;
      const SolveStats st = solve_from_rest(m, mu.dynamic, f, so, X[keep]);
      ASSERT_TRUE(st.converged) << mu.name << ": " << st.message;
      if (keep == 0) {
        EXPECT_EQ(st.chord_steps, 0) << mu.name;
      } else {
        chords += st.chord_steps;
      }
      tangents[keep] += st.assemblies;
      iterations[keep] += st.iterations;
    }
    EXPECT_LT((X[1] - X[0]).cwiseAbs().maxCoeff(), m.quantum) << mu.name;
  }
  std::printf("1k head, six muscles at +100 %%: %d chord steps; %d tangents and %d Newton iterations with them, "
              "%d and %d without\n",
              chords, tangents[1], iterations[1], tangents[0], iterations[0]);
  EXPECT_GT(chords, 0);
  EXPECT_LT(tangents[1], tangents[0]);
  EXPECT_LE(iterations[1], iterations[0]);
}

TEST(Solver, TheLineSearchCarriesItsEnergyAcrossTheContacts) {
  // After a step the contacts put nodes back on the skull or an eyeball; the
  // next line search starts from the tissue energy measured at the step,
  // with the change of the terms those nodes are in added
  // (SolveStats::carried_energies). Checked against the energy evaluated
  // there after every such step: equal to rounding. Without the change
  // added, the gap is that of the contacts' corrections (0.35 of the energy
  // when this was written, and the check fails).
  const std::vector<std::string> names = {"palpebral_upper_left", "orbicularis_oculi_left", "frontalis_inner_left",
                                          "zygomaticus_major_left"};
  Expected<FaceModel> model = model_1k(names);
  ASSERT_TRUE(model.is_ok()) << model.status().message();
  const FaceModel &m = *model;
  int carried = 0, energies = 0;
  double gap = 0;
  for (const std::string &name : names) {
    const Muscle &mu = m.muscles[static_cast<size_t>(m.find(name))];
    ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
      return muscle_load(m.tissue, mu, mu.tension_max, X, F, K);
    };
    SolverOptions so = m.solver;
    so.check_carried_energy = true;
    Eigen::MatrixXd X;
    const SolveStats st = solve_from_rest(m, mu.dynamic, f, so, X);
    ASSERT_TRUE(st.converged) << mu.name << ": " << st.message;
    carried += st.carried_energies;
    energies += st.energies;
    gap = std::max(gap, st.carried_energy_gap);
  }
  std::printf("1k head, four muscles at +100 %%: %d energies evaluated, %d carried across the contacts; largest gap "
              "%.3g of the energy\n",
              energies, carried, gap);
  EXPECT_GT(carried, 0);
  EXPECT_LT(gap, 1e-12);
}

TEST(Solver, LongerStepsCutTheCrawlOnAStiffSkin) {
  // bench_builder's stiffness case on the 1k head: the epidermis 10 times
  // stiffer. Frontalis inner pulls the forehead up; Newton's steps on the
  // projected tangent fall short along the mode the compressed springs
  // soften. Tried at 2, 4 and 8 times their length while the energy falls,
  // they reach the same equilibrium in fewer iterations (19 -> 13 when
  // this was written; switched off, the last check fails). On the tissue
  // before the layered skin and the floor (unlayered_tissue), where this was
  // measured: on the default one the two solves end 8 quanta apart.
  const Built &b = head_1k();
  FaceModelOptions fo;
  fo.calibrate = false;
  fo.tissue = unlayered_tissue();
  fo.tissue.slab[0].modulus *= 10;
  Expected<FaceModel> m = build_face_model(b.head.scene, b.head.fdps, fo);
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  const Muscle &mu = m->muscles[static_cast<size_t>(m->find("frontalis_inner_right"))];
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
    return muscle_load(m->tissue, mu, 2.0, X, F, K);
  };
  SolveStats st[2];
  Eigen::MatrixXd X[2];
  for (int extend = 0; extend < 2; ++extend) {
    SolverOptions so = m->solver;
    so.extend_steps = extend == 1;
    st[extend] = solve_from_rest(*m, all_vertices(m->tissue), f, so, X[extend]);
    ASSERT_TRUE(st[extend].converged) << st[extend].message;
  }
  EXPECT_LT((X[1] - X[0]).cwiseAbs().maxCoeff(), m->quantum);
  EXPECT_LT(st[1].iterations, st[0].iterations);
}

TEST(Solver, TheHalfTangentCutsTheCrawlOnAStiffSkin) {
  // bench_builder's stiffness case on Song: zygomaticus major at its
  // calibrated +100 % tension on a 10 times stiffer epidermis (the same
  // dynamic set: that model is not calibrated), which buckles under it.
  // Where the full tangent is indefinite, the half tangent keeps half of
  // what the projected one drops, and Newton reaches the same equilibria in
  // fewer iterations (switched off, the last checks fail; 32 against 35 when
  // this was written, 34 against 35 with the chord steps of
  // SolverOptions::keep_tangent). "The same": each end solved on to a
  // hundredth of the tolerance lands on one point. The ends themselves are
  // not that close: a buckled skin's equilibrium is flat, the stopping
  // rule's Jacobi estimate misses its soft direction, and the right side's
  // solves stop about 57 quanta short of the equilibrium, 1.3 to 2.2 quanta
  // apart as rounding (the preconditioner's) changes. Without keep_tangent's
  // bound on the step before, the solve without the half tangent took 47
  // iterations and stopped 29 quanta from where the other did; with the
  // seventy-second session's preconditioner it no longer converges. On the
  // tissue before the layered skin and the floor (unlayered_tissue), where
  // this was measured: on the default one the half tangent takes 29
  // iterations against 28.
  AFM_REQUIRE_SHARED_DATA();
  Expected<LoadedFace> face = load_song();
  ASSERT_TRUE(face.is_ok()) << face.status().message();
  const std::vector<std::string> names = {"zygomaticus_major_left", "zygomaticus_major_right"};
  FaceModelOptions fo;
  fo.tissue = unlayered_tissue();
  fo.calibrate_only = names;
  fo.calibrate_jaw = false;
  Expected<FaceModel> m1 = build_face_model(face->scene, face->fdps, fo);
  fo.calibrate = false;
  fo.tissue.slab[0].modulus *= 10;
  Expected<FaceModel> m = build_face_model(face->scene, face->fdps, fo);
  ASSERT_TRUE(m1.is_ok() && m.is_ok()) << (m1 ? m : m1).status().message();
  int iterations[2] = {0, 0}, half_steps[2] = {0, 0};
  for (const std::string &name : names) {
    const Muscle &mu = m1->muscles[static_cast<size_t>(m1->find(name))];
    const Muscle &stiff = m->muscles[static_cast<size_t>(m->find(name))];
    ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
      return muscle_load(m->tissue, stiff, mu.tension_max, X, F, K);
    };
    Eigen::MatrixXd X[2];
    for (int half = 0; half < 2; ++half) {
      SolverOptions so = m->solver;
      so.half_tangent = half == 1;
      const SolveStats st = solve_from_rest(*m, mu.dynamic, f, so, X[half]);
      ASSERT_TRUE(st.converged) << name << ": " << st.message;
      iterations[half] += st.iterations;
      half_steps[half] += st.half_steps;
    }
    // Both ends, solved on to a hundredth of the tolerance: the same point.
    Eigen::MatrixXd T[2];
    for (int half = 0; half < 2; ++half) {
      SolverOptions so = m->solver;
      so.tolerance /= 100;
      T[half] = X[half];
      FactorCache cache;
      const SolveStats st = solve_equilibrium(m->tissue, mu.dynamic, f, m->tissue.X0, T[half], so, &cache);
      ASSERT_TRUE(st.converged) << name << ": " << st.message;
      std::printf("%s, half tangent %s: ended %.3g quanta from the equilibrium\n", name.c_str(), half ? "on" : "off",
                  (T[half] - X[half]).cwiseAbs().maxCoeff() / m->quantum);
    }
    EXPECT_LT((T[1] - T[0]).cwiseAbs().maxCoeff(), 0.01 * m->quantum) << name;
  }
  std::printf("Song, epidermis x10, zygomaticus major at +100 %%: %d Newton iterations with the half tangent (%d "
              "steps on it), %d without\n",
              iterations[1], half_steps[1], iterations[0]);
  EXPECT_EQ(half_steps[0], 0);
  EXPECT_GT(half_steps[1], 0);
  EXPECT_LT(iterations[1], iterations[0]);
}

TEST(Solver, InexactNewtonStepsReachTheSameEquilibrium) {
  // Each Newton step's linear solve stops once CG has cut its residual by
  // newton_forcing (0.1), not 1e-5: the stopping rule on the positions
  // decides the result, so both land within the tolerance of the one
  // equilibrium; the inexact steps need fewer CG iterations. Also under
  // load control (a calibration's bordered steps): the same tension.
  const FaceModel &m = head_1k().model;
  const Muscle &mu = m.muscles[static_cast<size_t>(m.find("zygomaticus_major_left"))];
  ASSERT_EQ(SolverOptions().newton_forcing, m.solver.newton_forcing);
  ForceField f = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
    return muscle_load(m.tissue, mu, 0.5, X, F, K);
  };
  LoadControl control[2];
  Eigen::MatrixXd X[2], Xc[2];
  SolveStats st[2], sc[2];
  for (int exact = 0; exact < 2; ++exact) {
    SolverOptions so = m.solver;
    if (exact) so.newton_forcing = 1e-5;
    FactorCache cache;
    X[exact] = m.tissue.X0;
    st[exact] = solve_equilibrium(m.tissue, all_vertices(m.tissue), f, m.tissue.X0, X[exact], so, &cache);
    ASSERT_TRUE(st[exact].converged) << st[exact].message;
    control[exact].unit_load = [&](const Eigen::MatrixXd &P, Eigen::MatrixXd *F, NodeBlocks *K) {
      return muscle_load(m.tissue, mu, 1.0, P, F, K);
    };
    control[exact].action = [&](const Eigen::MatrixXd &P, Eigen::MatrixXd *gradient) {
      return muscle_action(m.tissue, mu, P, gradient);
    };
    control[exact].value = 0.5 * muscle_action_target(mu, true);
    Xc[exact] = m.tissue.X0;
    sc[exact] = solve_equilibrium(m.tissue, all_vertices(m.tissue), ForceField(), m.tissue.X0, Xc[exact], so,
                                  &cache, &control[exact]);
    ASSERT_TRUE(sc[exact].converged) << sc[exact].message;
  }
  EXPECT_LT((X[0] - X[1]).cwiseAbs().maxCoeff(), 2 * m.solver.tolerance);
  EXPECT_LT(st[0].cg_iterations, st[1].cg_iterations);
  EXPECT_LT((Xc[0] - Xc[1]).cwiseAbs().maxCoeff(), 2 * m.solver.tolerance);
  EXPECT_NEAR(control[0].tension, control[1].tension, 1e-3 * control[1].tension);
  EXPECT_LT(sc[0].cg_iterations, sc[1].cg_iterations);
}

TEST(Solver, ASolveStartingWithTheLastSolvesFactorisationEndsWhereAFreshOneDoes) {
  // A second solve on a set (a target's search past its range) starts with
  // the factorisation the first ended on (FactorCache): the same equilibrium
  // as a solve with a cache of its own, within the stopping rule's slack,
  // and at least one factorisation fewer.
  const FaceModel &m = head_1k().model;
  const Muscle &mu = m.muscles[static_cast<size_t>(m.find("zygomaticus_major_left"))];
  auto load = [&](double t) {
    return ForceField([&m, &mu, t](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
      return muscle_load(m.tissue, mu, t, X, F, K);
    });
  };
  const std::vector<int> set = all_vertices(m.tissue);
  FactorCache shared, own;
  Eigen::MatrixXd first = m.tissue.X0, second = m.tissue.X0, fresh = m.tissue.X0;
  const SolveStats s1 = solve_equilibrium(m.tissue, set, load(0.3), m.tissue.X0, first, m.solver, &shared);
  ASSERT_TRUE(s1.converged) << s1.message;
  const SolveStats s2 = solve_equilibrium(m.tissue, set, load(0.5), m.tissue.X0, second, m.solver, &shared);
  const SolveStats sf = solve_equilibrium(m.tissue, set, load(0.5), m.tissue.X0, fresh, m.solver, &own);
  ASSERT_TRUE(s2.converged) << s2.message;
  ASSERT_TRUE(sf.converged) << sf.message;
  EXPECT_GT((fresh - m.tissue.X0).cwiseAbs().maxCoeff(), 20 * m.solver.tolerance);  // it moved
  EXPECT_LT((second - fresh).cwiseAbs().maxCoeff(), 2 * m.solver.tolerance);
  EXPECT_LT(s2.factorisations, sf.factorisations);
  std::printf("from the last solve's factorisation: %d factorisations, %d Newton and %d CG iterations; "
              "fresh: %d, %d and %d; apart by %.2f tolerances\n",
              s2.factorisations, s2.iterations, s2.cg_iterations, sf.factorisations, sf.iterations,
              sf.cg_iterations, (second - fresh).cwiseAbs().maxCoeff() / m.solver.tolerance);
}

TEST(Solver, ALoadThatMovesTheActionTheWrongWayFailsAtOnce) {
  // Load control from a tension already found (a solve beyond a FAP's
  // range starts so): the step clamp halves the tension each iteration
  // while the load pulls the action the other way; the guard ends the solve
  // once it has fallen to 1/50 (switched off, both checks below fail).
  const FaceModel &m = head_1k().model;
  const Muscle &mu = m.muscles[static_cast<size_t>(m.find("zygomaticus_major_left"))];
  LoadControl control;
  control.unit_load = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
    return muscle_load(m.tissue, mu, 1.0, X, F, K);
  };
  // The muscle's own action, negated: the load lowers it.
  control.action = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *gradient) {
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(X.rows(), 3);
    const double a = muscle_action(m.tissue, mu, X, &g);
    if (gradient) *gradient -= g;
    return -a;
  };
  control.value = 100 * m.solver.tolerance;
  control.tension = 0.05;
  Eigen::MatrixXd X = m.tissue.X0;
  FactorCache cache;
  SolveStats st = solve_equilibrium(m.tissue, all_vertices(m.tissue), ForceField(), m.tissue.X0, X, m.solver, &cache,
                                    &control);
  EXPECT_FALSE(st.converged);
  EXPECT_NE(st.message.find("wrong way"), std::string::npos) << st.message;
  EXPECT_LE(st.iterations, 10) << st.message;
  EXPECT_TRUE(X.allFinite());
}

TEST(BadInput, NotAFaceFlippedOrMissingFdps) {
  const Built &b = head_1k();
  // Flipped triangles: the skin faces inward.
  {
    Scene s = b.head.scene;
    Part &skin = s.parts[static_cast<size_t>(b.model.skin)];
    skin.F.col(1).swap(skin.F.col(2));
    Expected<FaceModel> m = build_face_model(s, b.head.fdps, FaceModelOptions{});
    ASSERT_FALSE(m.is_ok());
    EXPECT_NE(m.status().message().find("face inward"), std::string::npos) << m.status().message();
  }
  // Not a face: a flat sheet around the FDPs.
  {
    Scene s = b.head.scene;
    Part &skin = s.parts[static_cast<size_t>(b.model.skin)];
    skin.V.col(2).setZero();
    Expected<FaceModel> m = build_face_model(s, b.head.fdps, FaceModelOptions{});
    EXPECT_FALSE(m.is_ok());
  }
  // Missing FDPs without estimates: frontalis skipped naming 11.1, an
  // essential muscle fails the build.
  {
    const FdpSet f = without(b.head.fdps, "11.1");
    FaceModelOptions fo;
    fo.calibrate = false;
    fo.estimate_missing_fdps = false;
    Expected<FaceModel> m = build_face_model(b.head.scene, f, fo);
    ASSERT_TRUE(m.is_ok()) << m.status().message();
    EXPECT_EQ(m->muscles.size(), muscle_table().size() - 6) << "the six frontalis skipped";
    ASSERT_FALSE(m->warnings.empty());
    EXPECT_NE(m->warnings[0].find("11.1"), std::string::npos) << m->warnings[0];
    fo.estimate_missing_fdps = true;
    m = build_face_model(b.head.scene, f, fo);
    ASSERT_TRUE(m.is_ok());
    EXPECT_EQ(m->muscles.size(), muscle_table().size());
    ASSERT_FALSE(m->notes.empty());
    EXPECT_NE(m->notes[0].find("FDP 11.1 absent"), std::string::npos);
  }
  {
    const FdpSet f = without(b.head.fdps, "5.3");
    FaceModelOptions fo;
    fo.calibrate = false;
    fo.estimate_missing_fdps = false;
    Expected<FaceModel> m = build_face_model(b.head.scene, f, fo);
    ASSERT_FALSE(m.is_ok());
    EXPECT_NE(m.status().message().find("zygomaticus_major_left needs FDP 5.3"), std::string::npos)
        << m.status().message();
  }
}

TEST(FdpCompletion, EstimatesLandNearTheTrueFdps) {
  // The 2000-vertex head's own FDPs, deleted and estimated from the template.
  RefHeadOptions o;
  o.skin_vertices = 2000;
  Expected<RefHead> h = make_reference_head(o);
  ASSERT_TRUE(h.is_ok());
  const double es0 = 0.063;
  for (const char *id : {"3.7", "11.1", "2.13", "9.15"}) {
    const Eigen::Vector3d truth = h->fdps.find(*FdpId::parse(id))->pos;
    FdpSet f = without(h->fdps, id);
    std::vector<std::string> notes;
    Expected<std::vector<FdpId>> added = complete_fdps(h->scene, h->scene.find_kind(PartKind::Skin), f,
                                                        {*FdpId::parse(id)}, &notes);
    ASSERT_TRUE(added.is_ok()) << added.status().message();
    ASSERT_EQ(added->size(), 1u);
    EXPECT_LT((f.find(*FdpId::parse(id))->pos - truth).norm(), 0.15 * es0) << id;
  }
}

// The frozen template (fdp_completion.cpp) is the reference head's FDPs:
// every surface FDP once, mirror-symmetric, and near the generator's own at
// two resolutions. The generator's FDPs snap to its nearest vertex, so they
// move with the mesh: by up to 13 mm between 1000 and 10000 vertices. Bound:
// a quarter of ES0, which is 63 mm on the reference head (so 15.75 mm).
TEST(FdpCompletion, TheTemplateIsTheReferenceHeads) {
  const auto tpl = fdp_template();
  EXPECT_EQ(tpl.size(), 82u);
  int mirrored = 0;
  for (const auto &a : tpl)
    for (const auto &b : tpl) {
      if (a.first == b.first || std::abs(a.second.x()) < 1e-6 || a.second.x() < 0) continue;
      const Eigen::Vector3d m(-b.second.x(), b.second.y(), b.second.z());
      if ((a.second - m).norm() < 2e-6) ++mirrored;
    }
  EXPECT_GE(mirrored, 30) << "left/right pairs that mirror each other to the micrometre";
  for (int n : {1000, 10000}) {
    RefHeadOptions o;
    o.skin_vertices = n;
    Expected<RefHead> h = make_reference_head(o);
    ASSERT_TRUE(h.is_ok());
    double worst = 0;
    std::string at;
    for (const auto &t : tpl) {
      const FdpPoint *p = h->fdps.find(t.first);
      ASSERT_NE(p, nullptr) << t.first.str();
      const double d = (p->pos - t.second).norm();
      if (d > worst) worst = d, at = t.first.str();
    }
    std::printf("template against the %d-vertex head: worst %.2f mm (FDP %s)\n", n, worst * 1e3, at.c_str());
    EXPECT_LT(worst, 0.25 * 0.063) << n << " vertices, FDP " << at;
  }
}

// Song's own skin FDPs, each left out in turn and estimated: the local fit
// lands 3.5 model units (0.107 ES0) from the truth on average; a global
// affine fit, 4.6 (0.14 ES0). Bound: 0.12 ES0.
TEST(FdpCompletion, SongsFdpsLeftOutComeBackNearby) {
  AFM_REQUIRE_SHARED_DATA();
  Expected<LoadedFace> f = load_song();
  ASSERT_TRUE(f.is_ok()) << f.status().message();
  const int skin = f->scene.find_kind(PartKind::Skin);
  Expected<Fapu> fapu = compute_fapu(f->fdps);
  ASSERT_TRUE(fapu.is_ok()) << fapu.status().message();
  const double es0 = fapu->es0;
  std::vector<FdpId> ids;
  for (const FdpPoint &p : f->fdps.points)
    if (p.part == skin && p.vertex >= 0 && std::find(ids.begin(), ids.end(), p.id) == ids.end()) ids.push_back(p.id);
  ASSERT_GE(ids.size(), 30u);
  double sum = 0;
  for (const FdpId &id : ids) {
    FdpSet s = without(f->fdps, id.str());
    Expected<std::vector<FdpId>> added = complete_fdps(f->scene, skin, s, {id}, nullptr);
    ASSERT_TRUE(added.is_ok()) << id.str() << ": " << added.status().message();
    sum += (s.find(id)->pos - f->fdps.find(id)->pos).norm();
  }
  EXPECT_LT(sum / static_cast<double>(ids.size()), 0.12 * es0);
}

TEST(Builds, SongHeadPlacesItsMusclesAndJaw) {
  AFM_REQUIRE_SHARED_DATA();
  LoadOptions lo;
  lo.flip_v = true;
  Expected<LoadedFace> f = load_song(lo);
  ASSERT_TRUE(f.is_ok()) << f.status().message();
  Expected<FaceModel> m = song_model(*f, "zygomaticus_major_left");
  ASSERT_TRUE(m.is_ok()) << m.status().message();
  EXPECT_EQ(m->muscles.size(), muscle_table().size());
  EXPECT_GE(m->notes.size(), 10u) << "Song lacks the hairline, eye corners, jaw corners...";
  EXPECT_EQ(m->tissue.n, 2916);
  FactorCache cache;
  Activation a;
  a.muscles = {{m->find("zygomaticus_major_left"), 100.0}};
  Expected<Pose> p = solve_pose(*m, a, &cache);
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  EXPECT_GT(moved(*m, p->X, "8.3").y(), 0) << "the smile raises Song's corner";
  EXPECT_TRUE(p->X.allFinite());
  // Known defect (docs/notes.md, "Slabs turned through"): at +100 % this
  // and most muscles turn some slabs of tissue through themselves on every
  // head (make bench counts them); the tests here check modest tensions.
}

TEST(Builds, ReferenceHeadAtTwoResolutions) {
  for (int n : {1000, 3000}) {
    RefHeadOptions o;
    o.skin_vertices = n;
    Expected<RefHead> h = make_reference_head(o);
    ASSERT_TRUE(h.is_ok());
    FaceModelOptions fo;
    fo.calibrate_only = {"corrugator_left"};
    Expected<FaceModel> m = build_face_model(h->scene, h->fdps, fo);
    ASSERT_TRUE(m.is_ok()) << n << ": " << m.status().message();
    EXPECT_EQ(m->muscles.size(), muscle_table().size());
    EXPECT_FALSE(m->jaw.dynamic.empty());
    EXPECT_GT(m->muscles[static_cast<size_t>(m->find("corrugator_left"))].tension_max, 0);
  }
}
