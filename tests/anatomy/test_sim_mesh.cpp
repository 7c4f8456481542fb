// The simulation mesh (anatomy/sim_mesh.h): a coarser copy of the skin that
// keeps every FDP, the openings and the surface, and carries its motion back
// to every skin vertex.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <queue>
#include <set>

#include "anatomy/fdp_completion.h"
#include "anatomy/sim_mesh.h"
#include "core/part_kind.h"
#include "io/load_face.h"
#include "refhead/refhead.h"
#include "../common/test_paths.h"

using namespace afmb;

namespace {

const RefHead &head_2k() {
  static std::unique_ptr<RefHead> h;
  if (!h) {
    RefHeadOptions o;
    o.skin_vertices = 2000;
    Expected<RefHead> r = make_reference_head(o);
    EXPECT_TRUE(r.is_ok()) << r.status().message();
    h = std::make_unique<RefHead>(std::move(*r));
  }
  return *h;
}

const SimMesh &sim_700() {
  static std::unique_ptr<SimMesh> s;
  if (!s) {
    Expected<SimMesh> r = make_sim_mesh(head_2k().scene, head_2k().fdps, SimMeshOptions{700});
    EXPECT_TRUE(r.is_ok()) << r.status().message();
    s = std::make_unique<SimMesh>(std::move(*r));
  }
  return *s;
}

// Boundary loops of a triangle mesh (edges used by one triangle), counted.
int boundary_loops(const Eigen::MatrixXi &F, int *nonmanifold_edges) {
  std::map<std::pair<int, int>, int> uses;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      uses[{std::min(a, b), std::max(a, b)}]++;
    }
  std::map<int, std::vector<int>> next;
  *nonmanifold_edges = 0;
  for (const auto &[e, n] : uses) {
    if (n > 2) ++*nonmanifold_edges;
    if (n == 1) next[e.first].push_back(e.second), next[e.second].push_back(e.first);
  }
  std::set<int> seen;
  int loops = 0;
  for (const auto &[v, _] : next) {
    if (seen.count(v)) continue;
    ++loops;
    std::vector<int> stack{v};
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      if (!seen.insert(u).second) continue;
      for (int w : next[u]) stack.push_back(w);
    }
  }
  return loops;
}

// Vertex normals of a mesh (area-weighted), #V x 3.
Eigen::MatrixXd vertex_normals(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F) {
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(V.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) N.row(F(f, k)) += n.transpose();
  }
  N.rowwise().normalize();
  return N;
}

