// check_skin on real skins and on small broken ones.
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../common/test_paths.h"
#include "core/repair.h"
#include "core/validate.h"
#include "io/mesh_io.h"
#include "io/vrml.h"

namespace {

using afmb::Part;
using afmb::Scene;

// An nx x ny grid of unit squares in z = 0, two triangles each,
// counter-clockwise seen from +z. Vertex (i, j) is i + (nx + 1) j; square
// (i, j) holds triangles 2 (i + nx j) and 2 (i + nx j) + 1.
Scene grid(int nx = 3, int ny = 3) {
  Scene s;
  s.source = "grid.obj";
  Part p;
  p.name = "skin";
  const int w = nx + 1;
  p.V.resize(w * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) p.V.row(i + w * j) << i, j, 0;
  p.F.resize(2 * nx * ny, 3);
  int t = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = i + w * j, b = a + 1, c = a + w + 1, d = a + w;
      p.F.row(t++) << a, b, c;
      p.F.row(t++) << a, c, d;
    }
  s.parts.push_back(p);
  return s;
}

void add_triangle(Part &p, int a, int b, int c) {
  p.F.conservativeResize(p.F.rows() + 1, 3);
  p.F.row(p.F.rows() - 1) << a, b, c;
}

// A closed tetrahedron at `o`, outward-facing, appended to p (4 vertices).
void add_tetrahedron(Part &p, const Eigen::Vector3d &o) {
  const int b = static_cast<int>(p.V.rows());
  p.V.conservativeResize(b + 4, 3);
  p.V.row(b) = o.transpose();
  p.V.row(b + 1) = (o + Eigen::Vector3d(1, 0, 0)).transpose();
  p.V.row(b + 2) = (o + Eigen::Vector3d(0, 1, 0)).transpose();
  p.V.row(b + 3) = (o + Eigen::Vector3d(0, 0, 1)).transpose();
  add_triangle(p, b, b + 2, b + 1);
  add_triangle(p, b, b + 1, b + 3);
  add_triangle(p, b, b + 3, b + 2);
  add_triangle(p, b + 1, b + 2, b + 3);
}

afmb::FdpPoint on(const char *id, const std::string &part, int part_index, int vertex) {
  afmb::FdpPoint q;
  q.id = *afmb::FdpId::parse(id);
  q.part_name = part;
  q.part = part_index;
  q.vertex = vertex;
  return q;
}

