// The tongue's motions (anatomy/tongue.h) against the MPEG-4 table and the
// tongue's physics: each FAP moves its FDP by value x FAPU the way the table
// says, the root stays, and the tongue keeps its volume where it bends and
// stretches (a muscular hydrostat).
#include <afm/mpeg4.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "anatomy/tongue.h"
#include "core/fapu.h"
#include "refhead/refhead.h"

using namespace afmb;

namespace {

struct Head {
  RefHead head;
  Fapu fapu;
  Tongue tongue;
  const Eigen::MatrixXd *V = nullptr;  // the tongue's rest vertices
  Eigen::MatrixXi F;
};

const Head &head() {
  static std::unique_ptr<Head> h;
  if (!h) {
    h = std::make_unique<Head>();
    RefHeadOptions o;
    o.skin_vertices = 1000;
    Expected<RefHead> r = make_reference_head(o);
    EXPECT_TRUE(r.is_ok()) << r.status().message();
    h->head = std::move(*r);
    Expected<Fapu> f = compute_fapu(h->head.fdps);
    EXPECT_TRUE(f.is_ok()) << f.status().message();
    h->fapu = *f;
    Expected<Tongue> t = find_tongue(h->head.scene, h->head.fdps);
    EXPECT_TRUE(t.is_ok()) << t.status().message();
    h->tongue = *t;
    const Part &p = h->head.scene.parts[static_cast<size_t>(t->part)];
    h->V = &p.V;
    h->F = p.F;
  }
  return *h;
}

// The enclosed volume of a closed triangle mesh (divergence theorem).
double volume(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F) {
  double v = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    v += a.dot(b.cross(c)) / 6;
  }
  return v;
}

// The FDP's rest position and its vertex on the tongue part.
const FdpPoint &fdp(int index) {
  const FdpPoint *p = head().head.fdps.find(FdpId{6, index}, head().tongue.part);
  EXPECT_NE(p, nullptr) << "6." << index;
  return *p;
}

// A reference-head copy with the tongue's FDPs edited by `edit`.
Expected<Tongue> tongue_with(const std::function<void(FdpSet &)> &edit) {
  FdpSet f = head().head.fdps;
  edit(f);
  return find_tongue(head().head.scene, f);
}

}  // namespace

TEST(Tongue, EachFapMovesItsFdpAsTheMpeg4TableSays) {
  const Head &h = head();
  // value x FAPU along the table's direction, from afm_fap and the FAPU
  // distances, not from the tongue model.
  for (int fap = 43; fap <= 46; ++fap)
    for (double value : {-300.0, 150.0, 512.0}) {
      const afm_fap_info *info = afm_fap(fap);
      const Eigen::Vector3d dir(info->direction[0], info->direction[1], info->direction[2]);
      const double x0 = info->unit == AFM_FAPU_MW ? h.fapu.mw0 : h.fapu.mns0;
      ASSERT_TRUE(info->unit == AFM_FAPU_MW || info->unit == AFM_FAPU_MNS) << fap;
      const Eigen::MatrixXd D = tongue_displacement(h.tongue, *h.V, h.fapu, fap, value);
      ASSERT_TRUE(D.allFinite());
      const Eigen::Vector3d moved = D.row(fdp(info->fdp_index).vertex).transpose();
      EXPECT_LT((moved - value * x0 / 1024 * dir).norm(), 1e-12 * x0) << fap << " at " << value;
      EXPECT_LT((tongue_fdp_motion(h.tongue, h.fapu, fap, value) - moved).norm(), 1e-12 * x0) << fap;
    }
}

