// OpenMesh's VectorT default constructor leaves its elements uninitialised on
// purpose, and GCC 12 flags the copies its property arrays make of them
// (inside the standard headers, so the pragma has to precede every include).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "io/mesh_io.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <array>
#include <filesystem>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <exception>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "core/atomic_file.h"
#include "core/part_kind.h"
#include "core/repair.h"
#include "io/vrml.h"

namespace afmb {

namespace {

// Double positions so nothing is lost after OpenMesh's own parsing.
struct OmTraits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec2d TexCoord2D;
};
using OmMesh = OpenMesh::PolyMesh_ArrayKernelT<OmTraits>;

// Catches what OpenMesh says on its omerr/omlog streams while the object
// lives, for our error messages instead of the terminal. Those streams write
// to std::cerr / std::clog, so their buffers are swapped for ours: OpenMesh's
// own connect()/disconnect() would leak a small object per call. Everything
// the process writes to std::cerr / std::clog meanwhile is caught as well,
// and the streams are process-wide: do not read meshes from two threads at
// once.
class OmCapture {
 public:
  OmCapture() : err_(std::cerr.rdbuf(buf_.rdbuf())), log_(std::clog.rdbuf(buf_.rdbuf())) {}
  ~OmCapture() {
    omerr().flush();
    omlog().flush();
    std::cerr.rdbuf(err_);
    std::clog.rdbuf(log_);
  }
  OmCapture(const OmCapture &) = delete;
  OmCapture &operator=(const OmCapture &) = delete;

  // What OpenMesh said, on one line, repeats counted ("...: complex edge
  // (x20)"), or "".
  std::string text() {
    omerr().flush();
    omlog().flush();
    std::vector<std::pair<std::string, int>> lines;
    std::istringstream in(buf_.str());
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      auto it = std::find_if(lines.begin(), lines.end(), [&](const auto &l) { return l.first == line; });
      if (it == lines.end()) lines.emplace_back(line, 1);
      else ++it->second;
    }
    std::string t;
    for (const auto &[l, n] : lines)
      t += (t.empty() ? "" : "; ") + l + (n > 1 ? " (x" + std::to_string(n) + ")" : "");
    return t;
  }
  std::string suffix() {
    std::string t = text();
    return t.empty() ? std::string() : " (OpenMesh: " + t + ")";
  }

 private:
  std::ostringstream buf_;
  std::streambuf *err_;
  std::streambuf *log_;
};

