// FAPU distances from FDP positions (builder/core/fapu.h, formats/fdp.md).
#include "core/fapu.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "../common/csv.h"
#include "../common/test_paths.h"
#include "io/fdp_io.h"
#include "io/vrml.h"
#include "test_fdp_helpers.h"

namespace {

using afmb::Fapu;
using afmb::FdpId;
using afmb::FdpPoint;
using afmb::FdpSet;

bool contains(const std::string &s, const std::string &part) { return s.find(part) != std::string::npos; }

void add(FdpSet &set, int g, int i, double x, double y, double z) {
  FdpPoint p;
  p.id = FdpId{g, i};
  p.pos = Eigen::Vector3d(x, y, z);
  p.line = static_cast<int>(set.points.size()) + 1;
  set.points.push_back(p);
}

void remove(FdpSet &set, int g, int i) {
  auto &v = set.points;
  v.erase(std::remove_if(v.begin(), v.end(), [&](const FdpPoint &p) { return p.id == FdpId{g, i}; }), v.end());
}

// A face in the MPEG-4 frame (+x the face's left, +y up, +z forward) whose
// units are easy to work out by hand.
FdpSet hand_face() {
  FdpSet s;
  s.source = "t.fdp";
  add(s, 3, 5, 16, 7, 39);     // pupils: ES0 = 32
  add(s, 3, 6, -16, 7, 39);
  add(s, 3, 1, 16, 9.5, 40);   // left lids: 5.5
  add(s, 3, 3, 16, 4, 40);
  add(s, 3, 2, -16, 9.7, 40);  // right lids: 5.7 -> IRISD0 5.6
  add(s, 3, 4, -16, 4, 40);
  add(s, 9, 15, 0, -18, 44);   // ENS0 = 7 + 18 = 25
  add(s, 2, 2, 0, -27, 44);    // MNS0 = -18 + 27 = 9
  add(s, 8, 3, 12, -26, 37);   // MW0 = 25
  add(s, 8, 4, -13, -26, 37);
  add(s, 9, 4, -5, -17.5, 43);  // nose bottom edges
  add(s, 9, 5, 5, -17.5, 43);
  add(s, 9, 3, 0, -16, 52);    // nose tip
  add(s, 8, 1, 0, -25, 46);    // upper lip top: 9.3 + (8.1 - 9.3) / 4 = -18.25
  return s;
}

TEST(Fapu, AxisDistancesOfTheStandardDefinitions) {
  std::string notes;
  auto f = afmb::compute_fapu(hand_face(), &notes);
  ASSERT_TRUE(f) << f.status().message();
  EXPECT_DOUBLE_EQ(f->es0, 32);
  EXPECT_DOUBLE_EQ(f->irisd0, 5.6);
  EXPECT_DOUBLE_EQ(f->ens0, 25);
  EXPECT_DOUBLE_EQ(f->mns0, 9);
  EXPECT_DOUBLE_EQ(f->mw0, 25);
  EXPECT_EQ(notes, "");
  // The first point of an FDP in file order counts.
  FdpSet twice = hand_face();
  add(twice, 3, 5, 100, 100, 100);
  EXPECT_DOUBLE_EQ(afmb::compute_fapu(twice)->es0, 32);
}

TEST(Fapu, NoseBaseFallbacks) {
  FdpSet s = hand_face();
  remove(s, 9, 15);
  std::string notes;
  auto f = afmb::compute_fapu(s, &notes);
  ASSERT_TRUE(f) << f.status().message();
  EXPECT_DOUBLE_EQ(f->ens0, 24.5);  // 9.4 / 9.5 height
  EXPECT_DOUBLE_EQ(f->mns0, 9.5);
  EXPECT_TRUE(contains(notes, "9.4 and 9.5")) << notes;

  remove(s, 9, 4);
  notes.clear();
  f = afmb::compute_fapu(s, &notes);
  ASSERT_TRUE(f) << f.status().message();
  EXPECT_DOUBLE_EQ(f->ens0, 25.25);  // 7 - (-16 + (-25 + 16) / 4)
  EXPECT_DOUBLE_EQ(f->mns0, 8.75);
  EXPECT_TRUE(contains(notes, "9.3 and 8.1")) << notes;
  EXPECT_DOUBLE_EQ(f->es0, 32);  // the others are untouched
  EXPECT_DOUBLE_EQ(f->mw0, 25);
}

TEST(Fapu, IrisFromOneEyeWhenTheOtherIsIncomplete) {
  FdpSet s = hand_face();
  remove(s, 3, 2);
  std::string notes;
  auto f = afmb::compute_fapu(s, &notes);
  ASSERT_TRUE(f) << f.status().message();
  EXPECT_DOUBLE_EQ(f->irisd0, 5.5);
  EXPECT_TRUE(contains(notes, "left eye only")) << notes;
  s = hand_face();
  remove(s, 3, 3);
  EXPECT_NEAR(afmb::compute_fapu(s)->irisd0, 5.7, 1e-12);
}

TEST(Fapu, MissingFdpsAreAllNamedWithTheirUnits) {
  FdpSet s = hand_face();
  const std::pair<int, int> gone[] = {{3, 6}, {9, 15}, {9, 4}, {9, 3}, {8, 4}, {3, 1}, {3, 4}};
  for (auto gi : gone) remove(s, gi.first, gi.second);
  auto f = afmb::compute_fapu(s);
  ASSERT_FALSE(f);
  const std::string &m = f.status().message();
  EXPECT_EQ(m.rfind("t.fdp: cannot compute FAPU: ", 0), 0u) << m;
  EXPECT_TRUE(contains(m, "ES0 needs FDP 3.6;")) << m;
  EXPECT_TRUE(contains(m, "IRISD0 needs FDP 3.1 and 3.3, or 3.2 and 3.4 (missing 3.1, 3.4)")) << m;
  EXPECT_TRUE(contains(m, "ENS0 needs FDP 3.6, 9.15 (or 9.4 and 9.5, or 9.3 and 8.1")) << m;
  EXPECT_TRUE(contains(m, "MNS0 needs FDP 9.15 (or")) << m;
  EXPECT_TRUE(contains(m, "MW0 needs FDP 8.4")) << m;
  EXPECT_FALSE(contains(m, "2.2")) << m;
}

TEST(Fapu, MirroredOrUnboundInputIsRejected) {
  FdpSet s = hand_face();
  for (FdpPoint &p : s.points) p.pos.x() = -p.pos.x();  // face's left at -x
  auto f = afmb::compute_fapu(s);
  ASSERT_FALSE(f);
  EXPECT_TRUE(contains(f.status().message(), "t.fdp: FAPU ES0 = 3.5.x - 3.6.x = -32 is not positive"))
      << f.status().message();

  s = hand_face();
  s.points[4].part_name = "head";  // 3.2 names a part but was never bound
  f = afmb::compute_fapu(s);
  ASSERT_FALSE(f);
  EXPECT_TRUE(contains(f.status().message(), "t.fdp:5: FDP 3.2: not bound")) << f.status().message();
}

// Candide-3 has its own 9.15 (and 9.4 / 9.5): the model tests the fallbacks
// against the point they stand in for. Vertices come from candide3.wfm.obj,
// FDP vertex numbers from the reference list; the pupils (several vertices)
// are taken as the mean of theirs.
TEST(Fapu, CandideNoseBaseFallbacksAgainstItsOwn915) {
  AFM_REQUIRE_SHARED_DATA();
  AFM_REQUIRE_SHARED_REFERENCE();
  auto V = fdptest::obj_vertices(afmtest::shared_data("faces/candide3/candide3.wfm.obj"));
  ASSERT_EQ(V.size(), 113u);
  afmtest::CsvTable t = afmtest::read_csv(afmtest::shared_reference("mpeg4-fdp-list.csv"));
  ASSERT_EQ(t.error, "");
  FdpSet s;
  s.source = "candide3";
  for (auto &row : t.rows) {
    const std::string &cv = row["candide3_vertex"];
    if (cv.empty() || cv == "n/a") continue;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    auto ids = afmtest::split(cv, '/');
    for (const std::string &v : ids) {
      size_t k = static_cast<size_t>(std::stoi(v));
      sum += Eigen::Vector3d(V[k][0], V[k][1], V[k][2]);
    }
    auto id = FdpId::parse(row["fdp"]);
    ASSERT_TRUE(id) << row["fdp"];
    Eigen::Vector3d p = sum / static_cast<double>(ids.size());
    add(s, id->group, id->index, p.x(), p.y(), p.z());
  }
  auto exact = afmb::compute_fapu(s);
  ASSERT_TRUE(exact) << exact.status().message();
  std::printf("Candide-3 FAPU from its own 9.15: ES0 %.4f IRISD0 %.4f ENS0 %.4f MNS0 %.4f MW0 %.4f\n",
              exact->es0, exact->irisd0, exact->ens0, exact->mns0, exact->mw0);

  remove(s, 9, 15);
  auto edges = afmb::compute_fapu(s);  // 9.4 / 9.5 are level with 9.15 on Candide-3
  ASSERT_TRUE(edges) << edges.status().message();
  EXPECT_NEAR(edges->ens0, exact->ens0, 1e-9);
  EXPECT_NEAR(edges->mns0, exact->mns0, 1e-9);

  remove(s, 9, 4);
  std::string notes;
  auto quarter = afmb::compute_fapu(s, &notes);
  ASSERT_TRUE(quarter) << quarter.status().message();
  EXPECT_TRUE(contains(notes, "9.3 and 8.1")) << notes;
  double ens_err = quarter->ens0 / exact->ens0 - 1, mns_err = quarter->mns0 / exact->mns0 - 1;
  std::printf("Candide-3 with 9.15 from 9.3 and 8.1: ENS0 %.4f (%+.1f%%) MNS0 %.4f (%+.1f%%)\n", quarter->ens0,
              100 * ens_err, quarter->mns0, 100 * mns_err);
  EXPECT_LT(std::fabs(ens_err), 0.05);  // formats/fdp.md: the fallback is within 5% on Candide-3
  EXPECT_LT(std::fabs(mns_err), 0.05);
  EXPECT_DOUBLE_EQ(quarter->es0, exact->es0);
}

// The Song head: FAPU computed from song.fdp's points on song.WRL against the
// FAPU XfaceEd stored in song.fdp. Tolerances (relative, per unit) and their
// reasons are in formats/fdp.md.
TEST(Fapu, SongComputedAgainstStored) {
  AFM_REQUIRE_SHARED_DATA();
  auto scene = afmb::read_vrml(afmtest::shared_data("faces/song/song.WRL"));
  ASSERT_TRUE(scene) << scene.status().message();
  auto fdps = afmb::read_fdp(afmtest::shared_data("faces/song/song.fdp"));
  ASSERT_TRUE(fdps) << fdps.status().message();
  afmb::Status bound = afmb::bind_fdps(*fdps, *scene);
  ASSERT_TRUE(bound) << bound.message();
  std::string notes;
  auto f = afmb::compute_fapu(*fdps, &notes);
  ASSERT_TRUE(f) << f.status().message();
  EXPECT_TRUE(contains(notes, "9.15 absent")) << notes;  // Song has no 9.15
  ASSERT_TRUE(fdps->stored_fapu);
  const Fapu &st = *fdps->stored_fapu;
  struct Row {
    const char *unit;
    double computed, stored, tolerance;
  };
  const Row rows[] = {
      {"ES0", f->es0, st.es0, 0.10},      {"IRISD0", f->irisd0, st.irisd0, 0.02},
      {"ENS0", f->ens0, st.ens0, 0.05},   {"MNS0", f->mns0, st.mns0, 0.40},
      {"MW0", f->mw0, st.mw0, 0.05},
  };
  for (const Row &r : rows) {
    double rel = r.computed / r.stored - 1;
    std::printf("Song %-6s computed %8.4f  stored %8.4f  %+6.1f%%  (tolerance %.0f%%)\n", r.unit, r.computed,
                r.stored, 100 * rel, 100 * r.tolerance);
    EXPECT_LT(std::fabs(rel), r.tolerance) << r.unit;
  }
}

}  // namespace
