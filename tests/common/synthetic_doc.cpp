#include "synthetic_doc.h"

#include <afm/draco.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace afmtest {

namespace {

int16_t q(double x) { return static_cast<int16_t>(std::lround(std::clamp(x, -32767.0, 32767.0))); }

// A target entry: its index (vertex, or V + control) and where the field is
// sampled.
struct Entry {
  uint32_t index;
  double x, y, z;
};

void add_target(SyntheticDoc &s, uint8_t kind, uint8_t number, int32_t reference, bool normals,
                double (*field)(double, double, double, int), const std::vector<Entry> &entries) {
  SyntheticDoc::Target t;
  // Runs over entries where the field is nonzero.
  for (const Entry &e : entries) {
    const uint32_t i = e.index;
    double x = e.x, y = e.y, z = e.z;
    int16_t d[3] = {q(field(x, y, z, 0)), q(field(x, y, z, 1)), q(field(x, y, z, 2))};
    if (d[0] == 0 && d[1] == 0 && d[2] == 0) continue;
    if (!t.runs.empty() && t.runs.back().start + t.runs.back().length == i) {
      t.runs.back().length++;
    } else {
      t.runs.push_back({static_cast<uint32_t>(i), 1});
    }
    t.dx.push_back(d[0]);
    t.dy.push_back(d[1]);
    t.dz.push_back(d[2]);
    if (normals) {
      t.nx.push_back(q(d[0] * 0.5));
      t.ny.push_back(q(-d[1] * 0.25));
      t.nz.push_back(q(d[2] * 0.125));
    }
  }
  s.target_data.push_back(std::move(t));
  afm_target at{};
  at.kind = kind;
  at.number = number;
  at.flags = normals ? AFM_TARGET_NORMALS : 0;
  at.reference = reference;
  s.targets.push_back(at);
}

// Analytic displacement fields in position quanta.
double jaw_field(double, double y, double, int c) {
  return (y < -4000 && c == 1) ? -(y + 4000) * 0.2 : 0.0;
}
double smile_field(double x, double y, double, int c) {
  double r2 = ((x - 6000) * (x - 6000) + (y + 2000) * (y + 2000)) / 4.0e6;
  double w = r2 < 1 ? (1 - r2) * (1 - r2) : 0;
  return w * (c == 0 ? 600 : c == 1 ? 900 : -150);
}
double brow_field(double x, double y, double, int c) {
  double r2 = (x * x + (y - 9000) * (y - 9000)) / 9.0e6;
  return (r2 < 1 && c == 1) ? 700 * (1 - r2) : 0.0;
}

}  // namespace

