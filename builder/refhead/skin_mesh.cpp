#include "refhead/skin_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "refhead/head_shape.h"
#include "refhead/sdf.h"

namespace afmb::refhead {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kCapRadius = 0.095;  // metres per radian of latitude in the cap
constexpr double kTMax = 0.26;        // rays start this far out

// ---- the ray parametrisation -----------------------------------------------
//
// A vertex's parameters are (phi, v): phi the longitude (0 ahead, +pi/2 the
// face's left), v a height. v <= 0: a horizontal ray from (0, cap_y + v,
// axis_z). v > 0: latitude v / kCapRadius from (0, cap_y, axis_z). The skin
// is a graph over these rays, so the grid cannot fold.

struct Ray {
  Vec3 o, d;
};

Ray ray_of(double phi, double v) {
  const HeadDesign &hd = head_design();
  // Exact on the midline (phi = 0 and the back seam, phi = +-pi), so those
  // vertices lie on the symmetry plane x = 0.
  const bool seam = std::abs(phi) == kPi;
  const double s = phi == 0.0 || seam ? 0.0 : std::sin(phi);
  const double c = phi == 0.0 ? 1.0 : seam ? -1.0 : std::cos(phi);
  Ray r;
  if (v <= 0) {
    r.o = Vec3(0.0, hd.cap_y + v, hd.axis_z);
    r.d = Vec3(s, 0.0, c);
  } else {
    const double th = v / kCapRadius;
    r.o = Vec3(0.0, hd.cap_y, hd.axis_z);
    r.d = Vec3(std::cos(th) * s, std::sin(th), std::cos(th) * c);
  }
  return r;
}

void param_of(const Vec3 &p, double *phi, double *v) {
  const HeadDesign &hd = head_design();
  const double dz = p.z() - hd.axis_z;
  *phi = std::atan2(p.x(), dz);
  if (p.y() <= hd.cap_y) {
    *v = p.y() - hd.cap_y;
  } else {
    *v = kCapRadius * std::atan2(p.y() - hd.cap_y, std::hypot(p.x(), dz));
  }
}

// Distance along the ray to the outermost skin crossing. Marches in from
// beyond the head by a fraction of the distance bound, so thin parts (ears,
// whose backs stand off the head) are not jumped over and the first
// crossing met is the outermost; then refines by regula falsi. Always from
// outside, never from a neighbour's answer: that could start between an
// ear and the head and miss the ear.
double cast(const Ray &r) {
  auto f = [&](double t) { return head_sdf(r.o + t * r.d); };
  double t = kTMax;
  double ft = f(t);
  double t_out = t, f_out = ft;
  for (int i = 0; ft > 1e-7; ++i) {
    t_out = t;
    f_out = ft;
    // Near a grazing ray the bound shrinks without a crossing: fixed steps.
    const double step = i < 48 ? std::max(0.9 * ft, 1e-5) : 3e-4;
    t -= step;
    if (t <= 0) return 0.0;
    ft = f(t);
  }
  if (ft >= 0) return t;
  // Bracketed: t inside (ft < 0), t_out outside (f_out > 0). Illinois.
  double lo = t, flo = ft, hi = t_out, fhi = f_out;
  int side = 0;
  for (int i = 0; i < 30 && hi - lo > 1e-9; ++i) {
    const double m = (lo * fhi - hi * flo) / (fhi - flo);
    const double fm = f(m);
    if (fm < 0) {
      lo = m;
      flo = fm;
      if (side == -1) fhi *= 0.5;
      side = -1;
    } else {
      hi = m;
      fhi = fm;
      if (side == 1) flo *= 0.5;
      side = 1;
    }
    if (std::abs(fm) < 1e-9) return m;
  }
  return 0.5 * (lo + hi);
}

// ---- layout: rows and their longitudes ---------------------------------------

struct Row {
  double v = 0;
  std::vector<double> phis;  // half ring: phis[0] = 0 < ... < phis.back() = pi
  bool pole = false;
};

struct Layout {
  std::vector<Row> rows;
  double face_spacing = 0;  // the grid's spacing on the face, metres
  double face_factor = 1;   // face spacing / spacing elsewhere
  int mouth_row = -1, eye_row = -1, nose_row = -1;
  double phi_mc = 0, phi_ei = 0, phi_ec = 0, phi_eo = 0;
  long count = 0;
};

struct Knots {
  double v_bot, v_face_lo, v_mouth, v_nose, v_eye, v_face_hi, v_top;
  double phi_mc, phi_ei, phi_ec, phi_eo;
};

Knots knots() {
  const HeadDesign &hd = head_design();
  Knots k;
  k.v_bot = hd.neck_bottom_y - hd.cap_y;
  k.v_face_lo = -0.118 - hd.cap_y;  // just under the chin
  k.v_mouth = hd.mouth_y - hd.cap_y;
  k.v_nose = hd.subnasale_y - hd.cap_y;
  k.v_eye = hd.eye_centre.y() - hd.cap_y;
  k.v_face_hi = kCapRadius * 0.5;
  k.v_top = kCapRadius * kPi / 2;
  auto lon = [&](const Vec3 &p) { return std::atan2(p.x(), p.z() - hd.axis_z); };
  k.phi_mc = lon(Vec3(hd.mouth_half_width, hd.mouth_y, 0.080));
  k.phi_ei = lon(hd.eye_inner_corner);
  k.phi_ec = lon(hd.eye_centre + Vec3(0, 0, hd.eye_radius));
  k.phi_eo = lon(hd.eye_outer_corner);
  return k;
}

// The face gets this fraction of the spacing elsewhere: denser where the
// features are. Smaller at low resolution, where features need the help.
double face_factor(double target) {
  const double t = std::clamp(std::log(target / 1000.0) / std::log(100.0), 0.0, 1.0);
  return 0.56 + 0.16 * t;
}

// Rows over the eyes (the upper lids, up to the brow's foot) at most this
// far apart, metres: a lid of one band of triangles cuts through the eyeball
// as it closes, whatever holds its vertices off it (a chord of 4.4 mm dips
// 0.2 mm into an eyeball of 12.2 mm radius, one of 10 mm 1 mm). Never
// closer than kLidRowsShare of the face's spacing, so that the lid's
// triangles do not turn into slivers at coarse resolutions: the 1k and 2k
// heads get rows at 0.45 of their face spacing (13.5 and 9.8 mm), the 5k
// head at 0.71, and the 10k head's face spacing (4.1 mm) is fine enough as
// it is.
constexpr double kLidRowSpacing = 4.4e-3;
constexpr double kLidRowsShare = 0.45;

// Row spacing relative to the global spacing H, as a function of v.
double row_weight(double v, const Knots &k, double ff, double H) {
  const double w = 0.03;
  const double band = sdf::smoothstep(k.v_face_lo - w, k.v_face_lo, v) *
                      (1.0 - sdf::smoothstep(k.v_face_hi, k.v_face_hi + w, v));
  const double lid_share = std::clamp(kLidRowSpacing / (H * ff), kLidRowsShare, 1.0);
  const double lids = sdf::smoothstep(k.v_eye, k.v_eye + 0.004, v) *
                      (1.0 - sdf::smoothstep(k.v_eye + 0.014, k.v_eye + 0.020, v));
  return (1.0 - (1.0 - ff) * band) * (1.0 - (1.0 - lid_share) * lids);
}

// Column spacing relative to the global spacing, as a function of phi.
double col_weight(double phi, double ff) {
  return 1.0 - (1.0 - ff) * (1.0 - sdf::smoothstep(1.0, 1.7, std::abs(phi)));
}

// Places n intervals on [a, b] so each holds an equal share of the integral
// of 1 / spacing; returns the n + 1 positions.
template <class Spacing>
std::vector<double> distribute(double a, double b, int n, Spacing spacing) {
  const int m = 64;
  std::vector<double> cum(m + 1, 0.0);
  for (int i = 0; i < m; ++i) {
    const double x0 = a + (b - a) * i / m, x1 = a + (b - a) * (i + 1) / m;
    cum[i + 1] = cum[i] + (x1 - x0) * 0.5 * (1.0 / spacing(x0) + 1.0 / spacing(x1));
  }
  std::vector<double> out(n + 1);
  out[0] = a;
  out[n] = b;
  int seg = 0;
  for (int j = 1; j < n; ++j) {
    const double target = cum[m] * j / n;
    while (seg < m - 1 && cum[seg + 1] < target) ++seg;
    const double f = (target - cum[seg]) / std::max(cum[seg + 1] - cum[seg], 1e-300);
    out[j] = a + (b - a) * (seg + f) / m;
  }
  return out;
}

template <class Spacing>
double integral(double a, double b, Spacing spacing) {
  const int m = 64;
  double s = 0;
  for (int i = 0; i < m; ++i) {
    const double x0 = a + (b - a) * i / m, x1 = a + (b - a) * (i + 1) / m;
    s += (x1 - x0) * 0.5 * (1.0 / spacing(x0) + 1.0 / spacing(x1));
  }
  return s;
}

// How much surface a unit of parameter covers on the face, measured once:
// along v (the most over a few longitudes in front) and along phi (the most
// over a few rows across the face), so rows and columns crowd where the
// surface runs along the rays (under the chin and the nose, the nose's
// sides) instead of stretching triangles there.
struct Metric {
  double v0 = 0, dv = 0.0005;
  std::vector<double> mv;
  double dphi = 0.005;
  std::vector<double> mphi;

