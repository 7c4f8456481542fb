// OBJ / PLY / OFF / STL through OpenMesh, and read_scene's dispatch.
// OpenMesh's VectorT leaves elements uninitialised on purpose; GCC 12 flags
// the copies inside the standard headers.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include <gtest/gtest.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <array>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "../common/test_paths.h"
#include "core/atomic_file.h"
#include "core/validate.h"
#include "io/mesh_io.h"
#include "io/vrml.h"

namespace {

using afmb::Scene;

void write_text(const std::string &path, const std::string &text) {
  std::ofstream(path, std::ios::binary) << text;
}

// ---- Candide ---------------------------------------------------------------------

TEST(MeshIo, CandideObjMatchesItsLinesAndSourcesMd) {
  AFM_REQUIRE_SHARED_DATA();
  const std::string path = afmtest::shared_data("faces/candide3/candide3.wfm.obj");
  // Independent counts: `v ` lines, and triangles from `f ` lines.
  std::istringstream in(afmtest::read_file(path));
  std::string line;
  int v = 0, tri = 0;
  double first[3] = {0, 0, 0};
  while (std::getline(in, line)) {
    std::istringstream w(line);
    std::string key;
    w >> key;
    if (key == "v") {
      if (v == 0) w >> first[0] >> first[1] >> first[2];
      ++v;
    } else if (key == "f") {
      int corners = 0;
      std::string c;
      while (w >> c) ++corners;
      tri += corners - 2;
    }
  }
  // SOURCES.md: "Candide-3.1.6: 113 vertices, 184 triangles".
  std::smatch m;
  const std::string doc = afmtest::read_file(afmtest::shared_data("SOURCES.md"));
  ASSERT_TRUE(std::regex_search(doc, m, std::regex(R"(Candide-3[^:]*: (\d+) vertices, (\d+) triangles)")));
  EXPECT_EQ(v, std::stoi(m[1].str()));
  EXPECT_EQ(tri, std::stoi(m[2].str()));

  auto scene = afmb::read_scene(path);
  ASSERT_TRUE(scene) << scene.status().message();
  ASSERT_EQ(scene->parts.size(), 1u);
  const afmb::Part &p = scene->parts[0];
  EXPECT_EQ(p.name, "candide3.wfm");
  EXPECT_EQ(p.V.rows(), v);
  EXPECT_EQ(p.F.rows(), tri);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p.V(0, k), first[k], 1e-6);
  EXPECT_EQ(p.TC.rows(), 0);
}

// ---- OBJ groups and texcoords ------------------------------------------------------

TEST(MeshIo, ObjGroupsBecomePartsWithTexcoords) {
  const std::string dir = afmtest::temp_dir("mesh_io_groups");
  const std::string path = dir + "/g.obj";
  write_text(path,
             "# two objects sharing nothing, a quad and relative indices\n"
             "mtllib g.mtl\n"
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "o Head\n"
             "g head_skin\n"
             "usemtl skin\n"
             "f 1/1 2/2 3/3 4/4\n"
             "v 5 5 5\nv 6 5 5\nv 5 6 5\n"
             "g left eye\n"
             "f -3 -2 -1\n");
  auto s = afmb::read_scene(path);
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 2u);  // the empty `o Head` group is dropped
  const afmb::Part &a = s->parts[0], &b = s->parts[1];
  EXPECT_EQ(a.name, "head_skin");
  EXPECT_EQ(b.name, "left eye");
  EXPECT_EQ(a.kind, afmb::PartKind::Skin);
  EXPECT_EQ(b.kind, afmb::PartKind::EyeLeft);
  EXPECT_EQ(a.V.rows(), 4);
  EXPECT_EQ(b.V.rows(), 3);
  Eigen::MatrixXi F(2, 3);
  F << 0, 1, 2, 0, 2, 3;
  EXPECT_EQ(a.F, F);
  EXPECT_EQ(a.FTC, F);
  ASSERT_EQ(a.TC.rows(), 4);
  EXPECT_EQ(a.TC.row(2), Eigen::RowVector2d(1, 1));
  EXPECT_EQ(b.V.row(0), Eigen::RowVector3d(5, 5, 5));
  EXPECT_EQ(b.TC.rows(), 0);
}