std::string lower(std::string s) {
  for (char &c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string stem(const std::string &path) { return std::filesystem::path(path).stem().string(); }

std::string extension(const std::string &path) {
  return lower(std::filesystem::path(path).extension().string());
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> words(std::string_view s) {
  std::vector<std::string_view> w;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    if (j > i) w.push_back(s.substr(i, j - i));
    i = j;
  }
  return w;
}

bool parse_int(std::string_view s, long *out) {
  if (s.empty()) return false;
  auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// ---- OBJ ------------------------------------------------------------------------
// OpenMesh reads one mesh per call and knows nothing of groups. A first pass
// over the text finds the `o`/`g` groups, the face lines with their indices
// and the `vt` values (so that errors name lines). OpenMesh then reads, per
// group, the file with the other groups' face lines left out: the positions
// come from it, and every face it dropped is an error. A face OpenMesh can
// hold only by splitting it off from its neighbours onto copies of its
// vertices (an edge already used in the same direction, a third face on an
// edge, two fans meeting at a vertex) is kept as written, on the file's
// vertices: the reader does not judge topology, check_skin() does. Texture
// coordinates come from the first pass, because OpenMesh attaches them to
// the wrong corners of such split faces.

struct ObjFace {
  int line = 0;
  int group = 0;
  int material = -1;    // index into ObjScan::materials (the last usemtl), -1 for none
  std::vector<int> v;   // 0-based vertex indices as written (relative ones resolved)
  std::vector<int> vt;  // 0-based texture indices, or empty when the face has none
};

struct ObjLine {
  size_t begin = 0, end = 0;  // byte range in the text, without the newline
  char kind = 0;              // 'v' for v/vt/vn, 'f' face, 0 anything else
  int face = -1;              // index into faces when kind == 'f'
};

struct ObjScan {
  std::vector<ObjLine> lines;
  std::vector<ObjFace> faces;
  std::vector<std::string> groups;  // first appearance order; "" = faces before any o/g
  std::vector<Eigen::Vector2d> vt;
  int nv = 0;
  std::vector<std::string> materials;  // usemtl names, first use order
  std::vector<std::pair<std::string, int>> libraries;  // mtllib file names as written, with their line
};

bool parse_double(std::string_view s, double *out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
}

Expected<ObjScan> scan_obj(const std::string &text, const std::string &path) {
  ObjScan s;
  std::map<std::string, int> group_index, material_index;
  int group = -1, material = -1;
  auto use_group = [&](const std::string &name) {
    auto it = group_index.find(name);
    if (it != group_index.end()) return it->second;
    group_index[name] = static_cast<int>(s.groups.size());
    s.groups.push_back(name);
    return static_cast<int>(s.groups.size()) - 1;
  };
  // Relative indices count what was read so far; positive ones may point
  // forward (OpenMesh allows it), so they are checked once all are counted.
  struct Pending {
    int line;
    bool tex;
    long value;
  };
  std::vector<Pending> forward;

  size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    ++line_no;
    ObjLine L;
    L.begin = pos;
    L.end = nl;
    std::string_view line = trim(std::string_view(text).substr(pos, nl - pos));
    pos = nl + 1;
    std::vector<std::string_view> w = words(line);
    auto err = [&](const std::string &msg) {
      return Status::error(path + ":" + std::to_string(line_no) + ": " + msg);
    };
    if (w.empty() || w[0][0] == '#') {
      s.lines.push_back(L);
      continue;
    }
    const std::string_view key = w[0];
    if (key == "v" || key == "vn") {
      L.kind = 'v';
      double x = 0;
      for (size_t k = 1; k < 4; ++k)
        if (k >= w.size() || !parse_double(w[k], &x))
          return err(std::string(key == "v" ? "vertex" : "normal") + " needs three numbers, found '" +
                     std::string(line) + "'");
      if (key == "v") ++s.nv;
    } else if (key == "vt") {
      L.kind = 'v';
      Eigen::Vector2d t(0, 0);
      for (size_t k = 1; k < w.size() && k < 3; ++k)
        if (!parse_double(w[k], &t[static_cast<Eigen::Index>(k - 1)]))
          return err("malformed texture coordinate '" + std::string(w[k]) + "'");
      if (w.size() < 2) return err("texture coordinate without values");
      s.vt.push_back(t);
    } else if (key == "o" || key == "g") {
      group = use_group(std::string(trim(line.substr(1))));
    } else if (key == "usemtl") {
      const std::string name(trim(line.substr(6)));
      const auto [it, fresh] = material_index.insert({name, static_cast<int>(s.materials.size())});
      if (fresh) s.materials.push_back(name);
      material = it->second;
    } else if (key == "mtllib") {
      for (size_t k = 1; k < w.size(); ++k) s.libraries.push_back({std::string(w[k]), line_no});
    } else if (key == "f") {
      if (group < 0) group = use_group("");
      ObjFace f;
      f.line = line_no;
      f.group = group;
      f.material = material;
      if (w.size() < 4)
        return err("face with " + std::to_string(w.size() - 1) + " vertices (at least 3 needed)");
      const long nvt = static_cast<long>(s.vt.size());
      bool all_vt = true;
      for (size_t k = 1; k < w.size(); ++k) {
        std::string_view c = w[k];
        size_t slash = c.find('/');
        std::string_view vi = c.substr(0, slash);
        std::string_view ti = slash == std::string_view::npos ? std::string_view() : c.substr(slash + 1);
        ti = ti.substr(0, ti.find('/'));
        long a = 0;
        if (!parse_int(vi, &a) || a == 0)
          return err("malformed vertex '" + std::string(c) + "' in face (OBJ indices start at 1)");
        if (a < 0 && -a > s.nv)
          return err("vertex index " + std::to_string(a) + " out of range (" + std::to_string(s.nv) +
                     " vertices so far)");
        if (a > 0) forward.push_back({line_no, false, a});
        f.v.push_back(static_cast<int>(a < 0 ? s.nv + a : a - 1));
        if (ti.empty()) {
          all_vt = false;
          continue;
        }
        long t = 0;
        if (!parse_int(ti, &t) || t == 0) return err("malformed texture index in '" + std::string(c) + "'");
        if (t < 0 && -t > nvt)
          return err("texture index " + std::to_string(t) + " out of range (" + std::to_string(nvt) +
                     " texture coordinates so far)");
        if (t > 0) forward.push_back({line_no, true, t});
        f.vt.push_back(static_cast<int>(t < 0 ? nvt + t : t - 1));
      }
      if (!all_vt) f.vt.clear();
      // OpenMesh drops such faces; say so here, with the line.
      for (size_t a = 0; a < f.v.size(); ++a)
        for (size_t b = a + 1; b < f.v.size(); ++b)
          if (f.v[a] == f.v[b]) return err("face uses vertex " + std::to_string(f.v[a] + 1) + " twice");
      L.kind = 'f';
      L.face = static_cast<int>(s.faces.size());
      s.faces.push_back(std::move(f));
    }
    s.lines.push_back(L);
  }
  for (const Pending &p : forward) {
    const long limit = p.tex ? static_cast<long>(s.vt.size()) : s.nv;
    if (p.value > limit)
      return Status::error(path + ":" + std::to_string(p.line) + ": " +
                           (p.tex ? "texture index " : "vertex index ") + std::to_string(p.value) +
                           " out of range (" + std::to_string(limit) +
                           (p.tex ? " texture coordinates)" : " vertices)"));
  }
  return s;
}

// `keep_all`: the part takes every vertex of the file, in file order, used or
// not (a file with one group, so that vertex numbers stay the file's); else
// only those its faces use, still in file order. Texture coordinates are
// always only those the faces use. When some of the group's faces have
// texture coordinates and others none (a partial UV map), the corners of the
// others take their vertex's coordinates from a face that has them, else
// (0, 0), and `note` says so.
Status read_obj_group(const std::string &text, const std::string &path, const ObjScan &scan,
                      int group, bool keep_all, Part &part, std::string *note) {
  std::vector<const ObjFace *> faces;
  for (const ObjFace &f : scan.faces)
    if (f.group == group) faces.push_back(&f);
  const bool with_tc =
      std::any_of(faces.begin(), faces.end(), [](const ObjFace *f) { return !f->vt.empty(); });

  std::string sub;
  sub.reserve(text.size());
  for (const ObjLine &L : scan.lines) {
    if (L.kind == 'v' || (L.kind == 'f' && scan.faces[L.face].group == group)) {
      sub.append(text, L.begin, L.end - L.begin);
      sub += '\n';
    }
  }

  OmMesh mesh;
  mesh.request_face_status();
  OpenMesh::IO::Options opt;
  OmCapture capture;
  bool ok = false;
  try {
    std::istringstream in(sub);
    ok = OpenMesh::IO::read_mesh(mesh, in, ".obj", opt);
  } catch (const std::exception &e) {
    return Status::error(path + ": OpenMesh failed: " + e.what());
  }
  const std::string where =
      path + (scan.groups[group].empty() ? std::string() : " (group '" + scan.groups[group] + "')");
  if (!ok) return Status::error(where + ": OpenMesh could not read the file" + capture.suffix());
  if (mesh.n_vertices() < static_cast<size_t>(scan.nv))
    return Status::error(where + ": OpenMesh read " + std::to_string(mesh.n_vertices()) + " of " +
                         std::to_string(scan.nv) + " vertices" + capture.suffix());
  if (mesh.n_faces() != faces.size())
    return Status::error(where + ": OpenMesh kept " + std::to_string(mesh.n_faces()) + " of " +
                         std::to_string(faces.size()) + " faces" + capture.suffix());

  // OpenMesh keeps the faces in file order; check each against the first
  // pass (a manifold face has the file's vertices in the file's cycle).
  size_t k = 0;
  for (OmMesh::FaceHandle fh : mesh.faces()) {
    const ObjFace &f = *faces[k++];
    std::vector<int> cycle;
    for (OmMesh::VertexHandle vh : mesh.fv_range(fh)) cycle.push_back(vh.idx());
    bool same = cycle.size() == f.v.size();
    if (same && !mesh.status(fh).fixed_nonmanifold()) {
      auto start = std::find(cycle.begin(), cycle.end(), f.v[0]);
      same = start != cycle.end();
      if (same) std::rotate(cycle.begin(), start, cycle.end());
      same = same && cycle == f.v;
    }
    if (!same)
      return Status::error(path + ":" + std::to_string(f.line) +
                           ": OpenMesh read this face differently from the file");
  }

  std::vector<int> remap(static_cast<size_t>(scan.nv), -1), tremap(scan.vt.size(), -1);
  for (const ObjFace *f : faces) {
    for (int v : f->v) remap[v] = 0;
    for (int t : f->vt) tremap[t] = 0;
  }
  if (keep_all) std::fill(remap.begin(), remap.end(), 0);
  int nused = 0, ntused = 0;
  for (int &r : remap)
    if (r == 0) r = nused++;
  for (int &r : tremap)
    if (r == 0) r = ntused++;

  part.V.resize(nused, 3);
  for (int v = 0; v < scan.nv; ++v)
    if (remap[v] >= 0) {
      const OmMesh::Point p = mesh.point(OmMesh::VertexHandle(v));
      part.V.row(remap[v]) << p[0], p[1], p[2];
    }
  // The corners of faces without coordinates: their vertex's from the first
  // face that gives it some, else the extra (0, 0) row after the others.
  std::vector<int> vertex_tc(static_cast<size_t>(scan.nv), -1);
  int bare = 0, bare_line = 0, unmapped = 0;
  for (const ObjFace *f : faces)
    for (size_t c = 0; c < f->vt.size(); ++c)
      if (vertex_tc[static_cast<size_t>(f->v[c])] < 0) vertex_tc[static_cast<size_t>(f->v[c])] = tremap[f->vt[c]];
  std::vector<std::vector<int>> corners_tc(faces.size());
  for (size_t fk = 0; with_tc && fk < faces.size(); ++fk) {
    const ObjFace &f = *faces[fk];
    std::vector<int> &tc = corners_tc[fk];
    if (!f.vt.empty()) {
      for (int t : f.vt) tc.push_back(tremap[t]);
      continue;
    }
    if (bare++ == 0) bare_line = f.line;
    for (int v : f.v) {
      const int t = vertex_tc[static_cast<size_t>(v)];
      if (t < 0) ++unmapped;
      tc.push_back(t < 0 ? ntused : t);
    }
  }
  part.TC.resize(with_tc ? ntused + (unmapped > 0 ? 1 : 0) : 0, 2);
  if (with_tc) {
    for (size_t t = 0; t < scan.vt.size(); ++t)
      if (tremap[t] >= 0) part.TC.row(tremap[t]) = scan.vt[t].transpose();
    if (unmapped > 0) part.TC.row(ntused).setZero();
  }
  if (bare > 0 && note) {
    *note = where + ": " + std::to_string(bare) + " of " + std::to_string(faces.size()) +
            " faces have no texture coordinates (the first at line " + std::to_string(bare_line) +
            "): their corners take their vertex's from the other faces" +
            (unmapped > 0 ? ", or (0, 0) where none has any (" + std::to_string(unmapped) + " corners)"
                          : std::string());
  }

  int ntri = 0;
  for (const ObjFace *f : faces) ntri += static_cast<int>(f->v.size()) - 2;
  part.F.resize(ntri, 3);
  part.FTC.resize(with_tc ? ntri : 0, 3);
  int row = 0;
  for (size_t fk = 0; fk < faces.size(); ++fk) {
    const ObjFace *f = faces[fk];
    for (size_t c = 1; c + 1 < f->v.size(); ++c, ++row) {
      part.F.row(row) << remap[f->v[0]], remap[f->v[c]], remap[f->v[c + 1]];
      if (with_tc) part.FTC.row(row) << corners_tc[fk][0], corners_tc[fk][c], corners_tc[fk][c + 1];
    }
  }
  part.C.resize(0, 3);
  return Status::ok();
}

// The materials of one MTL file (newmtl; Kd the colour, map_Kd the texture;
// the rest is passed over). map_Kd's options (-s 1 1 1, -clamp on, ...) come
// before the file name, which may hold spaces.
Status read_mtl(const std::string &path, std::map<std::string, Part::Material> &out) {
  Expected<std::string> text = read_file(path);
  if (!text) return text.status();
  Part::Material *m = nullptr;
  size_t pos = 0;
  int line_no = 0;
  while (pos < text->size()) {
    size_t nl = text->find('\n', pos);
    if (nl == std::string::npos) nl = text->size();
    ++line_no;
    const std::string_view line = trim(std::string_view(*text).substr(pos, nl - pos));
    pos = nl + 1;
    const std::vector<std::string_view> w = words(line);
    if (w.empty() || w[0][0] == '#') continue;
    auto err = [&](const std::string &msg) { return Status::error(path + ":" + std::to_string(line_no) + ": " + msg); };
    if (w[0] == "newmtl") {
      m = &out[std::string(trim(line.substr(6)))];
    } else if (w[0] == "Kd" && m) {
      Eigen::Vector3d c;
      for (int k = 0; k < 3; ++k)
        if (w.size() < 4 || !parse_double(w[static_cast<size_t>(k) + 1], &c[k]))
          return err("Kd needs three numbers, found '" + std::string(line) + "'");
      m->diffuse = c.cwiseMax(0.0).cwiseMin(1.0);
    } else if (w[0] == "map_Kd" && m) {
      static const std::map<std::string_view, int> kArgs = {
          {"-blendu", 1}, {"-blendv", 1}, {"-bm", 1}, {"-boost", 1}, {"-cc", 1}, {"-clamp", 1}, {"-imfchan", 1},
          {"-mm", 2},     {"-o", 3},      {"-s", 3},  {"-t", 3},     {"-texres", 1}};
      size_t k = 1;
      while (k < w.size() && kArgs.count(w[k])) {
        const int n = kArgs.at(w[k]);
        ++k;
        double x = 0;
        for (int a = 0; a < n && k < w.size() && (n == 1 || parse_double(w[k], &x)); ++a) ++k;
      }
      if (k >= w.size()) return err("map_Kd names no file");
      m->texture = std::string(line.substr(static_cast<size_t>(w[k].data() - line.data())));
    }
  }
  return Status::ok();
}

Expected<Scene> read_obj(const std::string &path) {
  Expected<std::string> text = read_file(path);
  if (!text) return text.status();
  Expected<ObjScan> scan = scan_obj(*text, path);
  if (!scan) return scan.status();
  if (scan->faces.empty()) return Status::error(path + ": no faces");
  Scene scene;
  scene.name = stem(path);
  scene.source = path;
  std::vector<int> group_faces(scan->groups.size(), 0);
  for (const ObjFace &f : scan->faces) ++group_faces[f.group];
  const bool single =
      std::count_if(group_faces.begin(), group_faces.end(), [](int n) { return n > 0; }) == 1;
  std::vector<int> part_group;  // the group each part was read from
  for (int g = 0; g < static_cast<int>(scan->groups.size()); ++g) {
    if (group_faces[g] == 0) continue;  // e.g. an `o` line directly followed by a `g` line
    Part part;
    std::string name = scan->groups[g].empty() ? scene.name : scan->groups[g];
    part.name = name;
    for (int k = 2; scene.find_part(part.name) >= 0; ++k) part.name = name + "_" + std::to_string(k);
    std::string note;
    if (Status st = read_obj_group(*text, path, *scan, g, single, part, &note); !st) return st;
    if (!note.empty()) scene.notes.push_back(note);
    part.kind = guess_part_kind(part);
    scene.parts.push_back(std::move(part));
    part_group.push_back(g);
  }
  // Materials: each part takes the one most of its triangles use (the first
  // used of those tied), and keeps each triangle's (Part::face_material).
  std::map<std::string, Part::Material> materials;
  bool all_found = true;
  for (const auto &[lib, line] : scan->libraries) {
    const std::string file = (std::filesystem::path(path).parent_path() / lib).string();
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) {
      scene.notes.push_back(path + ":" + std::to_string(line) + ": material library '" + lib +
                            "' not found: the parts keep the default colour, without textures");
      all_found = false;
      continue;
    }
    if (Status st = read_mtl(file, materials); !st) return st;
  }
  std::set<std::string> unknown;
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    Part &part = scene.parts[i];
    // Each triangle's material (fan triangles share their polygon's), the
    // library's ones only; the part's own is the most used.
    std::vector<int> local(scan->materials.size(), -2);  // -2: not looked up yet
    std::vector<int> uses;
    for (const ObjFace &f : scan->faces) {
      if (f.group != part_group[i]) continue;
      int m = -1;
      if (f.material >= 0) {
        int &l = local[static_cast<size_t>(f.material)];
        if (l == -2) {
          const std::string &name = scan->materials[static_cast<size_t>(f.material)];
          const auto it = materials.find(name);
          if (it == materials.end()) {
            unknown.insert(name);
            l = -1;
          } else {
            l = static_cast<int>(part.materials.size());
            part.materials.push_back(it->second);
            uses.push_back(0);
          }
        }
        m = l;
      }
      for (size_t c = 1; c + 1 < f.v.size(); ++c) {
        part.face_material.push_back(m);
        if (m >= 0) ++uses[static_cast<size_t>(m)];
      }
    }
    if (part.materials.empty()) {
      part.face_material.clear();
      continue;
    }
    const Part::Material &most = part.materials[static_cast<size_t>(std::max_element(uses.begin(), uses.end()) - uses.begin())];
    part.diffuse = most.diffuse;
    part.texture = most.texture;
  }
  for (const std::string &name : unknown)
    if (all_found)
      scene.notes.push_back(path + ": material '" + name + "' is in no material library: the default colour");
  return scene;
}