const afm_doc *make_synthetic_doc(SyntheticDoc &s, const SyntheticOptions &o) {
  s = SyntheticDoc();
  const int R = o.rows, C = o.cols;
  // Skin: an open ellipsoid patch, rows bottom to top, front half.
  for (int r = 0; r < R; ++r) {
    for (int c = 0; c < C; ++c) {
      double th = -1.2 + 2.4 * r / (R - 1), ph = -1.3 + 2.6 * c / (C - 1);
      double x = std::sin(ph) * std::cos(th), y = std::sin(th), z = std::cos(ph) * std::cos(th);
      s.px.push_back(q(12000 * x));
      s.py.push_back(q(16000 * y));
      s.pz.push_back(q(13000 * z));
      s.nx.push_back(q(16384 * x));
      s.ny.push_back(q(16384 * y));
      s.nz.push_back(q(16384 * z));
      s.u.push_back(static_cast<uint16_t>(65535.0 * c / (C - 1)));
      s.v.push_back(static_cast<uint16_t>(65535.0 * r / (R - 1)));
      uint8_t col[4] = {static_cast<uint8_t>(200 + r % 50), static_cast<uint8_t>(150 + c % 80), 120, 255};
      s.rgba.insert(s.rgba.end(), col, col + 4);
    }
  }
  for (int r = 0; r + 1 < R; ++r)
    for (int c = 0; c + 1 < C; ++c) {
      uint32_t a = r * C + c, b = a + 1, d = a + C, e = d + 1;
      s.tris.insert(s.tris.end(), {a, b, e, a, e, d});
    }
  if (o.loose_vertex) {
    std::vector<uint32_t> kept;
    for (size_t t = 0; t < s.tris.size(); t += 3)
      if (s.tris[t] != 7 && s.tris[t + 1] != 7 && s.tris[t + 2] != 7)
        kept.insert(kept.end(), &s.tris[t], &s.tris[t + 3]);
    s.tris = kept;
  }
  const uint32_t skin_v = R * C, skin_t = static_cast<uint32_t>(s.tris.size() / 3);
  // Eye: a closed octahedron-subdivided sphere would be nicer; a small UV
  // sphere with poles is enough and has a closed surface.
  const int er = 6, ec = 8;
  uint32_t base = skin_v;
  s.px.push_back(4000), s.py.push_back(6000), s.pz.push_back(12000 + 1500);  // front pole
  for (int r = 1; r < er; ++r)
    for (int c = 0; c < ec; ++c) {
      double th = M_PI * r / er, ph = 2 * M_PI * c / ec;
      s.px.push_back(q(4000 + 1500 * std::sin(th) * std::cos(ph)));
      s.py.push_back(q(6000 + 1500 * std::sin(th) * std::sin(ph)));
      s.pz.push_back(q(12000 + 1500 * std::cos(th)));
    }
  s.px.push_back(4000), s.py.push_back(6000), s.pz.push_back(12000 - 1500);  // back pole
  const uint32_t eye_v = static_cast<uint32_t>(s.px.size()) - base;
  for (uint32_t i = skin_v; i < skin_v + eye_v; ++i) {
    s.nx.push_back(0), s.ny.push_back(0), s.nz.push_back(16384);
    s.u.push_back(static_cast<uint16_t>(i * 97)), s.v.push_back(static_cast<uint16_t>(i * 31));
    s.rgba.insert(s.rgba.end(), {250, 250, 250, 255});
  }
  auto ring = [&](int r, int c) { return base + 1 + (r - 1) * ec + (c % ec); };
  for (int c = 0; c < ec; ++c) s.tris.insert(s.tris.end(), {base, ring(1, c), ring(1, c + 1)});
  for (int r = 1; r + 1 < er; ++r)
    for (int c = 0; c < ec; ++c)
      s.tris.insert(s.tris.end(), {ring(r, c), ring(r + 1, c), ring(r + 1, c + 1), ring(r, c),
                                   ring(r + 1, c + 1), ring(r, c + 1)});
  uint32_t back = base + eye_v - 1;
  for (int c = 0; c < ec; ++c)
    s.tris.insert(s.tris.end(), {back, ring(er - 1, c + 1), ring(er - 1, c)});
  const uint32_t eye_t = static_cast<uint32_t>(s.tris.size() / 3) - skin_t;

  afm_part ranges[2]{};
  ranges[0].triangle_count = skin_t;
  ranges[1].first_triangle = skin_t, ranges[1].triangle_count = eye_t;
  afm_canonicalize_triangles(s.tris.data(), ranges, 2);
  if (o.shuffle_triangles) {
    // Deterministic rotation of corners and a reversal of the skin's order.
    for (size_t t = 0; t < skin_t; t += 3) std::rotate(&s.tris[3 * t], &s.tris[3 * t + 1], &s.tris[3 * t + 3]);
    for (size_t t = 0; t < skin_t / 2; ++t)
      std::swap_ranges(&s.tris[3 * t], &s.tris[3 * t + 3], &s.tris[3 * (skin_t - 1 - t)]);
  }

  afm_part skin{};
  skin.name = "skin";
  skin.texture = "skin.png";
  skin.kind = AFM_PART_SKIN;
  skin.diffuse[0] = 230, skin.diffuse[1] = 180, skin.diffuse[2] = 150, skin.diffuse[3] = 255;
  skin.first_vertex = 0, skin.vertex_count = skin_v, skin.first_triangle = 0, skin.triangle_count = skin_t;
  afm_part eye{};
  eye.name = "eye_left";
  eye.texture = "";
  eye.kind = AFM_PART_EYE_LEFT;
  eye.diffuse[0] = eye.diffuse[1] = eye.diffuse[2] = eye.diffuse[3] = 255;
  eye.first_vertex = skin_v, eye.vertex_count = eye_v, eye.first_triangle = skin_t, eye.triangle_count = eye_t;
  s.parts = {skin, eye};

  const size_t V = s.px.size();
  std::vector<Entry> entries;
  const bool normal_deltas = o.normal_deltas && !o.lift;
  if (!o.lift) {
    for (uint32_t i = 0; i < V; ++i) entries.push_back({i, double(s.px[i]), double(s.py[i]), double(s.pz[i])});
  } else {
    // Controls: skin rows and columns 0, 2, 4, ... (their positions sample
    // the fields); skin vertex (r, c) binds to the coarse cell around it,
    // split as the skin's cells are (a b e / a e d), clamped at the far edges.
    const int CR = (R + 1) / 2, CC = (C + 1) / 2;
    auto control = [&](int cr, int cc) { return uint32_t(cr * CC + cc); };
    for (uint32_t i = skin_v; i < V; ++i) entries.push_back({i, double(s.px[i]), double(s.py[i]), double(s.pz[i])});
    for (int cr = 0; cr < CR; ++cr)
      for (int cc = 0; cc < CC; ++cc) {
        const size_t f = size_t(2 * cr) * C + size_t(2 * cc);
        entries.push_back({uint32_t(V) + control(cr, cc), double(s.px[f]), double(s.py[f]), double(s.pz[f])});
      }
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c) {
        const int cr = std::min(r / 2, CR - 2), cc = std::min(c / 2, CC - 2);
        const double v = std::min(1.0, (r - 2 * cr) / 2.0), u = std::min(1.0, (c - 2 * cc) / 2.0);
        const uint32_t a = control(cr, cc), b = control(cr, cc + 1), d = control(cr + 1, cc),
                       e = control(cr + 1, cc + 1);
        uint32_t corner[3];
        double w[3];
        if (u >= v) {
          corner[0] = a, corner[1] = b, corner[2] = e, w[1] = u - v, w[2] = v;
        } else {
          corner[0] = a, corner[1] = e, corner[2] = d, w[1] = u, w[2] = v - u;
        }
        for (int k = 0; k < 3; ++k) s.lift_c[k].push_back(corner[k]);
        for (int k = 0; k < 2; ++k) s.lift_w[k].push_back(uint16_t(std::lround(w[k + 1] * 32768)));
      }
    s.lift_runs = {{0, skin_v}};
    afm_lift &l = s.lift;
    l.control_count = uint32_t(CR * CC);
    l.run_count = 1;
    l.runs = s.lift_runs.data();
    l.bound_count = skin_v;
    l.c0 = s.lift_c[0].data(), l.c1 = s.lift_c[1].data(), l.c2 = s.lift_c[2].data();
    l.w1 = s.lift_w[0].data(), l.w2 = s.lift_w[1].data();
  }
  add_target(s, AFM_TARGET_FAP, 3, 1024, normal_deltas, jaw_field, entries);
  add_target(s, AFM_TARGET_FAP, 12, 512, false, smile_field, entries);
  add_target(s, AFM_TARGET_FAP, 31, 256, normal_deltas, brow_field, entries);
  add_target(s, AFM_TARGET_FAP, 31, -256, false, smile_field, entries);  // negative side of FAP 31
  add_target(s, AFM_TARGET_VISEME, 1, 63, false, jaw_field, entries);
  add_target(s, AFM_TARGET_EXPRESSION, 1, 63, false, smile_field, entries);
  if (o.in_betweens) {
    // Farther targets on FAP 12's positive side and FAP 31's negative one,
    // out of order on purpose (the player sorts them by |reference|).
    add_target(s, AFM_TARGET_FAP, 12, 1800, false, brow_field, entries);
    add_target(s, AFM_TARGET_FAP, 12, 1024, normal_deltas, jaw_field, entries);
    add_target(s, AFM_TARGET_FAP, 31, -700, false, jaw_field, entries);
    if (o.combination) {
      add_target(s, AFM_TARGET_COMBINATION, 31, -700, false, brow_field, entries);
      s.targets.back().gate = 3;
      s.targets.back().gate_reference = 1024;
    }
  }
  for (size_t i = 0; i < s.targets.size(); ++i) {
    SyntheticDoc::Target &t = s.target_data[i];
    afm_target &at = s.targets[i];
    at.run_count = static_cast<uint32_t>(t.runs.size());
    at.runs = t.runs.data();
    at.delta_count = static_cast<uint32_t>(t.dx.size());
    at.dx = t.dx.data(), at.dy = t.dy.data(), at.dz = t.dz.data();
    if (at.flags & AFM_TARGET_NORMALS) at.nx = t.nx.data(), at.ny = t.ny.data(), at.nz = t.nz.data();
  }

  s.rigid_parts = {1, 0, 1};
  s.controls = {{23, AFM_DOF_ROTATE_Y, 1 << 16, 0}, {25, AFM_DOF_ROTATE_X, 1 << 16, 0},
                {27, AFM_DOF_TRANSLATE_Z, 3 << 15, 0}};
  if (o.in_betweens) {
    // Knots (version 1.3): the yaw half as steep past 20000, the pitch
    // twice as steep below -15000.
    s.controls.push_back({23, AFM_DOF_ROTATE_Y, -(1 << 15), 20000});
    s.controls.push_back({25, AFM_DOF_ROTATE_X, 1 << 16, -15000});
  }
  s.controls.push_back({48, AFM_DOF_ROTATE_X, 1 << 16, 0});
  afm_rigid eye_rig{};
  eye_rig.kind = AFM_RIGID_EYE_LEFT;
  eye_rig.pivot[0] = 4000, eye_rig.pivot[1] = 6000, eye_rig.pivot[2] = 12000;
  eye_rig.axes[0] = eye_rig.axes[4] = eye_rig.axes[8] = 16384;
  eye_rig.part_count = 1, eye_rig.parts = &s.rigid_parts[0];
  eye_rig.control_count = static_cast<uint16_t>(s.controls.size() - 1), eye_rig.controls = &s.controls[0];
  afm_rigid head{};
  head.kind = AFM_RIGID_HEAD;
  head.pivot[1] = -20000;
  head.axes[0] = head.axes[4] = head.axes[8] = 16384;
  head.part_count = 2, head.parts = &s.rigid_parts[1];
  head.control_count = 1, head.controls = &s.controls.back();
  s.rigids = {eye_rig, head};

  s.fdps = {{2, 1, 0, {0.0f, -0.12f, 0.05f}}, {3, 5, skin_v, {0.04f, 0.06f, 0.135f}},
            {7, 1, AFM_NONE, {0.0f, -0.2f, -0.02f}}};

  afm_doc &d = s.doc;
  d.meta.name = "synthetic";
  d.meta.units = "m";
  d.meta.generator = "tests/formats/synthetic_doc";
  d.meta.es0 = 0.063f, d.meta.irisd0 = 0.012f, d.meta.ens0 = 0.035f, d.meta.mns0 = 0.018f,
  d.meta.mw0 = 0.05f;
  d.meta.fdp_count = static_cast<uint32_t>(s.fdps.size());
  d.meta.fdps = s.fdps.data();
  afm_geometry &g = d.geometry;
  g.vertex_count = static_cast<uint32_t>(V);
  g.triangle_count = static_cast<uint32_t>(s.tris.size() / 3);
  g.part_count = 2;
  g.attributes = (o.normals ? AFM_ATTR_NORMALS : 0) | (o.texcoords ? AFM_ATTR_TEXCOORDS : 0) |
                 (o.colors ? AFM_ATTR_COLORS : 0);
  g.origin[0] = 0.0f, g.origin[1] = 0.01f, g.origin[2] = -0.02f;
  g.step = 1.0e-5f;
  g.uv_origin[0] = g.uv_origin[1] = 0.0f;
  g.uv_step[0] = g.uv_step[1] = 1.0f / 65535.0f;
  g.parts = s.parts.data();
  g.px = s.px.data(), g.py = s.py.data(), g.pz = s.pz.data();
  if (o.normals) g.nx = s.nx.data(), g.ny = s.ny.data(), g.nz = s.nz.data();
  if (o.texcoords) g.u = s.u.data(), g.v = s.v.data();
  if (o.colors) g.rgba = s.rgba.data();
  g.triangles = s.tris.data();
  d.target_count = static_cast<uint32_t>(s.targets.size());
  d.targets = s.targets.data();
  d.rigid_count = static_cast<uint32_t>(s.rigids.size());
  d.rigids = s.rigids.data();
  if (o.lift) d.lift = &s.lift;
  return &s.doc;
}