TEST(SimMesh, KeepsEveryFdpTheOpeningsAndTheSurface) {
  const RefHead &h = head_2k();
  const SimMesh &s = sim_700();
  const Part &skin = h.scene.parts[static_cast<size_t>(s.skin)];
  ASSERT_TRUE(s.decimated);
  // The decimation reaches its target (nothing stops it on a clean head;
  // one fewer where a mirror pair of collapses ends it).
  EXPECT_NEAR(s.V.rows(), 700, 1);
  EXPECT_EQ(s.kept.size(), static_cast<size_t>(s.V.rows()));
  EXPECT_TRUE(std::is_sorted(s.kept.begin(), s.kept.end()));
  for (size_t c = 0; c < s.kept.size(); ++c)
    EXPECT_EQ(s.V.row(static_cast<Eigen::Index>(c)), skin.V.row(s.kept[c])) << "coarse vertex " << c;

  // Every skin FDP is a coarse vertex at the same place, both ways.
  const FdpSet coarse = sim_fdps(h.fdps, s);
  const FdpSet back = lift_fdps(coarse, s);
  int on_skin = 0;
  for (size_t i = 0; i < h.fdps.points.size(); ++i) {
    const FdpPoint &p = h.fdps.points[i];
    if (p.part != s.skin) continue;
    ++on_skin;
    const int c = coarse.points[i].vertex;
    ASSERT_GE(c, 0) << p.id.str();
    EXPECT_EQ(s.V.row(c).transpose(), p.pos) << p.id.str();
    EXPECT_EQ(back.points[i].vertex, p.vertex) << p.id.str();
  }
  EXPECT_GT(on_skin, 40);

  // A manifold with the skin's openings (mouth slit, two eyes, the neck).
  int fine_nm = 0, coarse_nm = 0;
  EXPECT_EQ(boundary_loops(s.F, &coarse_nm), boundary_loops(skin.F, &fine_nm));
  EXPECT_EQ(coarse_nm, 0);
  EXPECT_EQ(fine_nm, 0);

  // The surface is the skin's: no coarse triangle is turned over against
  // the skin's normals at its corners, none is a sliver, and every skin vertex lies
  // close to it (within a fifth of the coarse mean edge).
  const Eigen::MatrixXd N = vertex_normals(skin.V, skin.F);
  double edge = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Eigen::Vector3d a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k)
      EXPECT_GT(n.normalized().dot(N.row(s.kept[static_cast<size_t>(s.F(f, k))])), 0.0) << "coarse face " << f;
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    EXPECT_LT(longest * longest / n.norm(), 8.0) << "coarse face " << f << " is a sliver";
    edge += ((b - a).norm() + (c - b).norm() + (a - c).norm()) / 3;
  }
  edge /= static_cast<double>(s.F.rows());
  double farthest = 0;
  for (Eigen::Index v = 0; v < skin.V.rows(); ++v) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) p += s.binding.weight(v, k) * s.V.row(s.binding.corner(v, k)).transpose();
    farthest = std::max(farthest, (p - skin.V.row(v).transpose()).norm());
  }
  EXPECT_LT(farthest, 0.2 * edge);

  // Finer around the eyes: coarse vertices per unit of skin area within 0.2
  // eye separations of an eye FDP are over three times as dense as farther
  // than half an eye separation from every eye and lip FDP (4.0 times as
  // built). Measured per area, not as the share of skin vertices kept: the
  // generated skin is itself finer over the lids. Most of it is not the
  // finer sizing but the sockets' curvature and the eye FDPs kept (3.7
  // times with the sizing off).
  // The lips keep every skin vertex within 0.2 eye separations of a lip FDP.
  std::vector<Eigen::Vector3d> eyes, features, lips;
  for (const FdpPoint &p : h.fdps.points) {
    if (p.part == s.skin && p.id.group == 3) eyes.push_back(p.pos);
    const bool lip = p.id.group == 8 || (p.id.group == 2 && p.id.index >= 2 && p.id.index <= 9);
    if (p.part == s.skin && (p.id.group == 3 || lip)) features.push_back(p.pos);
    if (p.part == s.skin && lip) lips.push_back(p.pos);
  }
  const double es0 = (h.fdps.find(FdpId{3, 5})->pos - h.fdps.find(FdpId{3, 6})->pos).norm();
  auto nearest = [](const std::vector<Eigen::Vector3d> &set, const Eigen::Vector3d &x) {
    double d = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d &c : set) d = std::min(d, (x - c).norm());
    return d;
  };
  std::vector<uint8_t> kept(static_cast<size_t>(skin.V.rows()), 0);
  for (int v : s.kept) kept[static_cast<size_t>(v)] = 1;
  Eigen::VectorXd area = Eigen::VectorXd::Zero(skin.V.rows());
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f) {
    const Eigen::Vector3d a = skin.V.row(skin.F(f, 0)), b = skin.V.row(skin.F(f, 1)), c = skin.V.row(skin.F(f, 2));
    for (int k = 0; k < 3; ++k) area(skin.F(f, k)) += (b - a).cross(c - a).norm() / 6;
  }
  double in[2] = {0, 0}, all[2] = {0, 0}, ar[2] = {0, 0};
  int on_lips = 0;
  for (Eigen::Index v = 0; v < skin.V.rows(); ++v) {
    const Eigen::Vector3d x = skin.V.row(v).transpose();
    if (nearest(lips, x) < 0.2 * es0) {
      ++on_lips;
      EXPECT_TRUE(kept[static_cast<size_t>(v)]) << "lip vertex " << v;
    }
    const int side = nearest(eyes, x) < 0.2 * es0 ? 1 : nearest(features, x) > 0.5 * es0 ? 0 : -1;
    if (side < 0) continue;
    all[side] += 1;
    ar[side] += area(v);
    in[side] += kept[static_cast<size_t>(v)];
  }
  EXPECT_GT(on_lips, 20);
  ASSERT_GT(all[1], 10);
  const double denser = (in[1] / ar[1]) / (in[0] / ar[0]);
  std::printf("2k head at 700: %.0f of %.0f skin vertices kept near the eyes, %.0f of %.0f far; coarse vertices per "
              "area %.2f times as dense near\n",
              in[1], all[1], in[0], all[0], denser);
  EXPECT_GT(denser, 3.0);
}

