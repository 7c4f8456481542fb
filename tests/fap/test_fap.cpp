// FAP mapping and synthesis: the table against the MPEG-4 FAP table, and
// synthesized targets against the MPEG-4 rule (the FDP moves by
// reference x FAPU along the FAP's direction), checked from the targets
// themselves.
#include <gtest/gtest.h>

#include <afm/draco.h>
#include <afm/format.h>
#include <afm/mpeg4.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "afm/afm_export.h"
#include "anatomy/face_model.h"
#include "anatomy/muscle_table.h"
#include "anatomy/muscles.h"
#include "core/fapu.h"
#include "fap/fap_mapping.h"
#include "fap/fap_synthesis.h"
#include "refhead/refhead.h"
#include "../common/reference_model.h"

using namespace afmb;

namespace {

TEST(FapMapping, CoversEveryLowLevelFapOnceAndAgreesWithTheMpeg4Table) {
  const std::vector<FapMapping> &t = fap_mappings();
  ASSERT_EQ(t.size(), 66u);
  for (size_t i = 0; i < t.size(); ++i) {
    const FapMapping &m = t[i];
    EXPECT_EQ(m.fap, static_cast<int>(i) + 3);
    EXPECT_EQ(find_fap_mapping(m.fap), &m);
    const afm_fap_info *info = afm_fap(m.fap);
    ASSERT_NE(info, nullptr);
    // The MPEG-4 table: FAPs without an FDP are the eyeball and head
    // rotations and thrusts, which are rigid.
    EXPECT_EQ(m.driver == FapDriver::Rigid, info->fdp_group == 0) << m.fap;
    if (m.driver == FapDriver::None) {
      EXPECT_STRNE(m.note, "") << m.fap << ": say why";
    }
    if (m.driver == FapDriver::Muscles || m.driver == FapDriver::JawOpen || m.driver == FapDriver::JawThrust ||
        m.driver == FapDriver::JawShift) {
      EXPECT_GT(m.reference, 0) << m.fap;
      EXPECT_EQ(info->motion, AFM_MOTION_TRANSLATE) << m.fap;
    }
    if (m.driver == FapDriver::Muscles) {
      EXPECT_FALSE(m.positive.empty()) << m.fap;
    }
    if (!info->bidirectional) {
      EXPECT_TRUE(m.negative.empty()) << m.fap << " is unidirectional";
    }
    for (const auto *g : {&m.positive, &m.negative})
      for (const FapContraction &c : *g) {
        EXPECT_GE(find_muscle(c.muscle), 0) << m.fap << ": " << c.muscle;
        EXPECT_TRUE(c.percent >= -100 && c.percent <= 100 && c.percent != 0) << m.fap << ": " << c.percent;
      }
  }
  EXPECT_EQ(find_fap_mapping(2), nullptr);
  EXPECT_EQ(find_fap_mapping(69), nullptr);
  EXPECT_NE(fap_mapping_text().find("open_jaw"), std::string::npos);
}

using Built = afmtest::ReferenceModel;

// The 1,000-vertex reference head, calibrated for the muscles the tests use.
const Built &head_1k() {
  static std::unique_ptr<Built> b;
  if (!b) {
    FaceModelOptions fo;
    fo.calibrate_only = {"zygomaticus_major_left", "depressor_anguli_left", "frontalis_major_left"};
    b = afmtest::build_reference_model(1000, fo);
  }
  return *b;
}

const FapSynthesis &synthesis() {
  static std::unique_ptr<FapSynthesis> s;
  if (!s) {
    FapSynthesisOptions o;
    o.only = {3, 12, 33};
    Expected<FapSynthesis> r = synthesize_faps(head_1k().head.scene, head_1k().model, o);
    EXPECT_TRUE(r.is_ok()) << r.status().message();
    s = std::make_unique<FapSynthesis>(std::move(*r));
  }
  return *s;
}

// The skin displacement of FAP `fap`'s target on side `side`, or nullptr.
const MorphTarget *target(int fap, int side) {
  for (const MorphTarget &t : synthesis().targets)
    if (t.number == fap && (t.reference > 0) == (side > 0)) return &t;
  return nullptr;
}

TEST(FapSynthesis, EachTargetMovesItsFdpByReferenceTimesFapuAlongTheFapsDirection) {
  const FaceModel &m = head_1k().model;
  const FapSynthesis &s = synthesis();
  // 3 (positive only), 12 and 33 (both sides).
  ASSERT_EQ(s.outcomes.size(), 5u);
  for (const FapOutcome &o : s.outcomes) {
    SCOPED_TRACE("FAP " + std::to_string(o.fap) + " side " + std::to_string(o.side));
    ASSERT_TRUE(o.made) << o.message;
    const MorphTarget *t = target(o.fap, o.side);
    ASSERT_NE(t, nullptr);
    EXPECT_EQ(t->reference, o.reference);
    EXPECT_EQ(o.reference > 0, o.side > 0);
    const Eigen::MatrixXd &D = t->displacement[static_cast<size_t>(m.skin)];
    ASSERT_EQ(D.rows(), m.tissue.n);
    EXPECT_TRUE(D.allFinite());
    // From the MPEG-4 table and the FAPU, not from the synthesis' own report.
    const afm_fap_info *info = afm_fap(o.fap);
    const FdpPoint *fdp = m.fdps.find(FdpId{info->fdp_group, info->fdp_index}, m.skin);
    ASSERT_NE(fdp, nullptr);
    const Eigen::Vector3d dir(info->direction[0], info->direction[1], info->direction[2]);
    const double unit = fapu_distance(m.fapu, info->unit) / 1024.0;
    const double along = D.row(fdp->vertex).dot(dir.transpose());
    const double want = t->reference * unit;
    // Muscles: to the solver tolerance, or a FAP unit where the reference was
    // lowered (rounded down). The jaw: its chin is carried rigidly but the
    // tissue around it settles, so within 5 %.
    const double tol = o.fap == 3 ? 0.05 * std::abs(want) : (o.lowered_from ? unit : 4 * m.solver.tolerance);
    EXPECT_NEAR(along, want, tol);
    // Only the solved vertices move.
    int moved = 0;
    for (Eigen::Index v = 0; v < D.rows(); ++v) moved += D.row(v).norm() > 0;
    EXPECT_LE(moved, o.dynamic);
    EXPECT_GT(moved, 0);
  }
}

TEST(FapSynthesis, TheJawsRigidControlMovesTheChinAsTheTargetDoes) {
  const FaceModel &m = head_1k().model;
  const FapSynthesis &s = synthesis();
  ASSERT_FALSE(s.jaw.parts.empty()) << "the reference head has lower teeth and a tongue";
  ASSERT_EQ(s.jaw.controls.size(), 1u);
  const RigidPart::Control &c = s.jaw.controls[0];
  EXPECT_EQ(c.fap, 3);
  EXPECT_EQ(c.dof, AFM_DOF_ROTATE_X);
  const MorphTarget *t = target(3, +1);
  ASSERT_NE(t, nullptr);
  // At the reference value the rigid turns by gain x reference AU about x
  // through the pivot: the angle the pose gave the jaw's bone.
  const double angle = c.gain * t->reference * 1e-5;
  double scale = 0;
  for (const FapOutcome &o : s.outcomes)
    if (o.fap == 3) scale = o.scale;
  EXPECT_NEAR(angle, scale * m.jaw.max_open, 1e-12);
  // The skin over the jaw follows the bone through the tissue: on average
  // within 15 % of the rigid motion, or the lower teeth would part from the lip.
  const Eigen::MatrixXd &D = t->displacement[static_cast<size_t>(m.skin)];
  ASSERT_FALSE(m.jaw.vertices.empty());
  double off = 0, rigid = 0;
  for (int v : m.jaw.vertices) {
    const Eigen::Vector3d p = m.tissue.X0.row(v).transpose();
    const Eigen::Vector3d q = s.jaw.pivot + Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()) * (p - s.jaw.pivot);
    off += (D.row(v).transpose() - (q - p)).norm();
    rigid += (q - p).norm();
  }
  EXPECT_LT(off, 0.15 * rigid);
}