// A mesh exported as one object: a face (a 3 x 3 grid cut along x = 1 into
// two pieces that an exporter split, the cut's vertices doubled), an eye and
// teeth inside (tetrahedra; the teeth touch the eye at one corner) and a
// loose piece no FDP names.
TEST(SplitSkinPieces, GivesEachPieceItsPartAndKeepsSeamsAndFdps) {
  Scene s = grid(3, 3);
  Part &p = s.parts[0];
  p.name = "head";
  // The seam: triangles of column 0 use copies of the vertices at x = 1.
  const int n0 = static_cast<int>(p.V.rows());
  p.V.conservativeResize(n0 + 4, 3);
  for (int j = 0; j <= 3; ++j) p.V.row(n0 + j) = p.V.row(1 + 4 * j);
  for (Eigen::Index f = 0; f < p.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = p.F(f, k), col = v % 4;
      bool column0 = true;
      for (int c = 0; c < 3; ++c) column0 = column0 && p.F(f, c) % 4 <= 1 && p.F(f, c) < n0;
      if (column0 && col == 1) p.F(f, k) = n0 + v / 4;
    }
  const Eigen::Index grid_faces = p.F.rows();
  add_tetrahedron(p, Eigen::Vector3d(1, 1, -3));   // the eye: vertices n0 + 4 ...
  add_tetrahedron(p, Eigen::Vector3d(1, 1, -2));   // teeth: their first corner is the eye's top
  add_tetrahedron(p, Eigen::Vector3d(5, 5, -5));   // a loose piece
  p.C = Eigen::MatrixXd::Zero(p.V.rows(), 3);
  for (Eigen::Index v = 0; v < p.V.rows(); ++v) p.C(v, 0) = static_cast<double>(v) / 100;
  afmb::FdpSet fdps;
  fdps.points = {on("2.1", "head", 0, 5), on("3.5", "head", 0, n0 + 4 + 1), on("9.9", "head", 0, n0 + 8 + 2),
                 on("9.11", "head", 0, n0 + 8 + 3), on("2.2", "head", 0, n0 + 1)};
  const Part before = p;
  std::vector<std::string> log;
  ASSERT_EQ(afmb::split_skin_pieces(s, 0, fdps, &log), 3);
  ASSERT_EQ(s.parts.size(), 4u);
  const Part &skin = s.parts[0];
  EXPECT_EQ(skin.name, "head");
  EXPECT_EQ(skin.F.rows(), grid_faces) << "the seam keeps the face one piece";
  EXPECT_EQ(skin.V.rows(), n0 + 4);
  EXPECT_TRUE(afmb::check_skin(s, 0));
  EXPECT_EQ(s.parts[1].name, "head_eye_left");
  EXPECT_EQ(s.parts[1].kind, afmb::PartKind::EyeLeft);
  EXPECT_EQ(s.parts[2].name, "head_teeth_lower") << "touching the eye, closed teeth stay apart";
  EXPECT_EQ(s.parts[2].kind, afmb::PartKind::TeethLower);
  EXPECT_EQ(s.parts[3].name, "head_piece2");
  EXPECT_EQ(s.parts[3].kind, afmb::PartKind::Other);
  for (size_t i = 1; i < 4; ++i) {
    EXPECT_EQ(s.parts[i].V.rows(), 4);
    EXPECT_EQ(s.parts[i].F.rows(), 4);
  }
  // Every FDP is where it was, on its piece, and so are the colours.
  for (const afmb::FdpPoint &q : fdps.points) {
    ASSERT_GE(q.part, 0);
    const Part &to = s.parts[static_cast<size_t>(q.part)];
    EXPECT_EQ(q.part_name, to.name);
    const int was = q.id.str() == "2.1" ? 5 : q.id.str() == "3.5" ? n0 + 5 : q.id.str() == "9.9" ? n0 + 10
                                              : q.id.str() == "9.11" ? n0 + 11 : n0 + 1;
    EXPECT_EQ(to.V.row(q.vertex), before.V.row(was)) << q.id.str();
    EXPECT_EQ(to.C.row(q.vertex), before.C.row(was)) << q.id.str();
  }
  EXPECT_EQ(fdps.points[1].part, 1);
  EXPECT_EQ(fdps.points[2].part, 2);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("split into its 4 separate pieces"), std::string::npos) << log[0];
  // One piece, or no chin on the part: nothing to do.
  Scene one = grid(2, 2);
  afmb::FdpSet chin;
  chin.points = {on("2.1", "skin", 0, 0)};
  EXPECT_EQ(afmb::split_skin_pieces(one, 0, chin, nullptr), 0);
  EXPECT_EQ(afmb::split_skin_pieces(s, 1, fdps, nullptr), 0);
}

// Lips that are one surface: a 6 x 4 grid whose row y = 2 is the lip line,
// the corners 2.4 at x = 5 and 2.5 at x = 1, 2.2 and 2.3 on one vertex at x = 3.
TEST(CutFusedLips, DoublesTheLineBetweenTheCornersAndGivesTheLowerLipTheCopies) {
  Scene s = grid(6, 4);
  const auto at = [](int x, int y) { return x + 7 * y; };
  afmb::FdpSet fdps;
  const std::pair<const char *, int> points[] = {{"2.4", at(5, 2)}, {"2.6", at(4, 2)}, {"2.8", at(4, 2)},
                                                 {"2.2", at(3, 2)}, {"2.3", at(3, 2)}, {"2.7", at(2, 2)},
                                                 {"2.9", at(2, 2)}, {"2.5", at(1, 2)}, {"2.1", at(3, 0)}};
  for (const auto &[id, v] : points) fdps.points.push_back(on(id, "skin", 0, v));
  const Part before = s.parts[0];
  auto open_edges = [](const Part &p) {
    std::map<std::pair<int, int>, int> n;
    for (Eigen::Index f = 0; f < p.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++n[{std::min(p.F(f, k), p.F(f, (k + 1) % 3)), std::max(p.F(f, k), p.F(f, (k + 1) % 3))}];
    int open = 0;
    for (const auto &e : n) open += e.second == 1;
    return open;
  };
  std::vector<std::string> log;
  ASSERT_EQ(afmb::cut_fused_lips(s, 0, fdps, &log), 3);
  const Part &p = s.parts[0];
  ASSERT_EQ(p.V.rows(), before.V.rows() + 3);
  EXPECT_TRUE(afmb::check_skin(s, 0));
  EXPECT_EQ(open_edges(p), open_edges(before) + 8) << "a slit of four edges, two sides";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.V.row(before.V.rows() + i), before.V.row(at(4 - i, 2)));
  // Below the line every triangle uses the copies, above it the originals.
  for (Eigen::Index f = 0; f < p.F.rows(); ++f) {
    double y = 0;
    for (int k = 0; k < 3; ++k) y += p.V(p.F(f, k), 1) / 3;
    for (int k = 0; k < 3; ++k) {
      const int v = p.F(f, k);
      if (y < 2) {
        EXPECT_FALSE(v == at(2, 2) || v == at(3, 2) || v == at(4, 2)) << "triangle " << f;
      } else {
        EXPECT_LT(v, before.V.rows()) << "triangle " << f;
      }
    }
  }
  for (const afmb::FdpPoint &q : fdps.points) {
    const bool lower = q.id.str() == "2.3" || q.id.str() == "2.8" || q.id.str() == "2.9";
    EXPECT_EQ(q.vertex >= before.V.rows(), lower) << q.id.str();
  }
  EXPECT_EQ(p.V.row(fdps.points[4].vertex), p.V.row(fdps.points[3].vertex)) << "2.3 where 2.2 is";
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("the lips are one surface"), std::string::npos) << log[0];
  // Lips already apart (2.2 and 2.3 on different vertices): left alone.
  Scene apart = grid(6, 4);
  fdps.points[4].vertex = at(3, 1);
  fdps.points[4].part = 0;
  EXPECT_EQ(afmb::cut_fused_lips(apart, 0, fdps, nullptr), 0);
  EXPECT_EQ(apart.parts[0].F, grid(6, 4).parts[0].F);
}