TEST(SimMesh, CarriesAnAffineFieldWithinItsDistanceToTheCoarseSurface) {
  const RefHead &h = head_2k();
  const SimMesh &s = sim_700();
  const Part &skin = h.scene.parts[static_cast<size_t>(s.skin)];
  Eigen::Matrix3d A;
  A << 0.3, -0.1, 0.05, 0.2, 0.1, -0.4, 0.0, 0.25, 0.15;
  const Eigen::RowVector3d b(0.001, -0.002, 0.003);
  const Eigen::MatrixXd Dc = (s.V * A.transpose()).rowwise() + b;
  const Eigen::MatrixXd D = lift_displacement(s, Dc);
  ASSERT_EQ(D.rows(), skin.V.rows());
  const double norm_a = A.jacobiSvd().singularValues()(0);
  std::vector<int> coarse_of(static_cast<size_t>(skin.V.rows()), -1);
  for (size_t c = 0; c < s.kept.size(); ++c) coarse_of[static_cast<size_t>(s.kept[c])] = static_cast<int>(c);
  for (Eigen::Index v = 0; v < skin.V.rows(); ++v) {
    const Eigen::RowVector3d x = skin.V.row(v);
    const Eigen::RowVector3d exact = x * A.transpose() + b;
    if (const int c = coarse_of[static_cast<size_t>(v)]; c >= 0) {
      EXPECT_EQ(D.row(v), Dc.row(c)) << "kept vertex " << v;
      continue;
    }
    // Blending an affine field is exact at the bound point p, so the error
    // at x is A (x - p): at most |A| |x - p|.
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k) p += s.binding.weight(v, k) * s.V.row(s.binding.corner(v, k));
    EXPECT_LE((D.row(v) - exact).norm(), norm_a * (x - p).norm() + 1e-12) << "vertex " << v;
  }
}

// A skin vertex binds to corners near it along the skin, never across the
// mouth slit or an eye opening: the path along the skin's edges from the
// vertex to each corner of its triangle is at most twice that triangle's
// longest edge. (Across the mouth slit, the path goes round a mouth corner.)
TEST(SimMesh, BindsEachSkinVertexToCornersNearItAlongTheSkin) {
  const RefHead &h = head_2k();
  const SimMesh &s = sim_700();
  const Part &skin = h.scene.parts[static_cast<size_t>(s.skin)];
  const int n = static_cast<int>(skin.V.rows());
  std::vector<std::vector<int>> adj(static_cast<size_t>(n));
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      adj[static_cast<size_t>(skin.F(f, k))].push_back(skin.F(f, (k + 1) % 3));
      adj[static_cast<size_t>(skin.F(f, (k + 1) % 3))].push_back(skin.F(f, k));
    }
  double lip_limit = 0;  // the limit at FDP 2.2's vertex
  const int lip = h.fdps.find(FdpId{2, 2})->vertex;
  for (int v = 0; v < n; ++v) {
    std::set<int> targets;
    double longest = 0;
    for (int k = 0; k < 3; ++k) {
      if (s.binding.weight(v, k) > 0.01) targets.insert(s.kept[static_cast<size_t>(s.binding.corner(v, k))]);
      longest = std::max(longest, (s.V.row(s.binding.corner(v, k)) - s.V.row(s.binding.corner(v, (k + 1) % 3))).norm());
    }
    const double limit = 2 * longest;
    if (v == lip) lip_limit = limit;
    // Dijkstra from v, stopped beyond the limit.
    std::map<int, double> dist{{v, 0.0}};
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
    q.emplace(0.0, v);
    while (!q.empty()) {
      const auto [d, u] = q.top();
      q.pop();
      if (d > dist[u] || d > limit) continue;
      targets.erase(u);
      if (targets.empty()) break;
      for (int w : adj[static_cast<size_t>(u)]) {
        const double dw = d + (skin.V.row(w) - skin.V.row(u)).norm();
        auto it = dist.find(w);
        if (it == dist.end() || dw < it->second) dist[w] = dw, q.emplace(dw, w);
      }
    }
    EXPECT_TRUE(targets.empty()) << "skin vertex " << v << " at " << skin.V.row(v)
                                 << " binds to a corner farther than " << limit << " along the skin";
  }
  // The mouth slit is in the way of a straight binding: the lips' FDPs 2.2
  // and 2.3 (inner upper and lower lip midpoints) are near in space and far
  // along the skin.
  const Eigen::Vector3d up = h.fdps.find(FdpId{2, 2})->pos, low = h.fdps.find(FdpId{2, 3})->pos;
  EXPECT_LT((up - low).norm(), lip_limit);
}