  static double sample(const std::vector<double> &m, double x) {
    const double i = std::clamp(x, 0.0, (double)m.size() - 1.0);
    const size_t a = (size_t)i;
    const size_t b = std::min(a + 1, m.size() - 1);
    return m[a] + (i - (double)a) * (m[b] - m[a]);
  }
  double along_v(double v) const { return sample(mv, (v - v0) / dv); }
  double along_phi(double phi) const { return sample(mphi, phi / dphi); }
};

std::vector<double> smooth(const std::vector<double> &m, int w) {
  std::vector<double> out(m.size());
  for (size_t i = 0; i < m.size(); ++i) {
    double s = 0;
    int n = 0;
    for (int j = -w; j <= w; ++j) {
      const long k = (long)i + j;
      if (k < 0 || k >= (long)m.size()) continue;
      s += m[(size_t)k];
      ++n;
    }
    out[i] = s / n;
  }
  return out;
}

Metric measure(const Knots &k) {
  Metric m;
  m.v0 = k.v_bot;
  const int nv = (int)std::ceil((k.v_top - k.v_bot) / m.dv);
  m.mv.assign(nv + 1, 1.0);
  for (double phi : {0.0, 0.35, 0.7, 1.05}) {
    Vec3 prev;
    double t = -1;
    for (int i = 0; i <= nv; ++i) {
      const Ray r = ray_of(phi, std::min(k.v_bot + i * m.dv, k.v_top - 1e-9));
      t = cast(r);
      const Vec3 p = r.o + t * r.d;
      if (i > 0) m.mv[i - 1] = std::max(m.mv[i - 1], (p - prev).norm() / m.dv);
      prev = p;
    }
  }
  const int np = (int)std::ceil(kPi / m.dphi);
  m.mphi.assign(np + 1, 0.6);
  for (double v : {k.v_eye + 0.012, k.v_eye - 0.012, k.v_eye - 0.030, k.v_mouth, k.v_mouth - 0.03}) {
    Vec3 prev;
    double t = -1;
    for (int i = 0; i <= np; ++i) {
      const Ray r = ray_of(std::min(i * m.dphi, kPi), v);
      t = cast(r);
      const Vec3 p = r.o + t * r.d;
      if (i > 0) m.mphi[i - 1] = std::max(m.mphi[i - 1], (p - prev).norm() / (m.dphi * 0.092));
      prev = p;
    }
  }
  for (double &x : m.mv) x = std::clamp(x, 0.6, 4.0);
  for (double &x : m.mphi) x = std::clamp(x, 0.6, 1.5);
  m.mv = smooth(m.mv, 4);
  m.mphi = smooth(m.mphi, 3);
  return m;
}

Layout make_layout(double H, double col_scale, double ff, const Metric &metric) {
  const Knots k = knots();
  const HeadDesign &hd = head_design();
  Layout L;
  L.face_spacing = H * ff;
  L.face_factor = ff;
  L.phi_mc = k.phi_mc;
  L.phi_ei = k.phi_ei;
  L.phi_ec = k.phi_ec;
  L.phi_eo = k.phi_eo;

  // Face columns: knots 0, eye inner, mouth corner, eye centre, eye outer, pi.
  std::vector<double> ck{0.0, k.phi_ei, k.phi_mc, k.phi_ec, k.phi_eo, kPi};
  std::sort(ck.begin(), ck.end());
  auto col_spacing = [&](double phi) {
    return H * col_scale * col_weight(phi, ff) / (0.092 * metric.along_phi(phi));
  };
  std::vector<int> cn(ck.size() - 1);
  for (size_t i = 0; i + 1 < ck.size(); ++i)
    cn[i] = std::max(1, (int)std::lround(integral(ck[i], ck[i + 1], col_spacing)));
  // Enough columns for the features to read and for their FDPs to be
  // distinct vertices: at least 3 intervals per mouth half, 2 per eye half.
  auto count_between = [&](double a, double b) {
    int n = 0;
    for (size_t i = 0; i + 1 < ck.size(); ++i)
      if (ck[i] >= a - 1e-12 && ck[i + 1] <= b + 1e-12) n += cn[i];
    return n;
  };
  auto widen = [&](double a, double b, int need) {
    while (count_between(a, b) < need) {
      size_t best = 0;
      double best_len = -1;
      for (size_t i = 0; i + 1 < ck.size(); ++i) {
        if (ck[i] >= a - 1e-12 && ck[i + 1] <= b + 1e-12) {
          double len = (ck[i + 1] - ck[i]) / (cn[i] + 1);
          if (len > best_len) {
            best_len = len;
            best = i;
          }
        }
      }
      ++cn[best];
    }
  };
  widen(0.0, k.phi_mc, 3);
  widen(k.phi_ei, k.phi_ec, 2);
  widen(k.phi_ec, k.phi_eo, 2);
  std::vector<double> face_cols{0.0};
  for (size_t i = 0; i + 1 < ck.size(); ++i) {
    std::vector<double> seg = distribute(ck[i], ck[i + 1], cn[i], col_spacing);
    face_cols.insert(face_cols.end(), seg.begin() + 1, seg.end());
  }

  // Rows: knots at the neck's end, the mouth, the subnasale, the eyes, the
  // cap's start and the top.
  auto row_spacing = [&](double v) { return H * row_weight(v, k, ff, H) / metric.along_v(v); };
  struct Seg {
    double a, b;
    int min_n;
  };
  // (The subnasale row makes FDP 9.15, and the FAP units that use it,
  // exact at every resolution, as the mouth and eye rows do for theirs.)
  const Seg segs[] = {{k.v_bot, k.v_mouth, 4}, {k.v_mouth, k.v_nose, 2}, {k.v_nose, k.v_eye, 3},
                      {k.v_eye, 0.0, 2}, {0.0, k.v_top, 3}};
  std::vector<double> vs{k.v_bot};
  for (const Seg &s : segs) {
    int n = std::max(s.min_n, (int)std::lround(integral(s.a, s.b, row_spacing)));
    std::vector<double> seg = distribute(s.a, s.b, n, row_spacing);
    vs.insert(vs.end(), seg.begin() + 1, seg.end());
  }

  // Rings: the face band shares the face columns; rows beyond it thin them
  // out toward the neck's end and the crown, at most halving per row, so
  // the triangles between rows stay fans of two or three.
  L.rows.resize(vs.size());
  int first_face = -1, last_face = -1;
  for (size_t i = 0; i < vs.size(); ++i) {
    Row &r = L.rows[i];
    r.v = vs[i];
    if (std::abs(r.v - k.v_mouth) < 1e-12) L.mouth_row = (int)i;
    if (std::abs(r.v - k.v_eye) < 1e-12) L.eye_row = (int)i;
    if (std::abs(r.v - k.v_nose) < 1e-12) L.nose_row = (int)i;
    if (i + 1 == vs.size()) {
      r.pole = true;
      r.phis = {0.0};
    } else if (r.v >= k.v_face_lo - 1e-9 && r.v <= k.v_face_hi) {
      r.phis = face_cols;
      if (first_face < 0) first_face = (int)i;
      last_face = (int)i;
    }
  }
  auto thin = [&](const std::vector<double> &prev, double v) {
    double radius;
    if (v < 0) {
      const double y = hd.cap_y + v;
      radius = 0.056 + 0.016 * sdf::smoothstep(-0.15, -0.115, y);
    } else {
      radius = 0.088 * std::cos(v / kCapRadius);
    }
    const double gap = 0.8 * H * col_scale * row_weight(v, k, ff, H) / std::max(radius, 1e-3);
    std::vector<double> out{0.0};
    size_t last = 0;
    for (size_t j = 1; j < prev.size(); ++j) {
      const bool end = j + 1 == prev.size();
      if (end || prev[j] - out.back() >= gap || j - last >= 2) {
        // No sliver before the seam: drop a kept column too close to it.
        if (end && out.size() > 2 && prev[j] - out.back() < 0.5 * gap) out.pop_back();
        out.push_back(prev[j]);
        last = j;
      }
    }
    return out;
  };
  for (int i = first_face - 1; i >= 0; --i) L.rows[i].phis = thin(L.rows[i + 1].phis, L.rows[i].v);
  for (int i = last_face + 1; i + 1 < (int)vs.size(); ++i)
    L.rows[i].phis = thin(L.rows[i - 1].phis, L.rows[i].v);

  long count = 0;
  for (const Row &r : L.rows) count += r.pole ? 1 : 2 * ((long)r.phis.size() - 1);
  const Row &mr = L.rows[L.mouth_row];
  const Row &er = L.rows[L.eye_row];
  for (double phi : mr.phis)
    if (phi < L.phi_mc - 1e-12) count += phi == 0.0 ? 1 : 2;
  for (double phi : er.phis)
    if (phi > L.phi_ei + 1e-12 && phi < L.phi_eo - 1e-12) count += 2;
  L.count = count;
  return L;
}

// Finds the grid spacing whose vertex count is nearest the target, trying a
// few column/row balances for finer steps than one row allows.
Layout solve_layout(int target) {
  const double ff = face_factor(target);
  // The same for every resolution: measured once per process.
  static const Metric metric = measure(knots());
  Layout best;
  long best_err = -1;
  for (int c = -4; c <= 4; ++c) {
    const double col_scale = 1.0 + 0.025 * c;
    double lo = std::log(0.0004), hi = std::log(0.05);
    for (int it = 0; it < 36; ++it) {
      const double mid = 0.5 * (lo + hi);
      Layout L = make_layout(std::exp(mid), col_scale, ff, metric);
      const long err = std::labs(L.count - target);
      const bool more = L.count > target;
      if (best_err < 0 || err < best_err) {
        best_err = err;
        best = std::move(L);
      }
      if (best_err == 0) return best;
      if (more)
        lo = mid;
      else
        hi = mid;
    }
  }
  return best;
}

// ---- eye opening --------------------------------------------------------------

struct EyeOpening {
  double phi_ei, phi_ec, phi_eo, v_eye;
  double up_reach = 0.016, low_reach = 0.013;  // rows this far away follow