TEST(MeshIo, ObjFacesWithoutTexcoordsTakeTheirVerticesFromTheOthers) {
  // A partial UV map: two faces of the group have coordinates, two none.
  // Before, the whole group lost its coordinates (and a textured head its
  // texture).
  const std::string dir = afmtest::temp_dir("mesh_io_partial_vt");
  const std::string path = dir + "/p.obj";
  write_text(path,
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
             "vt 0.1 0.2\nvt 0.3 0.4\nvt 0.5 0.6\nvt 0.7 0.8\n"
             "g face\n"
             "f 1/1 2/2 3/3\n"
             "f 1/1 3/3 4/4\n"
             "f 2 5 3\n"
             "f 5 6 3\n");
  auto s = afmb::read_scene(path);
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 1u);
  const afmb::Part &p = s->parts[0];
  ASSERT_EQ(p.TC.rows(), 5) << "the four written, and (0, 0) for the vertices no face maps";
  ASSERT_EQ(p.FTC.rows(), 4);
  // Face 3 (2 5 3): vertex 2 as face 1 maps it, 5 unmapped, 3 as face 1.
  EXPECT_EQ(p.TC.row(p.FTC(2, 0)), Eigen::RowVector2d(0.3, 0.4));
  EXPECT_EQ(p.TC.row(p.FTC(2, 1)), Eigen::RowVector2d(0, 0));
  EXPECT_EQ(p.TC.row(p.FTC(2, 2)), Eigen::RowVector2d(0.5, 0.6));
  EXPECT_EQ(p.TC.row(p.FTC(3, 2)), Eigen::RowVector2d(0.5, 0.6));
  // The faces that have coordinates keep them.
  EXPECT_EQ(p.TC.row(p.FTC(1, 2)), Eigen::RowVector2d(0.7, 0.8));
  ASSERT_EQ(s->notes.size(), 1u);
  EXPECT_NE(s->notes[0].find("p.obj (group 'face'): 2 of 4 faces have no texture coordinates (the first at line 14)"),
            std::string::npos)
      << s->notes[0];
  EXPECT_NE(s->notes[0].find("(0, 0) where none has any (3 corners)"), std::string::npos) << s->notes[0];
}

TEST(MeshIo, ObjMaterialsGiveEachPartItsColourAndTexture) {
  const std::string dir = afmtest::temp_dir("mesh_io_mtl");
  const std::string path = dir + "/m.obj";
  write_text(dir + "/m.mtl",
             "# two materials\nnewmtl skin\nNs 10\nKd 0.8 0.6 0.5\nmap_Kd -s 1 1 1 -clamp on face map.png\n"
             "newmtl eye\nKd 2 0.5 -1\n");
  write_text(path,
             "mtllib m.mtl\n"
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
             "g face\nusemtl skin\nf 1 2 3\nf 1 3 4\nusemtl eye\nf 2 5 3\n"
             "g eye_l\nusemtl eye\nf 1 2 4\n"
             "g other\nusemtl none\nf 2 3 4\n");
  auto s = afmb::read_scene(path);
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 3u);
  EXPECT_EQ(s->parts[0].texture, "face map.png") << "the most used material; options left out, spaces kept";
  EXPECT_EQ(s->parts[0].diffuse, Eigen::Vector3d(0.8, 0.6, 0.5));
  EXPECT_EQ(s->parts[1].texture, "");
  EXPECT_EQ(s->parts[1].diffuse, Eigen::Vector3d(1, 0.5, 0)) << "Kd held to 0..1";
  EXPECT_EQ(s->parts[2].diffuse, afmb::Part().diffuse);
  ASSERT_EQ(s->notes.size(), 1u);
  EXPECT_NE(s->notes[0].find("material 'none' is in no material library"), std::string::npos) << s->notes[0];
  // A missing library is a note, with the OBJ's line; a malformed Kd an error with the MTL's.
  write_text(dir + "/n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nmtllib gone.mtl\nusemtl skin\nf 1 2 3\n");
  auto n = afmb::read_scene(dir + "/n.obj");
  ASSERT_TRUE(n) << n.status().message();
  ASSERT_EQ(n->notes.size(), 1u);
  EXPECT_NE(n->notes[0].find("n.obj:4: material library 'gone.mtl' not found"), std::string::npos) << n->notes[0];
  write_text(dir + "/m.mtl", "newmtl skin\nKd 0.8 x 0.5\n");
  auto bad = afmb::read_scene(path);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.status().message().find("m.mtl:2: Kd needs three numbers"), std::string::npos) << bad.status().message();
}