TEST(SimMesh, NoDecimationBelowTheSkinsOwnSize) {
  const RefHead &h = head_2k();
  Expected<SimMesh> s = make_sim_mesh(h.scene, h.fdps, SimMeshOptions{0});
  ASSERT_TRUE(s.is_ok());
  EXPECT_FALSE(s->decimated);
  const Part &skin = h.scene.parts[static_cast<size_t>(s->skin)];
  EXPECT_EQ(s->V, skin.V);
  const Eigen::MatrixXd D = Eigen::MatrixXd::Random(skin.V.rows(), 3);
  EXPECT_EQ(lift_displacement(*s, D), D);
  Scene none;
  none.source = "empty.wrl";
  Expected<SimMesh> bad = make_sim_mesh(none, h.fdps, SimMeshOptions{500});
  ASSERT_FALSE(bad.is_ok());
  EXPECT_NE(bad.status().message().find("empty.wrl"), std::string::npos);
}

}  // namespace

namespace {

// Song as afm-build simulates it (missing FDPs estimated and kept, 1,000
// vertices), not calibrated; `model` is null when it did not build.
struct SongSim {
  LoadedFace face;
  std::unique_ptr<SimFaceModel> model;
};
const SongSim &song_sim() {
  static const SongSim built = [] {
    SongSim out;
    Expected<LoadedFace> f = load_face(afmtest::shared_data("faces/song/song.WRL"),
                                       afmtest::shared_data("faces/song/song.fdp"), LoadOptions{}, nullptr);
    EXPECT_TRUE(f.is_ok()) << f.status().message();
    if (!f) return out;
    out.face = std::move(*f);
    FaceModelOptions fo;
    fo.calibrate = false;
    Expected<SimFaceModel> m = build_sim_face_model(out.face.scene, out.face.fdps, SimMeshOptions{1000}, fo);
    EXPECT_TRUE(m.is_ok()) << m.status().message();
    if (m) out.model = std::make_unique<SimFaceModel>(std::move(*m));
    return out;
  }();
  return built;
}

}  // namespace

// Song lacks 18 of the FDPs its muscles use. They are estimated on the skin
// itself, as build_face_model estimates them, and the decimation keeps them:
// snapped to the coarse mesh instead, estimates land on other vertices
// (in one trial, 9.6 and 9.7 on the same one).
TEST(SimMesh, MissingFdpsAreEstimatedOnTheSkinAndKept) {
  AFM_REQUIRE_SHARED_DATA();
  const SongSim &song = song_sim();
  ASSERT_TRUE(song.model) << "Song's model did not build";
  const LoadedFace *f = &song.face;
  const int skin = f->scene.find_kind(PartKind::Skin);
  FdpSet on_skin = f->fdps;
  std::vector<std::string> notes;
  Expected<std::vector<FdpId>> added = complete_fdps(f->scene, skin, on_skin, anatomy_fdps(), &notes);
  ASSERT_TRUE(added.is_ok()) << added.status().message();
  ASSERT_GE(added->size(), 10u);

  const SimFaceModel *s = song.model.get();
  ASSERT_TRUE(s->sim.decimated);
  EXPECT_EQ(s->model.notes, notes) << "the same estimates, the same notes";
  const FdpSet lifted = lift_fdps(s->model.fdps, s->sim);
  std::set<int> vertices;
  for (const FdpId &id : *added) {
    const FdpPoint *want = on_skin.find(id, skin), *got = lifted.find(id, skin);
    ASSERT_TRUE(want && got) << id.str();
    EXPECT_EQ(got->vertex, want->vertex) << id.str();
    EXPECT_TRUE(vertices.insert(got->vertex).second) << id.str() << " shares a vertex";
  }
}