  // Lid heights above / below the eye row at longitude |phi|, 0 outside.
  double lid(double aphi, bool upper) const {
    if (aphi <= phi_ei || aphi >= phi_eo) return 0.0;
    const HeadDesign &hd = head_design();
    double u = aphi < phi_ec ? (phi_ec - aphi) / (phi_ec - phi_ei) : (aphi - phi_ec) / (phi_eo - phi_ec);
    // Rounder medially, more pointed at the outer corner.
    const double p = upper ? (aphi < phi_ec ? 0.62 : 0.78) : (aphi < phi_ec ? 0.75 : 0.82);
    return hd.iris_radius * std::pow(std::max(0.0, 1.0 - u * u), p);
  }

  // Moves a parameter point: the eye row's two copies go to the lid
  // margins; rows within reach are compressed to make room.
  double open(double phi, double v, int copy) const {
    const double aphi = std::abs(phi);
    const double up = lid(aphi, true), lo = lid(aphi, false);
    if (up == 0.0 && lo == 0.0) return v;
    if (copy == 1) return v_eye + up;
    if (copy == 2) return v_eye - lo;
    if (v > v_eye && v < v_eye + up_reach) return v_eye + up + (v - v_eye) * (up_reach - up) / up_reach;
    if (v < v_eye && v > v_eye - low_reach)
      return v_eye - lo - (v_eye - v) * (low_reach - lo) / low_reach;
    return v;
  }
};

// ---- mesh assembly ----------------------------------------------------------

struct Builder {
  const Layout &L;
  std::vector<int> base;         // first vertex of each row
  std::vector<int> mouth_copy;   // lower-lip copy per mouth-row column (+ side), -1 if none
  std::vector<int> mouth_copy_m; // the same for the - side
  std::vector<int> eye_copy;     // lower-lid copy per eye-row column (+ side)
  std::vector<int> eye_copy_m;
  std::vector<double> phi, v;    // parameters per vertex
  std::vector<int> copy_kind;    // 0 ordinary, 1 eye upper margin, 2 eye lower margin
  std::vector<Eigen::Vector3i> tris;