TEST(MeshIo, SongObjRoundTrip) {
  AFM_REQUIRE_SHARED_DATA();
  auto a = afmb::read_scene(afmtest::shared_data("faces/song/song.WRL"));
  ASSERT_TRUE(a) << a.status().message();
  const std::string out = afmtest::temp_dir("mesh_io_song_obj") + "/song.obj";
  ASSERT_TRUE(afmb::write_obj(*a, out));
  auto b = afmb::read_scene(out);
  ASSERT_TRUE(b) << b.status().message();
  ASSERT_EQ(a->parts.size(), b->parts.size());
  for (size_t i = 0; i < a->parts.size(); ++i) {
    const afmb::Part &p = a->parts[i], &q = b->parts[i];
    SCOPED_TRACE(p.name);
    EXPECT_EQ(p.name, q.name);
    EXPECT_EQ(p.kind, q.kind);
    ASSERT_EQ(p.V.rows(), q.V.rows());
    // OpenMesh parses OBJ numbers in single precision.
    EXPECT_LE((p.V - q.V).cwiseAbs().maxCoeff(), 1e-6 * p.V.cwiseAbs().maxCoeff());
    EXPECT_EQ(p.F, q.F);
    ASSERT_EQ(p.TC.rows(), q.TC.rows());
    EXPECT_LE((p.TC - q.TC).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_EQ(p.FTC, q.FTC);
  }
}

// ---- PLY / OFF / STL written by OpenMesh itself ----------------------------------------

using OmTri = OpenMesh::TriMesh_ArrayKernelT<>;

OmTri cube() {
  OmTri m;
  std::vector<OmTri::VertexHandle> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(m.add_vertex(OmTri::Point(float(i & 1), float(i >> 1 & 1), float(i >> 2 & 1))));
  const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                        {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto &t : f) m.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return m;
}

TEST(MeshIo, PlyOffStlFromOpenMeshLoadBack) {
  OmTri m = cube();
  ASSERT_EQ(m.n_faces(), 12u);
  const std::string dir = afmtest::temp_dir("mesh_io_openmesh");
  struct Case {
    const char *name;
    OpenMesh::IO::Options opt;
  } cases[] = {{"cube.ply", OpenMesh::IO::Options::Default},
               {"cube_bin.ply", OpenMesh::IO::Options::Binary},
               {"cube.off", OpenMesh::IO::Options::Default},
               {"cube.stl", OpenMesh::IO::Options::Default},
               {"cube_bin.stl", OpenMesh::IO::Options::Binary},
               {"CUBE.OFF", OpenMesh::IO::Options::Default}};
  for (const Case &c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir + "/" + c.name;
    ASSERT_TRUE(OpenMesh::IO::write_mesh(m, path, c.opt));
    auto s = afmb::read_scene(path);
    ASSERT_TRUE(s) << s.status().message();
    ASSERT_EQ(s->parts.size(), 1u);
    const afmb::Part &p = s->parts[0];
    EXPECT_EQ(p.F.rows(), 12);
    EXPECT_EQ(p.V.rows(), 8);  // STL: OpenMesh merges equal corner positions
    // Every triangle's corners are the cube's, in the same winding: compare
    // by position (STL renumbers vertices).
    for (int t = 0; t < 12; ++t) {
      OmTri::FaceHandle fh(t);
      int k = 0;
      for (auto vh : m.fv_range(fh)) {
        OmTri::Point q = m.point(vh);
        EXPECT_EQ(p.V.row(p.F(t, k)), Eigen::RowVector3d(q[0], q[1], q[2])) << "triangle " << t;
        ++k;
      }
    }
  }
}

TEST(MeshIo, StlSurfacesTouchingAtAPointComeApart) {
  // Two closed tetrahedra, apex to apex (as touching teeth rows meet): STL
  // has no vertex numbers, so OpenMesh joins the apexes, and the second
  // tetrahedron's faces there could only be held on copies of their corners,
  // cut off from their neighbours (before, an error). Now each surface keeps
  // its own apex, and the rest of each stays joined.
  const std::string dir = afmtest::temp_dir("mesh_io_stl_fans");
  auto facet = [](const std::array<Eigen::Vector3d, 3> &p) {
    std::ostringstream o;
    o << "facet normal 0 0 0\n outer loop\n";
    for (const Eigen::Vector3d &q : p) o << "  vertex " << q.x() << ' ' << q.y() << ' ' << q.z() << "\n";
    o << " endloop\nendfacet\n";
    return o.str();
  };
  // A tetrahedron with apex at the origin, pointing along `s` (+1 or -1 in z),
  // wound outwards.
  auto tetra = [&](double sz) {
    const Eigen::Vector3d a(0, 0, 0), b(1, 0, sz), c(-0.5, 0.8, sz), d(-0.5, -0.8, sz);
    std::string out;
    if (sz > 0)
      out = facet({a, c, b}) + facet({a, d, c}) + facet({a, b, d}) + facet({b, c, d});
    else
      out = facet({a, b, c}) + facet({a, c, d}) + facet({a, d, b}) + facet({b, d, c});
    return out;
  };
  write_text(dir + "/touch.stl", "solid touch\n" + tetra(1) + tetra(-1) + "endsolid touch\n");
  auto s = afmb::read_scene(dir + "/touch.stl");
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts.size(), 1u);
  const afmb::Part &p = s->parts[0];
  ASSERT_EQ(p.F.rows(), 8);
  ASSERT_EQ(p.V.rows(), 8) << "4 corners each; the apex twice";
  // Triangles 0-3 and 4-7 share no vertex; within each, every corner is
  // shared by three triangles (a closed tetrahedron).
  std::set<int> first, second;
  for (int t = 0; t < 8; ++t)
    for (int c = 0; c < 3; ++c) (t < 4 ? first : second).insert(p.F(t, c));
  EXPECT_EQ(first.size(), 4u);
  EXPECT_EQ(second.size(), 4u);
  for (int v : first) EXPECT_EQ(second.count(v), 0u) << v;
  int apexes = 0;
  for (Eigen::Index v = 0; v < p.V.rows(); ++v) apexes += p.V.row(v).isZero() ? 1 : 0;
  EXPECT_EQ(apexes, 2);
  ASSERT_EQ(s->notes.size(), 1u);
  EXPECT_NE(s->notes[0].find("touch.stl: 1 vertex joins closed surfaces that touch"), std::string::npos)
      << s->notes[0];
  // One surface alone: nothing to split, no note.
  write_text(dir + "/one.stl", "solid one\n" + tetra(1) + "endsolid one\n");
  auto one = afmb::read_scene(dir + "/one.stl");
  ASSERT_TRUE(one) << one.status().message();
  EXPECT_EQ(one->parts[0].V.rows(), 4);
  EXPECT_TRUE(one->notes.empty());
}