namespace {

// Of the coarse vertices, the share whose mirror image in the plane x = mid
// (the skin vertex there, within a thousandth of the eye separation) is
// also kept; and the kept vertices within `radius` of each pupil.
struct Symmetry {
  double mirrored = 0;
  int near_left = 0, near_right = 0;
};
Symmetry symmetry(const Part &skin, const SimMesh &sim, const Eigen::Vector3d &pupil_l,
                  const Eigen::Vector3d &pupil_r, double radius) {
  const double mid = 0.5 * (pupil_l.x() + pupil_r.x()), tol = 1e-3 * (pupil_l - pupil_r).norm();
  std::set<int> kept(sim.kept.begin(), sim.kept.end());
  Symmetry out;
  int mirrored = 0;
  for (int v : sim.kept) {
    Eigen::Vector3d image = skin.V.row(v).transpose();
    image.x() = 2 * mid - image.x();
    for (int u : kept)
      if ((skin.V.row(u).transpose() - image).norm() < tol) {
        ++mirrored;
        break;
      }
    out.near_left += (skin.V.row(v).transpose() - pupil_l).norm() < radius;
    out.near_right += (skin.V.row(v).transpose() - pupil_r).norm() < radius;
  }
  out.mirrored = static_cast<double>(mirrored) / static_cast<double>(sim.kept.size());
  return out;
}

Eigen::Vector3d pupil(const FdpSet &fdps, int index) { return fdps.find(FdpId{3, index})->pos; }

}  // namespace

// A mirror-symmetric skin is decimated into a mirror-symmetric simulation
// mesh, collapses made in mirror pairs (sim_mesh.cpp): every coarse vertex
// has its image among them, and the coarse triangles whose image is not a
// coarse triangle are at most the skin's own such. OpenMesh's decimater alone, even with mirror-invariant ties,
// left 8 of the 2k head's 700 coarse vertices without an image (45 and 49
// within 0.6 eye separations of the pupils), and the 10k head's FAP 42 41 %
// off its direction where 41 was 15 % (docs/notes.md).
TEST(SimMesh, AMirrorSymmetricSkinKeepsMirrorImages) {
  const RefHead &h = head_2k();
  const Part &skin = h.scene.parts[static_cast<size_t>(h.scene.find_kind(PartKind::Skin))];
  const SimMesh &sim = sim_700();
  const Eigen::Vector3d l = pupil(h.fdps, 5), r = pupil(h.fdps, 6);
  const Symmetry s = symmetry(skin, sim, l, r, 0.6 * (l - r).norm());
  std::printf("2k head at 700: %.3f mirrored, %d and %d near the pupils\n", s.mirrored, s.near_left, s.near_right);
  EXPECT_TRUE(sim.mirrored);
  EXPECT_EQ(sim.unpaired, 0);
  EXPECT_EQ(s.mirrored, 1.0);
  EXPECT_EQ(s.near_left, s.near_right);
  // The coarse vertex at each coarse vertex's image, by position.
  const double mid = 0.5 * (l.x() + r.x()), tol = 1e-3 * (l - r).norm();
  std::vector<int> image(static_cast<size_t>(sim.V.rows()), -1);
  for (Eigen::Index c = 0; c < sim.V.rows(); ++c) {
    Eigen::Vector3d p = sim.V.row(c).transpose();
    p.x() = 2 * mid - p.x();
    for (Eigen::Index d = 0; d < sim.V.rows(); ++d)
      if ((sim.V.row(d).transpose() - p).norm() < tol) image[static_cast<size_t>(c)] = static_cast<int>(d);
  }
  std::set<std::array<int, 3>> triangles;
  auto sorted = [](int a, int b, int c) {
    std::array<int, 3> t{a, b, c};
    std::sort(t.begin(), t.end());
    return t;
  };
  for (Eigen::Index f = 0; f < sim.F.rows(); ++f) triangles.insert(sorted(sim.F(f, 0), sim.F(f, 1), sim.F(f, 2)));
  int without = 0;
  for (Eigen::Index f = 0; f < sim.F.rows(); ++f) {
    const int a = image[static_cast<size_t>(sim.F(f, 0))], b = image[static_cast<size_t>(sim.F(f, 1))],
              c = image[static_cast<size_t>(sim.F(f, 2))];
    without += a < 0 || b < 0 || c < 0 || !triangles.count(sorted(a, b, c));
  }
  // The skin's own: a few of its triangles' images are not triangles (a
  // quad split the same way on both sides).
  std::vector<int> skin_image(static_cast<size_t>(skin.V.rows()), -1);
  std::set<std::array<int, 3>> skin_triangles;
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f) skin_triangles.insert(sorted(skin.F(f, 0), skin.F(f, 1), skin.F(f, 2)));
  for (Eigen::Index v = 0; v < skin.V.rows(); ++v) {
    Eigen::Vector3d p = skin.V.row(v).transpose();
    p.x() = 2 * mid - p.x();
    for (Eigen::Index u = 0; u < skin.V.rows(); ++u)
      if ((skin.V.row(u).transpose() - p).norm() < tol) skin_image[static_cast<size_t>(v)] = static_cast<int>(u);
  }
  int skin_without = 0;
  for (Eigen::Index f = 0; f < skin.F.rows(); ++f) {
    const int a = skin_image[static_cast<size_t>(skin.F(f, 0))], b = skin_image[static_cast<size_t>(skin.F(f, 1))],
              c = skin_image[static_cast<size_t>(skin.F(f, 2))];
    skin_without += a < 0 || b < 0 || c < 0 || !skin_triangles.count(sorted(a, b, c));
  }
  std::printf("triangles whose image is not one: %d of the skin's %lld, %d of the coarse mesh's %lld\n", skin_without,
              static_cast<long long>(skin.F.rows()), without, static_cast<long long>(sim.F.rows()));
  EXPECT_LE(without, skin_without) << "coarse triangles whose image is not one, beyond the skin's own";
}