std::vector<uint8_t> write_doc(const afm_doc &doc, afm_profile profile) {
  afm_write_options wo{};
  afm_diag diag{};
  wo.profile = profile;
  wo.draco = afm_draco_codec();
  wo.diag = &diag;
  uint8_t *out = nullptr;
  size_t size = 0;
  afm_result r = afm_doc_write(&doc, &wo, &out, &size);
  EXPECT_EQ(r, AFM_OK) << afm_result_string(r) << ": " << diag.message;
  std::vector<uint8_t> bytes(out, out + size);
  afm_free(nullptr, out);
  return bytes;
}

namespace {
template <class T>
bool same(const T *a, const T *b, size_t n) {
  if (!a || !b) return a == b || n == 0;
  return std::equal(a, a + n, b);
}
}  // namespace

std::string compare_docs(const afm_doc &a, const afm_doc &b) {
  std::ostringstream d;
  const afm_meta &ma = a.meta, &mb = b.meta;
  if (std::strcmp(ma.name, mb.name) || std::strcmp(ma.units, mb.units) ||
      std::strcmp(ma.generator, mb.generator))
    return "meta strings";
  if (ma.es0 != mb.es0 || ma.irisd0 != mb.irisd0 || ma.ens0 != mb.ens0 || ma.mns0 != mb.mns0 ||
      ma.mw0 != mb.mw0)
    return "fapu";
  if (ma.fdp_count != mb.fdp_count) return "fdp_count";
  for (uint32_t i = 0; i < ma.fdp_count; ++i)
    if (ma.fdps[i].group != mb.fdps[i].group || ma.fdps[i].index != mb.fdps[i].index ||
        ma.fdps[i].vertex != mb.fdps[i].vertex || !same(ma.fdps[i].pos, mb.fdps[i].pos, 3))
      return "fdp " + std::to_string(i);
  const afm_geometry &ga = a.geometry, &gb = b.geometry;
  size_t V = ga.vertex_count;
  if (ga.vertex_count != gb.vertex_count || ga.triangle_count != gb.triangle_count ||
      ga.part_count != gb.part_count || ga.attributes != gb.attributes)
    return "geometry counts";
  if (!same(ga.origin, gb.origin, 3) || ga.step != gb.step || !same(ga.uv_origin, gb.uv_origin, 2) ||
      !same(ga.uv_step, gb.uv_step, 2))
    return "quantisation";
  for (uint32_t p = 0; p < ga.part_count; ++p) {
    const afm_part &x = ga.parts[p], &y = gb.parts[p];
    if (std::strcmp(x.name, y.name) || std::strcmp(x.texture, y.texture) || x.kind != y.kind ||
        !same(x.diffuse, y.diffuse, 4) || x.first_vertex != y.first_vertex ||
        x.vertex_count != y.vertex_count || x.first_triangle != y.first_triangle ||
        x.triangle_count != y.triangle_count)
      return "part " + std::to_string(p);
  }
  if (!same(ga.px, gb.px, V) || !same(ga.py, gb.py, V) || !same(ga.pz, gb.pz, V)) return "positions";
  if (!same(ga.nx, gb.nx, V) || !same(ga.ny, gb.ny, V) || !same(ga.nz, gb.nz, V)) return "normals";
  if (!same(ga.u, gb.u, V) || !same(ga.v, gb.v, V)) return "texcoords";
  if (!same(ga.rgba, gb.rgba, 4 * V)) return "colors";
  if (!same(ga.triangles, gb.triangles, 3 * size_t(ga.triangle_count))) return "triangles";
  if (a.target_count != b.target_count) return "target_count";
  for (uint32_t i = 0; i < a.target_count; ++i) {
    const afm_target &x = a.targets[i], &y = b.targets[i];
    size_t n = x.delta_count;
    if (x.kind != y.kind || x.number != y.number || x.flags != y.flags ||
        x.reference != y.reference || x.gate != y.gate || x.gate_reference != y.gate_reference ||
        x.run_count != y.run_count || x.delta_count != y.delta_count)
      return "target header " + std::to_string(i);
    for (uint32_t k = 0; k < x.run_count; ++k)
      if (x.runs[k].start != y.runs[k].start || x.runs[k].length != y.runs[k].length)
        return "target runs " + std::to_string(i);
    if (!same(x.dx, y.dx, n) || !same(x.dy, y.dy, n) || !same(x.dz, y.dz, n))
      return "target deltas " + std::to_string(i);
    if (!same(x.nx, y.nx, n) || !same(x.ny, y.ny, n) || !same(x.nz, y.nz, n))
      return "target normal deltas " + std::to_string(i);
  }
  if (!a.lift != !b.lift) return "lift presence";
  if (a.lift) {
    const afm_lift &x = *a.lift, &y = *b.lift;
    const size_t n = x.bound_count;
    if (x.control_count != y.control_count || x.run_count != y.run_count || x.bound_count != y.bound_count)
      return "lift counts";
    for (uint32_t k = 0; k < x.run_count; ++k)
      if (x.runs[k].start != y.runs[k].start || x.runs[k].length != y.runs[k].length) return "lift runs";
    if (!same(x.c0, y.c0, n) || !same(x.c1, y.c1, n) || !same(x.c2, y.c2, n)) return "lift controls";
    if (!same(x.w1, y.w1, n) || !same(x.w2, y.w2, n)) return "lift weights";
  }
  if (a.rigid_count != b.rigid_count) return "rigid_count";
  for (uint32_t i = 0; i < a.rigid_count; ++i) {
    const afm_rigid &x = a.rigids[i], &y = b.rigids[i];
    if (x.kind != y.kind || !same(x.pivot, y.pivot, 3) || !same(x.axes, y.axes, 9) ||
        x.part_count != y.part_count || !same(x.parts, y.parts, x.part_count) ||
        x.control_count != y.control_count)
      return "rigid " + std::to_string(i);
    for (uint32_t k = 0; k < x.control_count; ++k)
      if (x.controls[k].fap != y.controls[k].fap || x.controls[k].dof != y.controls[k].dof ||
          x.controls[k].gain_q16 != y.controls[k].gain_q16 || x.controls[k].knot != y.controls[k].knot)
        return "rigid control " + std::to_string(i);
  }
  return d.str();
}

}  // namespace afmtest