TEST(MeshIo, PlyVertexColours) {
  OmTri m = cube();
  m.request_vertex_colors();
  for (auto vh : m.vertices()) m.set_color(vh, OmTri::Color(255, 0, 51));
  const std::string path = afmtest::temp_dir("mesh_io_ply_colour") + "/c.ply";
  OpenMesh::IO::Options opt = OpenMesh::IO::Options::VertexColor;
  ASSERT_TRUE(OpenMesh::IO::write_mesh(m, path, opt));
  auto s = afmb::read_scene(path);
  ASSERT_TRUE(s) << s.status().message();
  ASSERT_EQ(s->parts[0].C.rows(), 8);
  EXPECT_NEAR(s->parts[0].C(3, 0), 1.0, 1e-12);
  EXPECT_NEAR(s->parts[0].C(3, 2), 0.2, 1e-12);
}

// ---- errors ---------------------------------------------------------------------------

std::string error_of(const std::string &path) {
  testing::internal::CaptureStderr();
  auto s = afmb::read_scene(path);
  const std::string stderr_text = testing::internal::GetCapturedStderr();
  EXPECT_EQ(stderr_text, "") << "OpenMesh chatter reached stderr";
  EXPECT_FALSE(s) << path << " was accepted";
  return s ? std::string() : s.status().message();
}