  explicit Builder(const Layout &layout) : L(layout) {}

  int n_of(int r) const { return (int)L.rows[r].phis.size() - 1; }

  // Ordinary vertex of row r, half-column k, side +1 / -1.
  int vid(int r, int k, int side) const {
    if (L.rows[r].pole) return base[r];
    const int n = n_of(r);
    if (k == 0 || k == n || side > 0) return base[r] + n - 1 + k;
    return base[r] + n - 1 - k;
  }

  // The vertex a triangle below row r uses: the lower copy on slits.
  int vid_below(int r, int k, int side) const {
    if (r == L.mouth_row) {
      int c = side > 0 || k == 0 ? mouth_copy[k] : mouth_copy_m[k];
      if (c >= 0) return c;
    }
    if (r == L.eye_row) {
      int c = side > 0 ? eye_copy[k] : eye_copy_m[k];
      if (c >= 0) return c;
    }
    return vid(r, k, side);
  }

  void add_vertex(double ph, double vv, int kind) {
    phi.push_back(ph);
    v.push_back(vv);
    copy_kind.push_back(kind);
  }

  void build_vertices() {
    const int nrows = (int)L.rows.size();
    base.resize(nrows);
    for (int r = 0; r < nrows; ++r) {
      const Row &row = L.rows[r];
      base[r] = (int)phi.size();
      if (row.pole) {
        add_vertex(0.0, row.v, 0);
        continue;
      }
      const int n = n_of(r);
      for (int k = n - 1; k >= 1; --k) add_vertex(-row.phis[k], row.v, r == L.eye_row ? 1 : 0);
      for (int k = 0; k <= n; ++k) add_vertex(row.phis[k], row.v, r == L.eye_row ? 1 : 0);
      if (r == L.mouth_row) {
        mouth_copy.assign(n + 1, -1);
        mouth_copy_m.assign(n + 1, -1);
        for (int k = n; k >= 1; --k) {
          if (row.phis[k] < L.phi_mc - 1e-12) {
            mouth_copy_m[k] = (int)phi.size();
            add_vertex(-row.phis[k], row.v, 0);
          }
        }
        mouth_copy[0] = mouth_copy_m[0] = (int)phi.size();
        add_vertex(0.0, row.v, 0);
        for (int k = 1; k <= n; ++k) {
          if (row.phis[k] < L.phi_mc - 1e-12) {
            mouth_copy[k] = (int)phi.size();
            add_vertex(row.phis[k], row.v, 0);
          }
        }
      }
      if (r == L.eye_row) {
        eye_copy.assign(n + 1, -1);
        eye_copy_m.assign(n + 1, -1);
        for (int k = n; k >= 1; --k) {
          if (row.phis[k] > L.phi_ei + 1e-12 && row.phis[k] < L.phi_eo - 1e-12) {
            eye_copy_m[k] = (int)phi.size();
            add_vertex(-row.phis[k], row.v, 2);
          }
        }
        for (int k = 1; k <= n; ++k) {
          if (row.phis[k] > L.phi_ei + 1e-12 && row.phis[k] < L.phi_eo - 1e-12) {
            eye_copy[k] = (int)phi.size();
            add_vertex(row.phis[k], row.v, 2);
          }
        }
        // The eye row's corners and everything outside the eyes are
        // ordinary vertices: only the margins between the corners move.
        for (int k = 0; k <= n; ++k) {
          if (!(row.phis[k] > L.phi_ei + 1e-12 && row.phis[k] < L.phi_eo - 1e-12)) {
            copy_kind[vid(r, k, 1)] = 0;
            copy_kind[vid(r, k, -1)] = 0;
          }
        }
      }
    }
  }