TEST(Tongue, TheRollTurnsBothBordersUpByTheFapsAngle) {
  const Head &h = head();
  const double value = 40000;  // AU: 0.4 rad
  const Eigen::MatrixXd D = tongue_displacement(h.tongue, *h.V, h.fapu, 47, value);
  // The hinge: along z through 6.1's x, level with the borders.
  const double hx = fdp(1).pos.x(), hy = 0.5 * (fdp(3).pos.y() + fdp(4).pos.y());
  for (int border : {3, 4}) {
    const FdpPoint &p = fdp(border);
    const Eigen::Vector2d before(p.pos.x() - hx, p.pos.y() - hy);
    const Eigen::Vector3d q = p.pos + D.row(p.vertex).transpose();
    const Eigen::Vector2d after(q.x() - hx, q.y() - hy);
    const double turned = std::atan2(std::abs(before.x() * after.y() - before.y() * after.x()), before.dot(after));
    EXPECT_NEAR(turned, value * 1e-5, 1e-9) << "6." << border;
    EXPECT_GT(q.y(), p.pos.y()) << "6." << border << " goes up: concave upward";
    EXPECT_NEAR(after.norm(), before.norm(), 1e-12) << "6." << border << " turns about the hinge";
    EXPECT_EQ(D(p.vertex, 2), 0) << "the roll stays in the section";
  }
  // Mirror images of each other on this symmetric head (to a nanometre:
  // the generator's points are symmetric to rounding).
  EXPECT_NEAR(D(fdp(3).vertex, 1), D(fdp(4).vertex, 1), 1e-9);
  EXPECT_NEAR(D(fdp(3).vertex, 0), -D(fdp(4).vertex, 0), 1e-9);
  // The midline does not move.
  EXPECT_LT(D.row(fdp(1).vertex).norm(), 1e-15);
}

TEST(Tongue, TheRootStaysAndTheTongueKeepsItsVolume) {
  const Head &h = head();
  const double v0 = volume(*h.V, h.F);
  ASSERT_GT(v0, 0) << "a closed tongue, outward triangles";
  const double root = h.V->col(2).minCoeff();
  for (int fap = 43; fap <= 47; ++fap) {
    const double value = fap == 47 ? 52360 : fap == 44 || fap == 46 ? 512 : 200;
    for (double side : {1.0, -1.0}) {
      if (fap == 47 && side < 0) continue;  // unidirectional
      const Eigen::MatrixXd D = tongue_displacement(h.tongue, *h.V, h.fapu, fap, side * value);
      for (Eigen::Index v = 0; v < h.V->rows(); ++v)
        if ((*h.V)(v, 2) <= root + 1e-12) {
          EXPECT_LT(D.row(v).norm(), 1e-15) << fap << ": the root moved";
        }
      // Bending (43, 44, 46) is a shear along the tongue and the thrust
      // stretches it while its section shrinks: volume kept (stretched
      // alone, it would grow by the strain, 16 % here). The roll folds the
      // halves up about the hinge: within a few percent.
      const double dv = volume(*h.V + D, h.F) / v0 - 1;
      EXPECT_LT(std::abs(dv), fap == 47 ? 0.05 : 0.001) << fap << " at " << side * value;
      std::printf("FAP %d at %+g: volume %+.3f %%, largest motion %.2f mm\n", fap, side * value, 100 * dv,
                  1e3 * D.rowwise().norm().maxCoeff());
    }
  }
  // Only the thrust needs its own negative side.
  for (int fap = 43; fap <= 47; ++fap) EXPECT_EQ(tongue_negative_target(fap), fap == 45) << fap;
}

TEST(Tongue, BadTongueFdpsAreNamed) {
  auto message = [](const Expected<Tongue> &t) { return t.is_ok() ? std::string("ok") : t.status().message(); };
  // A missing FDP.
  const std::string missing = message(tongue_with([](FdpSet &f) {
    f.points.erase(std::remove_if(f.points.begin(), f.points.end(),
                                  [](const FdpPoint &p) { return p.id == FdpId{6, 2}; }),
                   f.points.end());
  }));
  EXPECT_NE(missing.find("6.2"), std::string::npos) << missing;
  // The borders swapped onto one side.
  const std::string swapped = message(tongue_with([](FdpSet &f) {
    for (FdpPoint &p : f.points)
      if (p.id == FdpId{6, 4}) p.pos.x() = -p.pos.x();
  }));
  EXPECT_NE(swapped.find("6.3 and 6.4"), std::string::npos) << swapped;
  // The tip behind the root.
  const std::string tip = message(tongue_with([](FdpSet &f) {
    for (FdpPoint &p : f.points)
      if (p.id == FdpId{6, 1}) p.pos.z() -= 1;
  }));
  EXPECT_NE(tip.find("6.1"), std::string::npos) << tip;
  // No tongue part.
  Scene none = head().head.scene;
  for (Part &p : none.parts)
    if (p.kind == PartKind::Tongue) p.kind = PartKind::Other;
  const Expected<Tongue> t = find_tongue(none, head().head.fdps);
  ASSERT_FALSE(t.is_ok());
  EXPECT_NE(t.status().message().find("no tongue part"), std::string::npos) << t.status().message();
}
