// The parts that move by their own kinematic models, against MPEG-4 and
// their physics. The tongue (anatomy/tongue.h): each FAP moves its FDP by
// value x FAPU the way the table says, the root stays, and the tongue keeps
// its volume where it bends and stretches (a muscular hydrostat). The pupils
// (anatomy/pupil.h): the neutral pupil is a third of the iris (the FAPU
// notes), FAPs 29 and 30 grow its diameter by value x IRISD, the pupil's
// centre (the FDP) stays, the eye stays a sphere and its white does not move.
#include <afm/mpeg4.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include "anatomy/pupil.h"
#include "anatomy/skin_model.h"
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
  std::vector<EyeSphere> eyes;
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
    h->eyes = fit_eyeballs(h->head.scene);
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
  // Borders at different places along the tongue (6.4 a tenth of its
  // length further back) still both turn by the angle.
  const Expected<Tongue> skew = tongue_with([&h](FdpSet &f) {
    for (FdpPoint &p : f.points)
      if (p.id == FdpId{6, 4}) p.pos.z() -= 0.1 * h.tongue.length;
  });
  ASSERT_TRUE(skew.is_ok()) << skew.status().message();
  Eigen::MatrixXd B(2, 3);
  B << skew->left.transpose(), skew->right.transpose();
  const Eigen::MatrixXd DB = tongue_displacement(*skew, B, h.fapu, 47, value);
  for (int r = 0; r < 2; ++r) {
    const Eigen::Vector2d before(B(r, 0) - skew->tip.x(), B(r, 1) - skew->hinge_y);
    const Eigen::Vector2d after = before + DB.row(r).head<2>().transpose();
    const double turned = std::atan2(std::abs(before.x() * after.y() - before.y() * after.x()), before.dot(after));
    EXPECT_NEAR(turned, value * 1e-5, 1e-9) << (r ? "6.4" : "6.3") << ", the one further back";
  }
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

TEST(Pupil, EachFapGrowsItsPupilsDiameterByValueTimesIrisd) {
  const Head &e = head();
  ASSERT_EQ(e.eyes.size(), 2u);
  for (int fap : {29, 30}) {
    SCOPED_TRACE("FAP " + std::to_string(fap));
    const Expected<Pupil> p = find_pupil(e.head.scene, e.head.fdps, e.eyes, fap);
    ASSERT_TRUE(p.is_ok()) << p.status().message();
    const afm_fap_info *info = afm_fap(fap);
    const FdpPoint *f = e.head.fdps.find(FdpId{info->fdp_group, info->fdp_index});
    ASSERT_TRUE(f && f->part == p->part);
    const Eigen::MatrixXd &V = e.head.scene.parts[static_cast<size_t>(p->part)].V;
    // MPEG-4's neutral face: the pupil a third of the iris' diameter, IRISD0.
    const double rest = pupil_diameter(*p, V, V);
    EXPECT_NEAR(rest, e.fapu.irisd0 / 3, 0.05 * e.fapu.irisd0 / 3);
    for (double value : {-150.0, 100.0, 300.0}) {
      ASSERT_TRUE(pupil_value_fits(*p, e.fapu, value)) << value;
      const Eigen::MatrixXd D = pupil_displacement(*p, V, e.fapu, value);
      ASSERT_TRUE(D.allFinite());
      EXPECT_NEAR(pupil_diameter(*p, V, V + D) - rest, value * e.fapu.irisd0 / 1024, 1e-9 * e.fapu.irisd0) << value;
      EXPECT_EQ(D.row(f->vertex).norm(), 0) << "the pupil's centre, FDP " << info->fdp_group << "." << info->fdp_index;
      int moved = 0;
      for (Eigen::Index v = 0; v < V.rows(); ++v) {
        const Eigen::Vector3d x = V.row(v).transpose(), y = x + D.row(v).transpose();
        EXPECT_NEAR((y - p->centre).norm(), (x - p->centre).norm(), 1e-12) << "on its sphere";
        // The white of the eye (beyond 1.2 times the iris' edge) stays.
        const double polar = std::acos(std::clamp((x - p->centre).normalized().dot(p->axis), -1.0, 1.0));
        if (polar > 1.2 * p->iris) {
          EXPECT_EQ(D.row(v).norm(), 0) << v;
        }
        moved += D.row(v).norm() > 0;
      }
      EXPECT_GT(moved, 0);
    }
    // Past the iris, or closed: refused.
    EXPECT_FALSE(pupil_value_fits(*p, e.fapu, 1024));
    EXPECT_FALSE(pupil_value_fits(*p, e.fapu, -400));
  }
}

TEST(Pupil, AnEyeWithoutPupilGeometryIsNamed) {
  const Head &e = head();
  // A textured eye (Song's): no vertex colours.
  Scene bare = e.head.scene;
  for (Part &p : bare.parts)
    if (p.kind == PartKind::EyeLeft) p.C.resize(0, 3);
  const Expected<Pupil> t = find_pupil(bare, e.head.fdps, e.eyes, 29);
  ASSERT_FALSE(t.is_ok());
  EXPECT_NE(t.status().message().find("no vertex colours"), std::string::npos) << t.status().message();
  // A pale eye: no dark disc.
  Scene pale = e.head.scene;
  for (Part &p : pale.parts)
    if (p.kind == PartKind::EyeRight) p.C.setConstant(0.9);
  const Expected<Pupil> u = find_pupil(pale, e.head.fdps, e.eyes, 30);
  ASSERT_FALSE(u.is_ok());
  EXPECT_NE(u.status().message().find("not dark"), std::string::npos) << u.status().message();
  // No eyeball under the FDP.
  const Expected<Pupil> v = find_pupil(e.head.scene, e.head.fdps, {}, 29);
  ASSERT_FALSE(v.is_ok());
  EXPECT_NE(v.status().message().find("3.5"), std::string::npos) << v.status().message();
}