TEST(FapSynthesis, TheCornerGoesUpForPositiveValuesAndDownForNegativeOnes) {
  const FaceModel &m = head_1k().model;
  const FdpPoint *corner = m.fdps.find(FdpId{2, 4}, m.skin);  // FAP 12's FDP
  ASSERT_NE(corner, nullptr);
  const MorphTarget *up = target(12, +1), *down = target(12, -1);
  ASSERT_TRUE(up && down);
  EXPECT_GT(up->displacement[static_cast<size_t>(m.skin)](corner->vertex, 1), 0);
  EXPECT_LT(down->displacement[static_cast<size_t>(m.skin)](corner->vertex, 1), 0);
}

TEST(FapSynthesis, AMissingMuscleIsAReportNotAnError) {
  const Built &b = head_1k();
  // FAP 37 needs corrugator_left, which this model did not calibrate: the
  // pose fails and the outcome says so; nothing is thrown away silently.
  FapSynthesisOptions o;
  o.only = {37};
  o.negative_sides = false;
  Expected<FapSynthesis> r = synthesize_faps(b.head.scene, b.model, o);
  ASSERT_TRUE(r.is_ok()) << r.status().message();
  ASSERT_EQ(r->outcomes.size(), 1u);
  EXPECT_FALSE(r->outcomes[0].made);
  EXPECT_NE(r->outcomes[0].message.find("corrugator_left"), std::string::npos) << r->outcomes[0].message;
  EXPECT_TRUE(r->targets.empty());
}