// ---- PLY / OFF / STL ------------------------------------------------------------------

// The face count the file itself states, or -1 when it cannot be told cheaply.
long stated_face_count(const std::string &path, const std::string &ext) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return -1;
  if (ext == ".stl") {
    in.seekg(0, std::ios::end);
    const long size = static_cast<long>(in.tellg());
    in.seekg(80);
    unsigned char n[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char *>(n), 4);
    const long count = n[0] | (n[1] << 8) | (n[2] << 16) | (static_cast<long>(n[3]) << 24);
    if (in && size == 84 + 50 * count) return count;  // binary
    in.clear();
    in.seekg(0);
    long facets = 0;
    std::string w;
    while (in >> w)
      if (w == "facet") ++facets;
    return facets;
  }
  std::string line;
  if (ext == ".ply") {
    while (std::getline(in, line)) {
      std::vector<std::string_view> w = words(line);
      if (w.size() == 3 && w[0] == "element" && w[1] == "face") {
        long n = 0;
        return parse_int(w[2], &n) ? n : -1;
      }
      if (!w.empty() && w[0] == "end_header") break;
    }
    return 0;
  }
  // OFF: [ST][C][N][4][n]OFF [BINARY], then "nv nf ne", comments with '#'.
  std::vector<std::string_view> counts;
  std::vector<std::string> keep;
  bool header = false;
  while (counts.size() < 2 && std::getline(in, line)) {
    line = line.substr(0, line.find('#'));
    keep.push_back(line);
    std::vector<std::string_view> w = words(keep.back());
    size_t i = 0;
    if (!header && !w.empty()) {
      header = true;
      if (w[0].size() >= 3 && w[0].substr(w[0].size() - 3) == "OFF") {
        if (w.size() > 1 && w[1] == "BINARY") return -1;
        i = 1;
      }
    }
    for (; i < w.size(); ++i) counts.push_back(w[i]);
  }
  long nf = 0;
  return counts.size() >= 2 && parse_int(counts[1], &nf) ? nf : -1;
}