  void add_tri(int a, int b, int c) { tris.emplace_back(a, b, c); }

  // Triangulates the band between rows r (below) and r + 1 on the + half,
  // then mirrors it onto the - half. When row r + 1 is a slit row, the
  // band's triangles (below the slit) take the lower copies.
  void zip(int r) {
    const Row &A = L.rows[r], &B = L.rows[r + 1];
    struct Corner {
      int row, k;
    };
    std::vector<std::array<Corner, 3>> cs;
    if (B.pole) {
      for (int i = 0; i < n_of(r); ++i) cs.push_back({{{0, i}, {0, i + 1}, {1, 0}}});
    } else {
      // Advance along whichever row's next longitude comes first.
      const int na = n_of(r), nb = n_of(r + 1);
      int i = 0, j = 0;
      while (i < na || j < nb) {
        const bool adv_a = j == nb || (i < na && A.phis[i + 1] <= B.phis[j + 1]);
        if (adv_a) {
          cs.push_back({{{0, i}, {0, i + 1}, {1, j}}});
          ++i;
        } else {
          cs.push_back({{{0, i}, {1, j + 1}, {1, j}}});
          ++j;
        }
      }
    }
    const int first = (int)tris.size(), n = (int)cs.size();
    for (int side : {1, -1}) {
      for (const auto &t : cs) {
        int id[3];
        for (int c = 0; c < 3; ++c)
          id[c] = t[c].row == 1 ? vid_below(r + 1, t[c].k, side) : vid(r, t[c].k, side);
        if (side > 0)
          add_tri(id[0], id[1], id[2]);
        else
          add_tri(id[0], id[2], id[1]);
      }
    }
    for (int i = 0; i < n; ++i) {
      tri_mirror.push_back(first + n + i);
      tri_plus.push_back(1);
    }
    for (int i = 0; i < n; ++i) {
      tri_mirror.push_back(first + i);
      tri_plus.push_back(0);
    }
  }

  void build_triangles() {
    for (int r = 0; r + 1 < (int)L.rows.size(); ++r) zip(r);
    vmirror.assign(phi.size(), -1);
    for (int r = 0; r < (int)L.rows.size(); ++r) {
      const int n = L.rows[r].pole ? 0 : n_of(r);
      for (int k = 0; k <= n; ++k) {
        vmirror[vid(r, k, 1)] = vid(r, k, -1);
        vmirror[vid(r, k, -1)] = vid(r, k, 1);
        vmirror[vid_below(r, k, 1)] = vid_below(r, k, -1);
        vmirror[vid_below(r, k, -1)] = vid_below(r, k, 1);
      }
    }
  }

