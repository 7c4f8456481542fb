#include "reference_player.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <tuple>

namespace afmtest {

namespace {

struct Lookup {
  // (FAP, positive side?) -> (|reference|, target), nearest zero first.
  std::map<std::pair<int, bool>, std::map<double, int>> fap;
  std::map<int, int> viseme, expression;
};

Lookup make_lookup(const afm_doc &doc) {
  Lookup l;
  for (uint32_t i = 0; i < doc.target_count; ++i) {
    const afm_target &t = doc.targets[i];
    if (t.kind == AFM_TARGET_FAP) l.fap[{t.number, t.reference > 0}][std::fabs(double(t.reference))] = int(i);
    if (t.kind == AFM_TARGET_VISEME) l.viseme.insert({t.number, int(i)});
    if (t.kind == AFM_TARGET_EXPRESSION) l.expression.insert({t.number, int(i)});
  }
  return l;
}

// formats/afm.md: the face is piecewise linear in the value between a
// side's references (0 at 0), the last segment extrapolated; a negative
// value without targets of its own extrapolates the positive side's first.
std::vector<double> weights_of(const afm_doc &doc, const Lookup &l, const afm_fap_state &s) {
  std::vector<double> w(doc.target_count, 0.0);
  for (int f = 3; f <= AFM_FAP_COUNT; ++f) {
    const double v = s.value[f];
    if (v == 0) continue;
    auto side = v < 0 ? l.fap.find({f, false}) : l.fap.end();
    if (side == l.fap.end()) side = l.fap.find({f, true});
    if (side == l.fap.end()) continue;
    const std::map<double, int> &chain = side->second;
    const double sense = side->first.second ? 1.0 : -1.0, x = sense * v;  // x: along the side
    double x0 = 0;
    int t0 = -1;
    auto it = chain.begin();
    while (std::next(it) != chain.end() && x > it->first) {
      x0 = it->first, t0 = it->second;
      ++it;
    }
    const double u = (x - x0) / (it->first - x0);
    w[size_t(it->second)] += u;
    if (t0 >= 0) w[size_t(t0)] += 1 - u;
  }
  auto add = [&](const std::map<int, int> &m, int number, double amount) {
    auto it = m.find(number);
    if (it != m.end() && amount) w[size_t(it->second)] += amount;
  };
  add(l.viseme, s.viseme.select1, s.viseme.blend / 63.0);
  add(l.viseme, s.viseme.select2, (63 - s.viseme.blend) / 63.0);
  add(l.expression, s.expression.select1, s.expression.intensity1 / 63.0);
  add(l.expression, s.expression.select2, s.expression.intensity2 / 63.0);
  // Combinations: the followed FAP target's weight, capped by the gate's
  // value / gate reference, never below 0.
  for (uint32_t i = 0; i < doc.target_count; ++i) {
    const afm_target &t = doc.targets[i];
    if (t.kind != AFM_TARGET_COMBINATION) continue;
    for (uint32_t j = 0; j < doc.target_count; ++j) {
      const afm_target &f = doc.targets[j];
      if (f.kind != AFM_TARGET_FAP || f.number != t.number || f.reference != t.reference) continue;
      const double gate = double(s.value[t.gate]) / t.gate_reference;
      w[i] += std::max(0.0, std::min(w[j], gate));
    }
  }
  return w;
}

using Mat = std::array<double, 9>;

Mat mul(const Mat &a, const Mat &b) {
  Mat c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return c;
}

Mat axis_rotation(int axis, double angle) {
  double s = std::sin(angle), c = std::cos(angle);
  Mat m{1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (axis == 0) m[4] = c, m[5] = -s, m[7] = s, m[8] = c;
  if (axis == 1) m[0] = c, m[2] = s, m[6] = -s, m[8] = c;
  if (axis == 2) m[0] = c, m[1] = -s, m[3] = s, m[4] = c;
  return m;
}

}  // namespace

ReferencePose reference_pose(const afm_doc &doc, const afm_fap_state &a, const afm_fap_state &b,
                             double t) {
  const afm_geometry &g = doc.geometry;
  const size_t V = g.vertex_count;
  const Lookup lookup = make_lookup(doc);
  ReferencePose out;
  std::vector<double> wa = weights_of(doc, lookup, a), wb = weights_of(doc, lookup, b);
  out.weights.resize(doc.target_count);
  for (size_t i = 0; i < wa.size(); ++i) out.weights[i] = wa[i] + (wb[i] - wa[i]) * t;

  out.positions.resize(V);
  for (size_t v = 0; v < V; ++v) out.positions[v] = {double(g.px[v]), double(g.py[v]), double(g.pz[v])};
  std::vector<char> moved(V, 0);
  for (uint32_t i = 0; i < doc.target_count; ++i) {
    const afm_target &tg = doc.targets[i];
    double w = out.weights[i];
    // The player rounds weights to Q12: a weight that rounds to 0 moves nothing.
    if (std::fabs(w) * 4096 < 0.5) continue;
    // The target's deltas over every entry: vertices, then the LIFT's
    // control points (formats/afm.md), which move their bound vertices by
    // (w0 d0 + w1 d1 + w2 d2) / 32768.
    const size_t C = doc.lift ? doc.lift->control_count : 0;
    std::vector<std::array<double, 3>> d(V + C, {0, 0, 0});
    std::vector<char> has(V + C, 0);
    uint32_t k = 0;
    for (uint32_t r = 0; r < tg.run_count; ++r)
      for (uint32_t j = 0; j < tg.runs[r].length; ++j, ++k) {
        size_t e = tg.runs[r].start + j;
        d[e] = {double(tg.dx[k]), double(tg.dy[k]), double(tg.dz[k])};
        has[e] = 1;
      }
    if (doc.lift) {
      const afm_lift &l = *doc.lift;
      bool any_control = false;
      for (size_t c = 0; c < C; ++c) any_control |= has[V + c] != 0;
      uint32_t bv = 0;  // bound vertex
      for (uint32_t r = 0; r < l.run_count && any_control; ++r)
        for (uint32_t j = 0; j < l.runs[r].length; ++j, ++bv) {
          const size_t v = l.runs[r].start + j;
          const double wt[3] = {(32768.0 - l.w1[bv] - l.w2[bv]) / 32768.0, l.w1[bv] / 32768.0, l.w2[bv] / 32768.0};
          const uint32_t c[3] = {l.c0[bv], l.c1[bv], l.c2[bv]};
          for (size_t x = 0; x < 3; ++x)
            d[v][x] = wt[0] * d[V + c[0]][x] + wt[1] * d[V + c[1]][x] + wt[2] * d[V + c[2]][x];
          has[v] = 1;
        }
    }
    for (size_t v = 0; v < V; ++v) {
      if (!has[v]) continue;
      for (size_t x = 0; x < 3; ++x) out.positions[v][x] += w * d[v][x];
      moved[v] = 1;
    }
  }

  // Normals: the base ones, recomputed around moved vertices over seam groups.
  out.normals.resize(V);
  for (size_t v = 0; v < V; ++v)
    out.normals[v] = g.nx ? std::array<double, 3>{g.nx[v] / 16384.0, g.ny[v] / 16384.0, g.nz[v] / 16384.0}
                          : std::array<double, 3>{0, 0, 1};
  std::map<std::tuple<uint32_t, int, int, int, int, int, int>, std::vector<uint32_t>> groups;
  std::vector<uint32_t> part_of(V);
  for (uint32_t p = 0; p < g.part_count; ++p)
    for (uint32_t v = g.parts[p].first_vertex; v < g.parts[p].first_vertex + g.parts[p].vertex_count; ++v)
      part_of[v] = p;
  std::vector<const std::vector<uint32_t> *> group_of(V);
  for (uint32_t v = 0; v < V; ++v) {
    auto key = std::make_tuple(part_of[v], g.px[v], g.py[v], g.pz[v], g.nx ? g.nx[v] : 0,
                               g.ny ? g.ny[v] : 0, g.nz ? g.nz[v] : 0);
    groups[key].push_back(v);
  }
  for (auto &[key, members] : groups)
    for (uint32_t v : members) group_of[v] = &members;
  std::vector<std::vector<uint32_t>> ring(V);
  for (uint32_t f = 0; f < g.triangle_count; ++f)
    for (int c = 0; c < 3; ++c) ring[g.triangles[3 * f + c]].push_back(f);
  out.recomputed.assign(V, 0);
  bool any_moved = false;
  for (size_t v = 0; v < V; ++v) any_moved |= moved[v] != 0;
  if (any_moved) {
    for (size_t v = 0; v < V; ++v) {
      if (!moved[v]) continue;
      for (uint32_t f : ring[v])
        for (int c = 0; c < 3; ++c)
          for (uint32_t w : *group_of[g.triangles[3 * f + c]]) out.recomputed[w] = 1;
    }
    for (size_t v = 0; v < V; ++v) {
      if (!out.recomputed[v] && !moved[v]) continue;
      out.recomputed[v] = 1;
      double n[3] = {0, 0, 0};
      for (uint32_t u : *group_of[v])
        for (uint32_t f : ring[u]) {
          const auto &p0 = out.positions[g.triangles[3 * f]], &p1 = out.positions[g.triangles[3 * f + 1]],
                     &p2 = out.positions[g.triangles[3 * f + 2]];
          double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
          double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
          n[0] += e1[1] * e2[2] - e1[2] * e2[1];
          n[1] += e1[2] * e2[0] - e1[0] * e2[2];
          n[2] += e1[0] * e2[1] - e1[1] * e2[0];
        }
      double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      out.normals[v] = len > 0 ? std::array<double, 3>{n[0] / len, n[1] / len, n[2] / len}
                               : std::array<double, 3>{0, 0, 1};
    }
  }

  // Rigid parts: jaw and eyes, then the head.
  for (int pass = 0; pass < 2; ++pass)
    for (uint32_t r = 0; r < doc.rigid_count; ++r) {
      const afm_rigid &rg = doc.rigids[r];
      if ((rg.kind == AFM_RIGID_HEAD) != (pass == 1)) continue;
      double m[6] = {0, 0, 0, 0, 0, 0};
      for (uint16_t k = 0; k < rg.control_count; ++k) {
        const afm_control &c = rg.controls[k];
        double v = a.value[c.fap] + (double(b.value[c.fap]) - a.value[c.fap]) * t;
        if (c.knot > 0) v = std::max(v - c.knot, 0.0);
        if (c.knot < 0) v = std::min(v - c.knot, 0.0);
        m[c.dof] += v * c.gain_q16 / 65536.0;
      }
      Mat A{}, At{};
      for (int i = 0; i < 9; ++i) A[size_t(i)] = rg.axes[i] / 16384.0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) At[size_t(3 * i + j)] = A[size_t(3 * j + i)];
      Mat L = mul(axis_rotation(1, m[1] * 1e-5), mul(axis_rotation(0, m[0] * 1e-5), axis_rotation(2, m[2] * 1e-5)));
      Mat R = mul(At, mul(L, A));
      double T[3];
      for (int i = 0; i < 3; ++i) T[i] = At[size_t(3 * i)] * m[3] + At[size_t(3 * i + 1)] * m[4] + At[size_t(3 * i + 2)] * m[5];
      for (uint16_t k = 0; k < rg.part_count; ++k) {
        const afm_part &pt = g.parts[rg.parts[k]];
        for (uint32_t v = pt.first_vertex; v < pt.first_vertex + pt.vertex_count; ++v) {
          auto &p = out.positions[v];
          auto &n = out.normals[v];
          double d[3] = {p[0] - rg.pivot[0], p[1] - rg.pivot[1], p[2] - rg.pivot[2]};
          std::array<double, 3> np{}, nn{};
          for (int i = 0; i < 3; ++i) {
            np[size_t(i)] = rg.pivot[i] + R[size_t(3 * i)] * d[0] + R[size_t(3 * i + 1)] * d[1] +
                            R[size_t(3 * i + 2)] * d[2] + T[i];
            nn[size_t(i)] = R[size_t(3 * i)] * n[0] + R[size_t(3 * i + 1)] * n[1] + R[size_t(3 * i + 2)] * n[2];
          }
          p = np;
          n = nn;
        }
      }
    }
  return out;
}

}  // namespace afmtest