TEST(MeshIoErrors, MissingFileAndUnknownExtension) {
  const std::string dir = afmtest::temp_dir("mesh_io_errors_basic");
  std::string e = error_of(dir + "/absent.obj");
  EXPECT_EQ(e.rfind(dir + "/absent.obj: cannot open", 0), 0u) << e;
  write_text(dir + "/x.xyz", "1 2 3\n");
  e = error_of(dir + "/x.xyz");
  EXPECT_EQ(e, dir + "/x.xyz: unknown mesh format '.xyz' (expected .obj, .ply, .off, .stl, .wrl or .vrml)");
  e = error_of(dir + "/noext");
  EXPECT_NE(e.find("unknown mesh format ''"), std::string::npos) << e;
}

TEST(MeshIoErrors, ObjIndexOutOfRangeNamesLine) {
  const std::string path = afmtest::temp_dir("mesh_io_errors_range") + "/bad.obj";
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\n# comment\nf 1 2 9\n");
  EXPECT_EQ(error_of(path), path + ":5: vertex index 9 out of range (3 vertices)");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n");
  EXPECT_EQ(error_of(path), path + ":4: vertex index -4 out of range (3 vertices so far)");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/2\n");
  EXPECT_EQ(error_of(path), path + ":5: texture index 2 out of range (1 texture coordinates)");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n");
  EXPECT_EQ(error_of(path), path + ":4: face uses vertex 2 twice");
  write_text(path, "v 0 0 0\nv 1 0 0\nf 1 2\n");
  EXPECT_EQ(error_of(path), path + ":3: face with 2 vertices (at least 3 needed)");
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n");
  EXPECT_NE(error_of(path).find(path + ":4: malformed vertex 'x'"), std::string::npos);
}

TEST(MeshIo, ObjFacesOpenMeshSplitsOffAreKeptAsWritten) {
  // OpenMesh can hold these only on copies of their vertices; the reader keeps
  // them on the file's vertices and check_skin() names the problem.
  const std::string path = afmtest::temp_dir("mesh_io_nm") + "/fin.obj";
  // Three triangles on edge 1-2 (a fin), then the same edge twice one way.
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n"
                   "f 1/1 2/2 3/3\nf 2/2 1/1 4/3\nf 1/1 2/2 5/3\n");
  testing::internal::CaptureStderr();
  auto s = afmb::read_scene(path);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "") << "OpenMesh chatter reached stderr";
  ASSERT_TRUE(s) << s.status().message();
  const afmb::Part &p = s->parts[0];
  EXPECT_EQ(p.V.rows(), 5);
  Eigen::MatrixXi F(3, 3), FTC(3, 3);
  F << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  FTC << 0, 1, 2, 1, 0, 2, 0, 1, 2;
  EXPECT_EQ(p.F, F);
  EXPECT_EQ(p.FTC, FTC);
  EXPECT_EQ(p.V.row(4), Eigen::RowVector3d(0, 0, 1));
  afmb::Status st = afmb::check_skin(*s, 0);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.message(), path + ": part 'fin': edge 0-1 is shared by 3 triangles (0, 1, 2): not edge-manifold");
}

TEST(MeshIoErrors, OffFaceOpenMeshDropsIsReported) {
  const std::string path = afmtest::temp_dir("mesh_io_errors_off") + "/bad.off";
  write_text(path, "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 7\n");
  std::string e = error_of(path);
  EXPECT_EQ(e.rfind(path + ": OpenMesh kept 1 of the 2 faces the file holds", 0), 0u) << e;
  write_text(path, "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  e = error_of(path);
  EXPECT_EQ(e.rfind(path + ": face 2 is not manifold", 0), 0u) << e;
}

TEST(MeshIo, VrmlThroughReadScene) {
  const std::string path = afmtest::temp_dir("mesh_io_vrml") + "/t.VRML";
  write_text(path, "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord Coordinate { point "
                   "[ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } }\n");
  auto s = afmb::read_scene(path);
  ASSERT_TRUE(s) << s.status().message();
  EXPECT_EQ(s->parts.size(), 1u);
  EXPECT_TRUE(s->parts[0].matches("t.VRML_0"));
}

}  // namespace