Expected<Scene> read_single(const std::string &path, const std::string &ext) {
  OmMesh mesh;
  mesh.request_face_status();
  mesh.request_vertex_colors();
  mesh.request_vertex_texcoords2D();
  OpenMesh::IO::Options opt;
  if (ext != ".stl") {
    opt += OpenMesh::IO::Options::VertexColor;
    opt += OpenMesh::IO::Options::VertexTexCoord;
  }
  OmCapture capture;
  bool ok = false;
  try {
    ok = OpenMesh::IO::read_mesh(mesh, path, opt);
  } catch (const std::exception &e) {
    return Status::error(path + ": OpenMesh failed: " + e.what());
  }
  if (!ok) return Status::error(path + ": OpenMesh could not read the file" + capture.suffix());
  const long stated = stated_face_count(path, ext);
  if (stated >= 0 && static_cast<long>(mesh.n_faces()) != stated)
    return Status::error(path + ": OpenMesh kept " + std::to_string(mesh.n_faces()) + " of the " +
                         std::to_string(stated) + " faces the file holds" + capture.suffix());
  if (mesh.n_faces() == 0) return Status::error(path + ": no faces");

  Part part;
  const int nv = static_cast<int>(mesh.n_vertices());
  part.V.resize(nv, 3);
  for (OmMesh::VertexHandle vh : mesh.vertices()) {
    const OmMesh::Point p = mesh.point(vh);
    part.V.row(vh.idx()) << p[0], p[1], p[2];
  }
  // STL holds loose triangles, which OpenMesh joins at equal positions. Two
  // closed surfaces that touch (teeth rows) then share vertices and edges,
  // and OpenMesh holds some of their faces only on copies of their corners,
  // cut off from their neighbours. So for STL the copies go back to the
  // vertex at their position, and the surfaces are taken apart again
  // (split_touching_surfaces, core/repair.h), with a note. Other formats number their
  // vertices: such a face is an error there.
  const bool stl = ext == ".stl";
  std::vector<int> canonical(static_cast<size_t>(nv));
  int rewelded = 0;
  if (stl) {
    std::map<std::array<double, 3>, int> at;
    for (int v = 0; v < nv; ++v) {
      const auto [it, fresh] = at.insert({{part.V(v, 0), part.V(v, 1), part.V(v, 2)}, v});
      canonical[static_cast<size_t>(v)] = it->second;
      if (!fresh) ++rewelded;
    }
  }
  int ntri = 0;
  for (OmMesh::FaceHandle fh : mesh.faces()) {
    if (mesh.status(fh).fixed_nonmanifold() && !stl)
      return Status::error(path + ": face " + std::to_string(fh.idx()) +
                           " is not manifold (an edge in three faces, an edge used twice in the "
                           "same direction, or a vertex joining two fans): OpenMesh can only hold "
                           "it split off from its neighbours");
    ntri += static_cast<int>(mesh.valence(fh)) - 2;
  }
  part.F.resize(ntri, 3);
  int row = 0;
  for (OmMesh::FaceHandle fh : mesh.faces()) {
    std::vector<int> v;
    for (OmMesh::VertexHandle vh : mesh.fv_range(fh))
      v.push_back(stl ? canonical[static_cast<size_t>(vh.idx())] : vh.idx());
    for (size_t c = 1; c + 1 < v.size(); ++c, ++row) part.F.row(row) << v[0], v[c], v[c + 1];
  }
  std::string stl_note;
  if (stl && rewelded > 0) {
    // Drop the copies: an STL has no vertex numbers to keep.
    std::vector<int> keep(static_cast<size_t>(nv), -1);
    int kept = 0;
    for (int v = 0; v < nv; ++v)
      if (canonical[static_cast<size_t>(v)] == v) keep[static_cast<size_t>(v)] = kept++;
    Eigen::MatrixXd V(kept, 3);
    for (int v = 0; v < nv; ++v)
      if (keep[static_cast<size_t>(v)] >= 0) V.row(keep[static_cast<size_t>(v)]) = part.V.row(v);
    for (Eigen::Index t = 0; t < part.F.rows(); ++t)
      for (int c = 0; c < 3; ++c) part.F(t, c) = keep[static_cast<size_t>(part.F(t, c))];
    part.V = std::move(V);
  }
  if (stl)
    if (const int split = split_touching_surfaces(part.V, part.F); split > 0)
      stl_note = path + ": " + std::to_string(split) + (split == 1 ? " vertex joins" : " vertices join") +
                 " closed surfaces that touch (as teeth rows do): split, one per surface";
  part.C.resize(0, 3);
  if (opt.vertex_has_color()) {
    part.C.resize(nv, 3);
    for (OmMesh::VertexHandle vh : mesh.vertices()) {
      const OmMesh::Color c = mesh.color(vh);
      part.C.row(vh.idx()) << c[0] / 255.0, c[1] / 255.0, c[2] / 255.0;
    }
  }
  part.TC.resize(0, 2);
  part.FTC.resize(0, 3);
  if (opt.vertex_has_texcoord()) {
    part.TC.resize(nv, 2);
    for (OmMesh::VertexHandle vh : mesh.vertices()) {
      const OmMesh::TexCoord2D t = mesh.texcoord2D(vh);
      part.TC.row(vh.idx()) << t[0], t[1];
    }
    part.FTC = part.F;
  }
  Scene scene;
  scene.name = stem(path);
  scene.source = path;
  part.name = scene.name;
  part.kind = guess_part_kind(part);
  scene.parts.push_back(std::move(part));
  if (!stl_note.empty()) scene.notes.push_back(stl_note);
  return scene;
}