// A pose steered past what the group can do within its calibrated range
// stops at scale 1: the same pose as the group at its table contractions.
TEST(FapSynthesis, ASteeredPoseStopsAtTheCalibratedRange) {
  const FaceModel &m = head_1k().model;
  const int i = m.find("zygomaticus_major_left");
  const Muscle &mu = m.muscles[static_cast<size_t>(i)];
  const std::vector<std::pair<int, double>> pattern = {{i, 100.0}};
  PoseAction action = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *g) { return muscle_action(m.tissue, mu, X, g); };
  FactorCache cache;
  double scale = 0;
  bool capped = false;
  const double far = 3 * muscle_action_target(mu, true);
  Expected<Pose> p = solve_pose_to(m, pattern, action, far, &cache, &scale, 1.0, &capped);
  ASSERT_TRUE(p.is_ok()) << p.status().message();
  EXPECT_TRUE(capped);
  EXPECT_EQ(scale, 1.0);
  Activation a;
  a.muscles = pattern;
  Expected<Pose> full = solve_pose(m, a, &cache);
  ASSERT_TRUE(full.is_ok());
  EXPECT_LT((pose_epidermis(m, *p) - pose_epidermis(m, *full)).cwiseAbs().maxCoeff(), 4 * m.solver.tolerance);
  EXPECT_NEAR(muscle_action(m.tissue, mu, p->X), muscle_action_target(mu, true), 4 * m.solver.tolerance);
  // Within reach, the cap does not bite.
  p = solve_pose_to(m, pattern, action, 0.5 * muscle_action_target(mu, true), &cache, &scale, 1.0, &capped);
  ASSERT_TRUE(p.is_ok());
  EXPECT_FALSE(capped);
  EXPECT_LT(scale, 1.0);
  EXPECT_NEAR(muscle_action(m.tissue, mu, p->X), 0.5 * muscle_action_target(mu, true), 4 * m.solver.tolerance);
}

TEST(FapSynthesis, TheSameOnAnyNumberOfThreads) {
  const Built &b = head_1k();
  FapSynthesisOptions o;
  o.only = {3, 12, 33};
  o.threads = 1;
  Expected<FapSynthesis> one = synthesize_faps(b.head.scene, b.model, o);
  o.threads = 3;
  Expected<FapSynthesis> three = synthesize_faps(b.head.scene, b.model, o);
  ASSERT_TRUE(one.is_ok() && three.is_ok());
  ASSERT_EQ(one->targets.size(), three->targets.size());
  for (size_t i = 0; i < one->targets.size(); ++i) {
    EXPECT_EQ(one->targets[i].number, three->targets[i].number);
    EXPECT_EQ(one->targets[i].reference, three->targets[i].reference);
    const size_t skin = static_cast<size_t>(b.model.skin);
    EXPECT_EQ(one->targets[i].displacement[skin], three->targets[i].displacement[skin]) << "bit for bit";
  }
  ASSERT_EQ(one->jaw.controls.size(), three->jaw.controls.size());
  EXPECT_EQ(one->jaw.controls[0].gain, three->jaw.controls[0].gain);
}

TEST(FapSynthesis, TheAfmHoldsTheTargetsAndTheJaw) {
  const Built &b = head_1k();
  const FapSynthesis &s = synthesis();
  ASSERT_FALSE(s.jaw.parts.empty());
  const AfmContent c = fap_afm_content(b.head.scene, b.head.fdps, b.model, s);
  Expected<std::vector<uint8_t>> bytes = encode_afm(c, AFM_PROFILE_DRACO);
  ASSERT_TRUE(bytes.is_ok()) << bytes.status().message();
  afm_read_options ro{};
  ro.draco = afm_draco_codec();
  afm_doc *doc = nullptr;
  ASSERT_EQ(afm_doc_read_alloc(bytes->data(), bytes->size(), &ro, nullptr, &doc), AFM_OK);
  std::unique_ptr<afm_doc, void (*)(afm_doc *)> hold(doc, [](afm_doc *d) { afm_free(nullptr, d); });
  ASSERT_EQ(doc->target_count, s.targets.size());
  for (uint32_t i = 0; i < doc->target_count; ++i) {
    bool found = false;
    for (const MorphTarget &t : s.targets)
      found |= t.number == doc->targets[i].number && t.reference == doc->targets[i].reference;
    EXPECT_TRUE(found) << "target " << int(doc->targets[i].number) << " ref " << doc->targets[i].reference;
  }
  bool jaw = false;
  for (uint32_t i = 0; i < doc->rigid_count; ++i)
    if (doc->rigids[i].kind == AFM_RIGID_JAW)
      jaw = doc->rigids[i].control_count == 1 && doc->rigids[i].controls[0].fap == 3;
  EXPECT_TRUE(jaw);
}

}  // namespace