  std::vector<int> tri_mirror;  // each triangle's mirror image
  std::vector<char> tri_plus;   // built on the + side
  std::vector<int> vmirror;     // each vertex's mirror image
};

// Smooths the grid in the parameter domain, each vertex pulled toward its
// neighbours weighted by how stretched (3-D length over parameter length)
// the edge to each is, so vertices migrate into the places the rays meet
// at a glancing angle (under the chin, around the ears and the nose tip)
// and thin triangles there fatten. Moves are checked in the parameter
// domain: the surface is a graph over it, so a triangle that keeps its
// orientation there cannot fold on the surface. Computed on the + side and
// mirrored, so the mesh stays exactly symmetric.
void relax(const Layout &L, Builder &b, const std::vector<char> &fixed, std::vector<double> &t,
           Eigen::MatrixXd &V) {
  const int nv = (int)b.phi.size();
  const double scale = 0.092;  // metres per radian of longitude, near the face
  const double v_cap_limit = 0.8 * L.rows.back().v;  // leave the crown's pole alone
  std::vector<std::vector<int>> adj(nv);
  for (const auto &tri : b.tris)
    for (int c = 0; c < 3; ++c) {
      adj[tri[c]].push_back(tri[(c + 1) % 3]);
      adj[tri[c]].push_back(tri[(c + 2) % 3]);
    }
  for (auto &a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  std::vector<std::vector<int>> tris_of(nv);
  for (int f = 0; f < (int)b.tris.size(); ++f)
    for (int c = 0; c < 3; ++c) tris_of[b.tris[f][c]].push_back(f);
  auto unwrap = [](double phi, double ref) {
    if (phi - ref > kPi) return phi - 2 * kPi;
    if (phi - ref < -kPi) return phi + 2 * kPi;
    return phi;
  };
  auto param_area = [&](int f) {
    const auto &tri = b.tris[f];
    const double p0 = b.phi[tri[0]];
    const double x1 = (unwrap(b.phi[tri[1]], p0) - p0) * scale, y1 = b.v[tri[1]] - b.v[tri[0]];
    const double x2 = (unwrap(b.phi[tri[2]], p0) - p0) * scale, y2 = b.v[tri[2]] - b.v[tri[0]];
    return x1 * y2 - x2 * y1;
  };
  std::vector<double> area0(b.tris.size());
  for (int f = 0; f < (int)b.tris.size(); ++f) area0[f] = param_area(f);

  std::vector<int> movers;  // + side and midline vertices that may move
  for (int i = 0; i < nv; ++i) {
    if (fixed[i] || b.v[i] > v_cap_limit || b.phi[i] < 0.0) continue;
    bool pole_next = false;
    for (int f : tris_of[i])
      for (int c = 0; c < 3; ++c)
        if (L.rows.back().pole && b.v[b.tris[f][c]] > v_cap_limit) pole_next = true;
    if (!pole_next) movers.push_back(i);
  }
  const int iterations = 8;
  for (int it = 0; it < iterations; ++it) {
    std::vector<double> old_phi = b.phi, old_v = b.v, old_t = t;
    Eigen::MatrixXd old_V = V;
    for (int i : movers) {
      double sw = 0, sx = 0, sy = 0;
      for (int j : adj[i]) {
        const double dx = (unwrap(old_phi[j], old_phi[i]) - old_phi[i]) * scale;
        const double dy = old_v[j] - old_v[i];
        const double d2 = dx * dx + dy * dy;
        if (d2 <= 0) continue;
        const double w = (old_V.row(j) - old_V.row(i)).squaredNorm() / d2;
        sw += w;
        sx += w * dx;
        sy += w * dy;
      }
      if (sw <= 0) continue;
      const bool midline = old_phi[i] == 0.0 || old_phi[i] == kPi;
      if (!midline) b.phi[i] = old_phi[i] + 0.5 * sx / sw / scale;
      b.v[i] = old_v[i] + 0.5 * sy / sw;
    }
    auto place = [&](int i) {
      const Ray r = ray_of(b.phi[i], b.v[i]);
      t[i] = cast(r);
      V.row(i) = (r.o + t[i] * r.d).transpose();
      const int m = b.vmirror[i];
      if (m != i) {
        b.phi[m] = -b.phi[i];
        b.v[m] = b.v[i];
        t[m] = t[i];
        V.row(m) = V.row(i);
        V(m, 0) = -V(i, 0);
      }
    };
    auto restore = [&](int i) {
      for (int k : {i, b.vmirror[i]}) {
        b.phi[k] = old_phi[k];
        b.v[k] = old_v[k];
        t[k] = old_t[k];
        V.row(k) = old_V.row(k);
      }
    };
    for (int i : movers) {
      const int m = b.vmirror[i];
      if (m != i) {  // mirror the parameters before checking
        b.phi[m] = -b.phi[i];
        b.v[m] = b.v[i];
      }
    }
    // Undo moves around triangles that would turn over (or nearly) in the
    // parameter domain, until none does.
    std::vector<char> is_mover(nv, 0);
    for (int i : movers) is_mover[i] = 1;
    for (int pass = 0; pass < 10; ++pass) {
      bool any = false;
      for (int i : movers) {
        if (b.phi[i] == old_phi[i] && b.v[i] == old_v[i]) continue;
        bool bad = false;
        for (int k : {i, b.vmirror[i]})
          for (int f : tris_of[k])
            if (param_area(f) < 0.2 * area0[f]) bad = true;
        if (bad) {
          restore(i);
          any = true;
        }
      }
      if (!any) break;
    }
    for (int i : movers)
      if (b.phi[i] != old_phi[i] || b.v[i] != old_v[i]) place(i);
  }
}

// Flips the shared edge of two triangles where the other diagonal makes
// better angles: the grid's quads are sheared where the surface turns away
// from the rays, and the zipper's diagonal is then the worse one. Only
// edges between + side triangles, flipped in mirrored pairs (the mesh stays
// symmetric), only between nearly coplanar triangles (the shape stays), and
// never creating an edge that exists (the mesh stays manifold).
void flip_edges(const Eigen::MatrixXd &V, Builder &b) {
  auto &T = b.tris;
  const long nv = (long)V.rows();
  auto key = [nv](int u, int w) { return u < w ? (long)u * nv + w : (long)w * nv + u; };
  std::unordered_set<long> edges;
  std::vector<int> valence(nv, 0);
  for (const auto &t : T)
    for (int c = 0; c < 3; ++c)
      if (edges.insert(key(t[c], t[(c + 1) % 3])).second) {
        ++valence[t[c]];
        ++valence[t[(c + 1) % 3]];
      }
  auto pt = [&](int i) -> Vec3 { return V.row(i).transpose(); };
  auto normal = [&](int a, int c, int d) -> Vec3 { return (pt(c) - pt(a)).cross(pt(d) - pt(a)); };
  auto min_angle = [&](int a, int c, int d) {
    const Vec3 p[3] = {pt(a), pt(c), pt(d)};
    double m = kPi;
    for (int i = 0; i < 3; ++i) {
      const Vec3 u = (p[(i + 1) % 3] - p[i]).normalized(), w = (p[(i + 2) % 3] - p[i]).normalized();
      m = std::min(m, std::acos(std::clamp(u.dot(w), -1.0, 1.0)));
    }
    return m;
  };
  const double min_gain = 2.0 * kPi / 180;
  for (int round = 0; round < 8; ++round) {
    // Directed edge -> triangle, + side only.
    std::unordered_map<long, int> owner;
    for (int f = 0; f < (int)T.size(); ++f)
      if (b.tri_plus[f])
        for (int c = 0; c < 3; ++c) owner[(long)T[f][c] * nv + T[f][(c + 1) % 3]] = f;
    struct Flip {
      double gain;
      int t1, t2, a, bb, c, d;
    };
    std::vector<Flip> cand;
    for (int f = 0; f < (int)T.size(); ++f) {
      if (!b.tri_plus[f]) continue;
      for (int e = 0; e < 3; ++e) {
        const int a = T[f][e], bb = T[f][(e + 1) % 3], c = T[f][(e + 2) % 3];
        if (a > bb) continue;  // each undirected edge once
        auto it = owner.find((long)bb * nv + a);
        if (it == owner.end()) continue;  // boundary, or the other side is on the - side
        const int g = it->second;
        int d = -1;
        for (int k = 0; k < 3; ++k)
          if (T[g][k] != a && T[g][k] != bb) d = T[g][k];
        if (d < 0 || edges.count(key(c, d)) || valence[a] <= 3 || valence[bb] <= 3) continue;
        // The new edge must not lie on or cross the midline: its mirror
        // image would be itself.
        if ((b.vmirror[c] == c && b.vmirror[d] == d) || b.vmirror[c] == d) continue;
        const Vec3 n1 = normal(a, bb, c).normalized(), n2 = normal(bb, a, d).normalized();
        if (n1.dot(n2) < 0.7) continue;  // a crease: leave the shape alone
        const Vec3 m1 = normal(a, d, c), m2 = normal(d, bb, c);
        if (m1.norm() == 0 || m2.norm() == 0) continue;
        const Vec3 avg = (n1 + n2).normalized();
        if (m1.normalized().dot(avg) < 0.7 || m2.normalized().dot(avg) < 0.7) continue;
        const double gain = std::min(min_angle(a, d, c), min_angle(d, bb, c)) -
                            std::min(min_angle(a, bb, c), min_angle(bb, a, d));
        if (gain > min_gain) cand.push_back({gain, f, g, a, bb, c, d});
      }
    }
    if (cand.empty()) break;
    std::sort(cand.begin(), cand.end(), [](const Flip &x, const Flip &y) {
      return x.gain != y.gain ? x.gain > y.gain : x.t1 < y.t1;
    });
    std::vector<char> used(T.size(), 0);
    for (const Flip &fl : cand) {
      if (used[fl.t1] || used[fl.t2]) continue;
      used[fl.t1] = used[fl.t2] = 1;
      T[fl.t1] = Eigen::Vector3i(fl.a, fl.d, fl.c);
      T[fl.t2] = Eigen::Vector3i(fl.d, fl.bb, fl.c);
      for (int tt : {fl.t1, fl.t2}) {
        const auto &s = T[tt];
        T[b.tri_mirror[tt]] = Eigen::Vector3i(b.vmirror[s[0]], b.vmirror[s[2]], b.vmirror[s[1]]);
      }
      const int ma = b.vmirror[fl.a], mb = b.vmirror[fl.bb], mc = b.vmirror[fl.c], md = b.vmirror[fl.d];
      edges.erase(key(fl.a, fl.bb));
      edges.erase(key(ma, mb));
      edges.insert(key(fl.c, fl.d));
      edges.insert(key(mc, md));
      for (int v : {fl.a, fl.bb, ma, mb}) --valence[v];
      for (int v : {fl.c, fl.d, mc, md}) ++valence[v];
    }
  }
}

}  // namespace

Expected<SkinMesh> build_skin(int target_vertices) {
  const HeadDesign &hd = head_design();
  const Layout L = solve_layout(target_vertices);
  Builder b(L);
  b.build_vertices();
  b.build_triangles();
  const int nv = (int)b.phi.size();
  if (nv != L.count)
    return Status::error("reference head: internal error: layout counted " +
                         std::to_string(L.count) + " skin vertices, built " + std::to_string(nv));

  EyeOpening eye{L.phi_ei, L.phi_ec, L.phi_eo, L.rows[L.eye_row].v};
  for (int i = 0; i < nv; ++i) b.v[i] = eye.open(b.phi[i], b.v[i], b.copy_kind[i]);

  // Cast every vertex.
  std::vector<double> t(nv, -1.0);
  Eigen::MatrixXd V(nv, 3);
  for (int i = 0; i < nv; ++i) {
    const Ray r = ray_of(b.phi[i], b.v[i]);
    t[i] = cast(r);
    V.row(i) = (r.o + t[i] * r.d).transpose();
  }

  // Features.
  SkinMesh out;
  const Row &mrow = L.rows[L.mouth_row];
  const int nm = (int)mrow.phis.size() - 1;
  std::vector<int> mouth_cols;  // + side columns up to and including the corner
  for (int k = 0; k <= nm; ++k)
    if (mrow.phis[k] <= L.phi_mc + 1e-12) mouth_cols.push_back(k);
  for (int i = (int)mouth_cols.size() - 1; i >= 0; --i) {
    out.mouth_upper.push_back(b.vid(L.mouth_row, mouth_cols[i], -1));
    out.mouth_lower.push_back(b.vid_below(L.mouth_row, mouth_cols[i], -1));
  }
  for (size_t i = 1; i < mouth_cols.size(); ++i) {
    out.mouth_upper.push_back(b.vid(L.mouth_row, mouth_cols[i], 1));
    out.mouth_lower.push_back(b.vid_below(L.mouth_row, mouth_cols[i], 1));
  }
  const Row &erow = L.rows[L.eye_row];
  for (int k = 0; k < (int)erow.phis.size(); ++k) {
    if (erow.phis[k] >= L.phi_ei - 1e-12 && erow.phis[k] <= L.phi_eo + 1e-12) {
      for (int e = 0; e < 2; ++e) {
        const int side = e == 0 ? 1 : -1;
        out.eye_upper[e].push_back(b.vid(L.eye_row, k, side));
        out.eye_lower[e].push_back(b.vid_below(L.eye_row, k, side));
      }
    }
  }
  for (int r = 0; r < (int)L.rows.size(); ++r) {
    out.midline.push_back(b.vid(r, 0, 1));
    if (r == L.mouth_row) out.midline.push_back(b.vid_below(r, 0, 1));
  }
  // Order the mouth's two midline copies bottom (lower lip) first.
  {
    auto it = std::find(out.midline.begin(), out.midline.end(), b.vid(L.mouth_row, 0, 1));
    std::iter_swap(it, it + 1);
  }
  const Row &r0 = L.rows[0];
  for (int k = 0; k < (int)r0.phis.size(); ++k) {
    out.neck_boundary.push_back(b.vid(0, k, 1));
    if (k > 0 && k + 1 < (int)r0.phis.size()) out.neck_boundary.push_back(b.vid(0, k, -1));
  }
  out.top = b.vid((int)L.rows.size() - 1, 0, 1);
  out.subnasale = b.vid(L.nose_row, 0, 1);

  // Lid margins rest on the eyeball; the lips roll a little into the mouth.
  std::vector<char> fixed(nv, 0);
  for (int e = 0; e < 2; ++e) {
    const Vec3 c(e == 0 ? hd.eye_centre.x() : -hd.eye_centre.x(), hd.eye_centre.y(),
                 hd.eye_centre.z());
    // A flat triangle of circumradius a through points at distance R + g
    // from the centre stays outside the eyeball (radius R) when
    // g > a^2 / 2R; the triangles at the margins are about 0.6 of the face
    // spacing across, a little more near the corners.
    const double a = 0.75 * L.face_spacing;
    const double gap = std::clamp(hd.lid_gap + a * a / (2 * hd.eye_radius), hd.lid_gap, 0.0013);
    const double rs = hd.eye_radius + gap;
    for (const auto *arc : {&out.eye_upper[e], &out.eye_lower[e]}) {
      for (int id : *arc) {
        fixed[id] = 1;
        const Ray r = ray_of(b.phi[id], b.v[id]);
        const Vec3 oc = r.o - c;
        const double bq = oc.dot(r.d), cq = oc.squaredNorm() - rs * rs;
        const double disc = bq * bq - cq;
        const double ts = disc > 0 ? -bq + std::sqrt(disc) : -1.0;
        if (ts > 0 && ts < t[id] && t[id] - ts < 0.006) {
          t[id] = ts;
          V.row(id) = (r.o + ts * r.d).transpose();
        } else {
          // A ray that misses the eyeball (beside a corner): pull the
          // vertex onto it so no gap opens into the head.
          const Vec3 p = V.row(id).transpose();
          V.row(id) = (c + rs * (p - c).normalized()).transpose();
        }
      }
    }
  }
  for (const auto *arc : {&out.mouth_upper, &out.mouth_lower}) {
    for (int id : *arc) {
      if (fixed[id]) continue;
      fixed[id] = 1;
      const Ray r = ray_of(b.phi[id], b.v[id]);
      t[id] -= 0.0010;
      V.row(id) = (r.o + t[id] * r.d).transpose();
    }
  }
  for (int id : out.neck_boundary) fixed[id] = 1;
  fixed[out.top] = 1;
  fixed[out.subnasale] = 1;

  relax(L, b, fixed, t, V);
  flip_edges(V, b);

  // Faces, colours, texture coordinates.
  const int nf = (int)b.tris.size();
  out.V = V;
  out.F.resize(nf, 3);
  for (int f = 0; f < nf; ++f) out.F.row(f) = b.tris[f].transpose();
  out.C.resize(nv, 3);
  for (int i = 0; i < nv; ++i) out.C.row(i) = skin_colour(V.row(i).transpose()).transpose();

  // Cylindrical map: u = 0.5 ahead, 0 and 1 at the back seam; v by height.
  const double v_bot = L.rows.front().v, v_top = L.rows.back().v;
  std::vector<Eigen::Vector2d> tc(nv);
  for (int i = 0; i < nv; ++i) {
    double ph, vv;
    param_of(V.row(i).transpose(), &ph, &vv);
    if (V(i, 0) == 0.0) ph = V(i, 2) > hd.axis_z ? 0.0 : kPi;
    if (i == out.top) ph = 0.0, vv = v_top;
    tc[i] = Eigen::Vector2d(0.5 + ph / (2 * kPi), (vv - v_bot) / (v_top - v_bot));
  }
  std::vector<Eigen::Vector2d> extra;
  out.FTC.resize(nf, 3);
  for (int f = 0; f < nf; ++f) {
    bool minus_side = false;
    for (int c = 0; c < 3; ++c)
      if (V(b.tris[f][c], 0) < 0) minus_side = true;
    Eigen::Vector2d uv[3];
    int pole = -1;
    for (int c = 0; c < 3; ++c) {
      const int id = b.tris[f][c];
      uv[c] = tc[id];
      if (id == out.top) pole = c;
      if (id != out.top && uv[c].x() >= 1.0 && minus_side) uv[c].x() = 0.0;  // the seam, seen from the - side
    }
    // The pole has no longitude: it takes its neighbours' mean.
    if (pole >= 0) uv[pole].x() = 0.5 * (uv[(pole + 1) % 3].x() + uv[(pole + 2) % 3].x());
    for (int c = 0; c < 3; ++c) {
      const int id = b.tris[f][c];
      if (uv[c] == tc[id]) {
        out.FTC(f, c) = id;
      } else {
        out.FTC(f, c) = nv + (int)extra.size();
        extra.push_back(uv[c]);
      }
    }
  }
  out.TC.resize(nv + (int)extra.size(), 2);
  for (int i = 0; i < nv; ++i) out.TC.row(i) = tc[i].transpose();
  for (size_t i = 0; i < extra.size(); ++i) out.TC.row(nv + (int)i) = extra[i].transpose();
  return out;
}

}  // namespace afmb::refhead