void put_number(std::string &out, double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

}  // namespace

Expected<Scene> read_scene(const std::string &path) {
  const std::string ext = extension(path);
  const bool known = ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl" ||
                     ext == ".wrl" || ext == ".vrml";
  if (!known)
    return Status::error(path + ": unknown mesh format '" + ext +
                         "' (expected .obj, .ply, .off, .stl, .wrl or .vrml)");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) return Status::error(path + ": cannot open: " + std::strerror(errno));
  }
  if (ext == ".wrl" || ext == ".vrml") return read_vrml(path);
  if (ext == ".obj") return read_obj(path);
  return read_single(path, ext);
}

namespace {

// A part's name as a single OBJ/MTL line's rest.
std::string line_name(const Part &p) {
  std::string name = p.name.empty() ? std::string("part") : p.name;
  std::replace(name.begin(), name.end(), '\n', '_');
  std::replace(name.begin(), name.end(), '\r', '_');
  return name;
}

}  // namespace

Status write_mtl(const Scene &scene, const std::string &path) {
  std::string out = "# materials of " + (scene.name.empty() ? std::string("the scene") : scene.name) + "\n";
  for (const Part &p : scene.parts) {
    out += "newmtl " + line_name(p) + "\nKd";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      put_number(out, p.diffuse[k]);
    }
    out += '\n';
    if (!p.texture.empty()) out += "map_Kd " + p.texture + "\n";
  }
  return write_file_atomic(path, out);
}