TEST(Validate, SongHeadFailsOnlyOnItsCoincidentCornerTriangles) {
  AFM_REQUIRE_SHARED_DATA();
  auto song = afmb::read_vrml(afmtest::shared_data("faces/song/song.WRL"));
  ASSERT_TRUE(song) << song.status().message();
  const int head = song->find_part("song_head");
  ASSERT_GE(head, 0);
  Part &p = song->parts[head];
  // Triangles with two corners at bit-identical positions (an exporter's
  // duplicate vertices), found here without check_skin.
  std::vector<int> flat;
  for (int t = 0; t < p.F.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (p.V.row(p.F(t, k)) == p.V.row(p.F(t, (k + 1) % 3))) {
        flat.push_back(t);
        break;
      }
  ASSERT_FALSE(flat.empty());
  afmb::Status st = afmb::check_skin(*song, head);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("part 'song_head': triangle " + std::to_string(flat[0]) + " ("),
            std::string::npos) << st.message();
  EXPECT_NE(st.message().find("is degenerate: area 0 "), std::string::npos) << st.message();
  // Without them the head is an edge-manifold, consistently oriented skin.
  Eigen::MatrixXi kept(p.F.rows() - static_cast<int>(flat.size()), 3);
  for (int t = 0, r = 0, f = 0; t < p.F.rows(); ++t) {
    if (f < static_cast<int>(flat.size()) && flat[f] == t) {
      ++f;
      continue;
    }
    kept.row(r++) = p.F.row(t);
  }
  p.F = kept;
  st = afmb::check_skin(*song, head);
  EXPECT_TRUE(st) << st.message();
}

TEST(Validate, CandideOrientationVerdictMatchesItsFaceLines) {
  AFM_REQUIRE_SHARED_DATA();
  const std::string path = afmtest::shared_data("faces/candide3/candide3.wfm.obj");
  // Independent: does any directed edge appear twice among the `f` lines?
  std::set<std::pair<int, int>> seen;
  bool repeated = false;
  std::istringstream in(afmtest::read_file(path));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream w(line);
    std::string key;
    w >> key;
    if (key != "f") continue;
    std::vector<int> v;
    std::string c;
    while (w >> c) v.push_back(std::stoi(c.substr(0, c.find('/'))));
    for (size_t k = 0; k < v.size(); ++k)
      repeated |= !seen.insert({v[k], v[(k + 1) % v.size()]}).second;
  }
  auto candide = afmb::read_scene(path);
  ASSERT_TRUE(candide) << candide.status().message();
  afmb::Status st = afmb::check_skin(*candide, 0);
  EXPECT_EQ(static_cast<bool>(st), !repeated) << st.message();
  if (repeated) {
    EXPECT_NE(st.message().find("inconsistent orientation"), std::string::npos) << st.message();
  }
}

TEST(Validate, GridWithBoundaryPasses) {
  Scene s = grid();
  EXPECT_TRUE(afmb::check_skin(s, 0));
}