// Song's skin is mirror-symmetric (nine in ten vertices have an image within
// a thousandth of the eye separation); its FDPs are a few hundredths off.
// Without the mirror rule its left eye kept 55 coarse vertices within 20
// units of the pupil and the right one 63, and its left eye sphincter
// calibrated to an eighth of its range, tearing the lid's outer corner.
TEST(SimMesh, SongsEyesAreDecimatedAlike) {
  AFM_REQUIRE_SHARED_DATA();
  const SongSim &song = song_sim();
  ASSERT_TRUE(song.model) << "Song's model did not build";
  const SimMesh &sim = song.model->sim;
  const FdpSet &fdps = song.face.fdps;
  const Part &skin = song.face.scene.parts[static_cast<size_t>(sim.skin)];
  const Symmetry s = symmetry(skin, sim, pupil(fdps, 5), pupil(fdps, 6), 20);
  std::printf("Song at 1000: %.3f mirrored, %d and %d near the pupils, %d collapses unpaired\n", s.mirrored,
              s.near_left, s.near_right, sim.unpaired);
  // 0.936 before the collapses were made in mirror pairs; Song's skin has
  // vertices without an image (its FDPs are a few hundredths off symmetric).
  EXPECT_TRUE(sim.mirrored);
  EXPECT_GE(s.mirrored, 0.98);
  EXPECT_LE(std::abs(s.near_left - s.near_right), 2);
}