Status write_obj(const Scene &scene, const std::string &path, const std::string &mtllib) {
  std::string out;
  out.reserve(64 + scene.vertex_count() * 40 + scene.triangle_count() * 30);
  if (!scene.name.empty()) out += "# " + scene.name + "\n";
  if (!mtllib.empty()) out += "mtllib " + mtllib + "\n";
  long vbase = 1, tbase = 1;
  for (const Part &p : scene.parts) {
    if (p.V.cols() != 3 || p.F.cols() != 3 || (p.TC.rows() > 0 && p.FTC.rows() != p.F.rows()))
      return Status::error(path + ": part '" + p.name + "' has malformed matrices");
    const std::string name = line_name(p);
    out += "o " + name + "\n";
    if (!mtllib.empty()) out += "usemtl " + name + "\n";
    for (Eigen::Index i = 0; i < p.V.rows(); ++i) {
      out += "v";
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        put_number(out, p.V(i, k));
      }
      out += '\n';
    }
    const bool tc = p.TC.rows() > 0;
    for (Eigen::Index i = 0; tc && i < p.TC.rows(); ++i) {
      out += "vt ";
      put_number(out, p.TC(i, 0));
      out += ' ';
      put_number(out, p.TC(i, 1));
      out += '\n';
    }
    for (Eigen::Index i = 0; i < p.F.rows(); ++i) {
      out += "f";
      for (int k = 0; k < 3; ++k) {
        out += ' ' + std::to_string(vbase + p.F(i, k));
        if (tc) out += '/' + std::to_string(tbase + p.FTC(i, k));
      }
      out += '\n';
    }
    vbase += p.V.rows();
    tbase += p.TC.rows();
  }
  return write_file_atomic(path, out);
}

}  // namespace afmb