TEST(Validate, ClosedSlitWithCoincidentVerticesPasses) {
  // A 5 x 3 grid cut along y = 1 from x = 1 to x = 4, like a closed mouth:
  // the corners (1,1) and (4,1) stay shared, the triangles above the cut get
  // their own copies of (2,1) and (3,1), at the same positions.
  Scene s = grid(5, 3);
  Part &p = s.parts[0];
  const int a = 2 + 6 * 1, b = 3 + 6 * 1;
  const int a2 = static_cast<int>(p.V.rows()), b2 = a2 + 1;
  p.V.conservativeResize(a2 + 2, 3);
  p.V.row(a2) = p.V.row(a);
  p.V.row(b2) = p.V.row(b);
  int changed = 0;
  for (int t = 0; t < p.F.rows(); ++t) {
    bool above = true;
    for (int k = 0; k < 3; ++k) above = above && p.V(p.F(t, k), 1) >= 1;
    for (int k = 0; above && k < 3; ++k) {
      if (p.F(t, k) == a) p.F(t, k) = a2, ++changed;
      if (p.F(t, k) == b) p.F(t, k) = b2, ++changed;
    }
  }
  ASSERT_GT(changed, 0);
  afmb::Status st = afmb::check_skin(s, 0);
  EXPECT_TRUE(st) << st.message();
}

TEST(Validate, TinyButRealTrianglesPass) {
  Scene s = grid();
  Part &p = s.parts[0];
  // A triangle of area 5e-7 on its own, 1e-4 of the model's size across
  // (the threshold is 1e-10 * diag^2 = 2e-8).
  p.V.conservativeResize(19, 3);
  p.V.row(16) << 10, 10, 0;
  p.V.row(17) << 10 + 1e-3, 10, 0;
  p.V.row(18) << 10, 10 + 1e-3, 0;
  add_triangle(p, 16, 17, 18);
  afmb::Status st = afmb::check_skin(s, 0);
  EXPECT_TRUE(st) << st.message();
}

TEST(ValidateErrors, NonManifoldEdge) {
  Scene s = grid();
  Part &p = s.parts[0];
  // A fin: a third triangle on the diagonal 5-10 of square (1,1), which its
  // triangles 8 and 9 already share, to a point above.
  p.V.conservativeResize(17, 3);
  p.V.row(16) << 1.5, 1.5, 1;
  add_triangle(p, 5, 10, 16);
  afmb::Status st = afmb::check_skin(s, 0);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message(), "grid.obj: part 'skin': edge 5-10 is shared by 3 triangles (8, 9, 18): not edge-manifold");
}

TEST(ValidateErrors, InconsistentOrientation) {
  Scene s = grid();
  Part &p = s.parts[0];
  std::swap(p.F(9, 1), p.F(9, 2));  // triangle 9 = (5, 10, 9) becomes (5, 9, 10)
  afmb::Status st = afmb::check_skin(s, 0);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("part 'skin': triangles"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("inconsistent orientation"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find(" 9 "), std::string::npos) << st.message();
}

TEST(ValidateErrors, DegenerateTriangles) {
  {
    Scene s = grid();
    s.parts[0].F(4, 2) = s.parts[0].F(4, 0);
    afmb::Status st = afmb::check_skin(s, 0);
    ASSERT_FALSE(st);
    EXPECT_EQ(st.message(), "grid.obj: part 'skin': triangle 4 (2, 3, 2) repeats a vertex");
  }
  {
    // Collinear: vertices 0, 1, 2 lie on y = 0.
    Scene s = grid();
    add_triangle(s.parts[0], 0, 1, 2);
    afmb::Status st = afmb::check_skin(s, 0);
    ASSERT_FALSE(st);
    EXPECT_EQ(st.message().rfind("grid.obj: part 'skin': triangle 18 (0, 1, 2) is degenerate: area 0", 0), 0u)
        << st.message();
  }
  {
    // Distinct vertices at (almost) one point.
    Scene s = grid();
    Part &p = s.parts[0];
    p.V.conservativeResize(19, 3);
    p.V.row(16) << 7, 7, 0;
    p.V.row(17) << 7 + 1e-9, 7, 0;
    p.V.row(18) << 7, 7 + 1e-9, 0;
    add_triangle(p, 16, 17, 18);
    afmb::Status st = afmb::check_skin(s, 0);
    ASSERT_FALSE(st);
    EXPECT_NE(st.message().find("triangle 18 (16, 17, 18) is degenerate"), std::string::npos) << st.message();
  }
}

TEST(ValidateErrors, IndicesPartsAndEmptiness) {
  Scene s = grid();
  s.parts[0].F(3, 1) = 99;
  afmb::Status st = afmb::check_skin(s, 0);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("vertex index 99 out of range (16 vertices)"), std::string::npos) << st.message();
  st = afmb::check_skin(s, 3);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message(), "grid.obj: no part 3 (1 parts)");
  Scene e = grid();
  e.parts[0].F.resize(0, 3);
  st = afmb::check_skin(e, 0);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message(), "grid.obj: part 'skin': no triangles");
}

}  // namespace