// Song's mouth corners, where its lips curl in and meet, hold clusters of
// triangles a thousandth of its mean triangle in area and less. Kept whole
// with the lips, they turned over under risorius' first pull, and the
// corners stretched (FAPs 6, 7, 53, 54) stopped at 71 % of their reference.
// The skin's shortest edges are collapsed first now (sim_mesh.h): no
// triangle of the simulation mesh is under a thousandth of its mean (before,
// 18, the smallest a ten-thousandth of it).
TEST(SimMesh, SongsMouthCornersKeepNoSliver) {
  AFM_REQUIRE_SHARED_DATA();
  const SongSim &song = song_sim();
  ASSERT_TRUE(song.model) << "Song's model did not build";
  const SimMesh &sim = song.model->sim;
  std::vector<double> area(static_cast<size_t>(sim.F.rows()));
  double mean = 0;
  for (Eigen::Index f = 0; f < sim.F.rows(); ++f) {
    const Eigen::Vector3d a = sim.V.row(sim.F(f, 0)), b = sim.V.row(sim.F(f, 1)), c = sim.V.row(sim.F(f, 2));
    area[static_cast<size_t>(f)] = 0.5 * (b - a).cross(c - a).norm();
    mean += area[static_cast<size_t>(f)];
  }
  mean /= static_cast<double>(std::max<Eigen::Index>(1, sim.F.rows()));
  const long slivers = std::count_if(area.begin(), area.end(), [mean](double x) { return x < 1e-3 * mean; });
  std::printf("Song at 1000: %d of the shortest edges collapsed first; the smallest triangle %.4f of the mean, "
              "%ld under a thousandth\n",
              sim.short_edges, *std::min_element(area.begin(), area.end()) / mean, slivers);
  EXPECT_GT(sim.short_edges, 0);
  EXPECT_EQ(slivers, 0);
}

// The simulation mesh keeps the skin vertices whose nodes the muscles' key
// points map to on the skin (muscle_key_vertices), so they map to the same
// ones. On Song's mesh without them, depressor anguli's attachment, 5.6
// units under the skin, went to nodes 5 units apart from side to side
// (fibres of 15.4 and 8.9 units: sadness pulled the left corner far more
// than the right), and frontalis major left shared frontalis outer's. The
// key points of each left/right pair are mirror images, so the pairs now
// attach alike (risorius too, since it starts from the mouth's corners
// rather than Song's 5.1 and 5.2, which are not mirror images).
TEST(SimMesh, SongsMusclesAttachAsOnTheSkinAndAlikeOnBothSides) {
  AFM_REQUIRE_SHARED_DATA();
  const SongSim &song = song_sim();
  ASSERT_TRUE(song.model) << "Song's model did not build";
  const SimMesh &sim = song.model->sim;
  const FaceModel &m = song.model->model;
  FdpSet complete = song.face.fdps;  // with the estimates, as build_sim_face_model makes them
  std::vector<std::string> notes;
  ASSERT_TRUE(complete_fdps(song.face.scene, sim.skin, complete, anatomy_fdps(), &notes).is_ok());
  Expected<std::vector<int>> keys = muscle_key_vertices(song.face.scene, complete, FaceModelOptions{}.tissue);
  ASSERT_TRUE(keys.is_ok()) << keys.status().message();
  int pairs = 0;
  for (const Muscle &l : m.muscles) {
    if (l.kind != MuscleKind::Linear) continue;
    for (int node : {l.node_a, l.node_b}) {
      const int kept = sim.kept[static_cast<size_t>(m.tissue.vertex_of(node))];
      EXPECT_NE(std::find(keys->begin(), keys->end(), kept), keys->end()) << l.name << ": not the skin's key vertex";
    }
    const size_t side = l.name.rfind("_left");
    if (side == std::string::npos) continue;
    const int ri = m.find(l.name.substr(0, side) + "_right");
    ASSERT_GE(ri, 0) << l.name;
    const Muscle &r = m.muscles[static_cast<size_t>(ri)];
    // The cheek puffs push from half the mouth's width inside their own
    // cheek's FDP (5.1, 5.2), which on Song are not mirror images (x 17.0
    // and -19.7, depth 37.1 and 35.1): their attachments follow, only their
    // fibres are alike.
    if (l.name.rfind("cheek_puff_", 0) != 0) {
      Eigen::Vector3d image = m.tissue.X0.row(l.node_a).transpose();
      image.x() = -image.x();
      EXPECT_LT((image - m.tissue.X0.row(r.node_a).transpose()).norm(), 0.05) << l.name << ": attachments not alike";
    }
    EXPECT_NEAR(l.length, r.length, 0.01 * l.length) << l.name;
    ++pairs;
  }
  // The paper's 11 linear pairs, the nostril dilators, the cheek puffs, the
  // depressores supercilii and labii, the nose's benders.
  EXPECT_EQ(pairs, 16);
}
