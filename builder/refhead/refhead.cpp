#include "refhead/refhead.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "refhead/head_shape.h"
#include "refhead/inner_parts.h"
#include "refhead/skin_mesh.h"

namespace afmb {

using refhead::HeadDesign;
using refhead::PartMesh;
using refhead::SkinMesh;
using Vec3 = Eigen::Vector3d;

namespace {

Part make_part(std::string name, PartKind kind, const PartMesh &m, const Vec3 &diffuse) {
  Part p;
  p.name = std::move(name);
  p.kind = kind;
  p.V = m.V;
  p.F = m.F;
  p.C = m.C;
  p.TC.resize(0, 2);
  p.FTC.resize(0, 3);
  p.diffuse = diffuse;
  return p;
}

// Vertex picking on one part.
struct Picker {
  const Eigen::MatrixXd &V;

  Vec3 at(int i) const { return V.row(i).transpose(); }

  // Among the vertices accepted by `ok`, the one nearest `target`, with
  // distances measured after scaling the axes by `w` (0 ignores an axis).
  int nearest(const Vec3 &target, const std::function<bool(int)> &ok,
              const Vec3 &w = Vec3(1, 1, 1)) const {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int i = 0; i < V.rows(); ++i) {
      if (!ok(i)) continue;
      const double d = (at(i) - target).cwiseProduct(w).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best = i;
      }
    }
    return best;
  }

  // Among the given vertices, the one furthest in direction `dir`.
  int extreme(const std::vector<int> &ids, const Vec3 &dir) const {
    int best = -1;
    double best_d = -std::numeric_limits<double>::infinity();
    for (int i : ids) {
      const double d = at(i).dot(dir);
      if (d > best_d) {
        best_d = d;
        best = i;
      }
    }
    return best;
  }
  std::vector<int> where(const std::function<bool(int)> &ok) const {
    std::vector<int> ids;
    for (int i = 0; i < V.rows(); ++i)
      if (ok(i)) ids.push_back(i);
    return ids;
  }
};

// The vertex of a contour (polyline of vertex ids) nearest the point at
// fraction `f` of its length from contour[from] toward contour[to].
int along(const Eigen::MatrixXd &V, const std::vector<int> &contour, int from, int to, double f) {
  const int step = to > from ? 1 : -1;
  std::vector<double> cum{0.0};
  for (int i = from; i != to; i += step)
    cum.push_back(cum.back() + (V.row(contour[i + step]) - V.row(contour[i])).norm());
  const double goal = f * cum.back();
  int best = from;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < cum.size(); ++k) {
    if (std::abs(cum[k] - goal) < best_d) {
      best_d = std::abs(cum[k] - goal);
      best = from + step * (int)k;
    }
  }
  return contour[best];
}

struct FdpAdder {
  FdpSet &set;
  const Scene &scene;
  std::string missing;  // FDPs no vertex qualified for (a bug, reported)
  void add(const char *id, int part, int vertex) {
    if (vertex < 0 || vertex >= scene.parts[part].V.rows()) {
      missing += missing.empty() ? id : std::string(", ") + id;
      return;
    }
    FdpPoint p;
    p.id = *FdpId::parse(id);
    p.part_name = scene.parts[part].name;
    p.part = part;
    p.vertex = vertex;
    p.pos = scene.parts[part].V.row(vertex).transpose();
    set.points.push_back(p);
  }
  void add_free(const char *id, const Vec3 &pos) {
    FdpPoint p;
    p.id = *FdpId::parse(id);
    p.pos = pos;
    set.points.push_back(p);
  }
};

std::string place_fdps(const SkinMesh &skin, const Scene &scene, const PartMesh &eye_l,
                const PartMesh &eye_r, const PartMesh &teeth_u, const PartMesh &teeth_l,
                const PartMesh &tongue, FdpSet &fdps) {
  const HeadDesign &hd = refhead::head_design();
  const Eigen::MatrixXd &V = skin.V;
  Picker pk{V};
  FdpAdder add{fdps, scene, {}};
  const int S = 0, EL = 1, ER = 2, TU = 3, TL = 4, TG = 5;  // part order of the scene

  // Slit-copy and eye-margin vertices are reserved for their own FDPs.
  std::vector<char> slit(V.rows(), 0);
  for (int i : skin.mouth_upper) slit[i] = 1;
  for (int i : skin.mouth_lower) slit[i] = 1;
  for (int e = 0; e < 2; ++e) {
    for (int i : skin.eye_upper[e]) slit[i] = 1;
    for (int i : skin.eye_lower[e]) slit[i] = 1;
  }
  auto front = [&](double min_z) { return [&, min_z](int i) { return V(i, 2) > min_z && !slit[i]; }; };
  const Vec3 xy(1, 1, 0);  // match on the face's x and y, whatever the depth

  // Midline in front, and the midline as a whole.
  std::vector<int> mid_front;
  std::vector<char> on_mid(V.rows(), 0);
  for (int i : skin.midline)
    if (!slit[i]) {
      mid_front.push_back(i);
      on_mid[i] = 1;
    }
  auto midline = [&](int i) { return on_mid[i] != 0; };
  auto mid_between = [&](double y_lo, double y_hi) {
    std::vector<int> ids;
    for (int i : mid_front)
      if (V(i, 1) >= y_lo && V(i, 1) <= y_hi) ids.push_back(i);
    return ids;
  };

  // ---- group 2: inner lip contour, chin, jaw ----
  const std::vector<int> &mu = skin.mouth_upper, &ml = skin.mouth_lower;
  const int m_mid = (int)mu.size() / 2, m_end = (int)mu.size() - 1;
  // Nose and lips first: other points are found relative to them.
  const int tip = pk.extreme(mid_between(-0.045, 0.0), Vec3(0, 0, 1));
  double up_y, lo_y;
  refhead::lip_borders(0.0, &up_y, &lo_y);
  const int ls = pk.nearest(Vec3(0, up_y, 0), midline, Vec3(0, 1, 0));
  const int li = pk.nearest(Vec3(0, lo_y, 0), midline, Vec3(0, 1, 0));
  // Subnasale: the mesher's vertex there.
  const int sn = skin.subnasale;
  // Pogonion: the most forward point of the chin. Menton: the bottom of
  // the chin, where the jaw line meets the midline (head_shape's jaw plane
  // and chin), below which the throat begins.
  const int pog = pk.extreme(mid_between(-0.115, V(li, 1) - 0.012), Vec3(0, 0, 1));
  const int men = pk.nearest(Vec3(0, -0.1125, 0.072), midline);

  add.add("2.1", S, men);
  add.add("2.2", S, mu[m_mid]);
  add.add("2.3", S, ml[m_mid]);
  add.add("2.4", S, mu[m_end]);
  add.add("2.5", S, mu[0]);
  // 2.6-2.9 follow the standard's FAP table (FAP 8 lower_t_lip_lm moves
  // 2.6) and figure: 2.6 and 2.8 lie on the left (toward 2.4). The
  // Candide-derived descriptions in mpeg4-fdp-list.csv swap the sides.
  add.add("2.6", S, along(V, mu, m_mid, m_end, 0.5));
  add.add("2.7", S, along(V, mu, m_mid, 0, 0.5));
  add.add("2.8", S, along(V, ml, m_mid, m_end, 0.5));
  add.add("2.9", S, along(V, ml, m_mid, 0, 0.5));
  add.add("2.10", S, pog);
  // Chin corners: on the jaw line either side of the chin.
  for (int s : {1, -1})
    add.add(s > 0 ? "2.11" : "2.12", S,
            pk.nearest(Vec3(s * 0.021, -0.106, 0.066), [&](int i) { return V(i, 0) * s > 0.004; }));
  // Jaw angles (gonion): on the mandible's corner below the ear.
  for (int s : {1, -1})
    add.add(s > 0 ? "2.13" : "2.14", S,
            pk.nearest(Vec3(s * 0.056, -0.083, 0.0), [&](int i) { return V(i, 0) * s > 0.03; }));

  // ---- group 3: eyes ----
  for (int e = 0; e < 2; ++e) {
    const std::vector<int> &up = skin.eye_upper[e], &lo = skin.eye_lower[e];
    const bool left = e == 0;
    // The lid centres: the upper margin's highest vertex and the one below it.
    int c = 0;
    for (int k = 0; k < (int)up.size(); ++k)
      if (V(up[k], 1) > V(up[c], 1)) c = k;
    add.add(left ? "3.1" : "3.2", S, up[c]);
    add.add(left ? "3.3" : "3.4", S, lo[c]);
    add.add(left ? "3.5" : "3.6", left ? EL : ER, left ? eye_l.key[0] : eye_r.key[0]);
    add.add(left ? "3.7" : "3.12", S, up.back());   // outer corner
    add.add(left ? "3.11" : "3.8", S, up.front());  // inner corner
    // Outer lid contours: the upper lid's fold under the brow, the lower
    // lid's border with the cheek.
    const Vec3 top = pk.at(up[c]), bottom = pk.at(lo[c]);
    add.add(left ? "3.13" : "3.14", S, pk.nearest(top + Vec3(0, 0.0072, 0), front(0.04), xy));
    add.add(left ? "3.9" : "3.10", S, pk.nearest(bottom - Vec3(0, 0.0062, 0), front(0.04), xy));
  }

  // ---- group 4: eyebrows ----
  for (int s : {1, -1}) {
    const bool left = s > 0;
    add.add(left ? "4.1" : "4.2", S,
            pk.nearest(Vec3(s * hd.brow_inner_x, hd.brow_inner_y, 0), front(0.04), xy));
    add.add(left ? "4.3" : "4.4", S,
            pk.nearest(Vec3(s * hd.brow_peak_x, hd.brow_peak_y, 0), front(0.04), xy));
    add.add(left ? "4.5" : "4.6", S,
            pk.nearest(Vec3(s * hd.brow_outer_x, hd.brow_outer_y, 0), front(0.03), xy));
  }

  // ---- group 5: cheeks ----
  for (int s : {1, -1}) {
    const bool left = s > 0;
    add.add(left ? "5.1" : "5.2", S, pk.nearest(Vec3(s * 0.047, -0.049, 0), front(0.03), xy));
    add.add(left ? "5.3" : "5.4", S, pk.nearest(Vec3(s * 0.043, -0.017, 0), front(0.03), xy));
  }

  // ---- group 6: tongue ----
  add.add("6.1", TG, tongue.key[0]);
  add.add("6.2", TG, tongue.key[1]);
  add.add("6.3", TG, tongue.key[2]);
  add.add("6.4", TG, tongue.key[3]);

  // ---- group 7: top of the spine, inside the neck behind the jaw ----
  add.add_free("7.1", Vec3(0.0, -0.036, -0.024));

  // ---- group 8: outer lip contour (the vermilion border) ----
  add.add("8.1", S, ls);
  add.add("8.2", S, li);
  add.add("8.3", S, mu[m_end]);  // a closed mouth's outer corners are its inner ones
  add.add("8.4", S, mu[0]);
  for (int s : {1, -1}) {
    const bool left = s > 0;
    auto lipfront = [&](int i) { return V(i, 2) > 0.06 && !slit[i]; };
    double uy, ly;
    // Midpoints between the corner and the middle, along the border.
    const double xm = 0.52 * hd.mouth_half_width;
    refhead::lip_borders(xm, &uy, &ly);
    add.add(left ? "8.5" : "8.6", S, pk.nearest(Vec3(s * xm, uy, 0), lipfront, xy));
    add.add(left ? "8.7" : "8.8", S, pk.nearest(Vec3(s * xm, ly, 0), lipfront, xy));
    // Peaks of the cupid's bow (off the midline even on coarse meshes).
    const double xb = 0.22 * hd.mouth_half_width;
    refhead::lip_borders(xb, &uy, &ly);
    add.add(left ? "8.10" : "8.9", S, pk.nearest(Vec3(s * xb, uy, 0), [&](int i) {
      return lipfront(i) && V(i, 0) * s > 0.001;
    }, xy));
  }

  // ---- group 9: nose and teeth ----
  {
    for (int s : {1, -1}) {
      const bool left = s > 0;
      // Nostril outer border: the outside of the ala (head_shape's alae).
      add.add(left ? "9.1" : "9.2", S,
              pk.nearest(Vec3(s * 0.0182, -0.0268, 0.0885), [&](int i) { return V(i, 0) * s > 0; }));
      add.add(left ? "9.5" : "9.4", S,
              pk.nearest(Vec3(s * 0.0105, -0.0335, 0), front(0.085), xy));
      add.add(left ? "9.7" : "9.6", S, pk.nearest(Vec3(s * 0.0062, 0.005, 0), front(0.07), xy));
      add.add(left ? "9.13" : "9.14", S,
              pk.nearest(Vec3(s * 0.0074, -0.012, 0), front(0.08), xy));
    }
  }
  add.add("9.3", S, tip);
  add.add("9.8", TU, teeth_u.key[1]);
  add.add("9.9", TL, teeth_l.key[1]);
  add.add("9.10", TU, teeth_u.key[0]);
  add.add("9.11", TL, teeth_l.key[0]);
  add.add("9.12", S, pk.nearest(Vec3(0, -0.012, 0), midline, Vec3(0, 1, 0)));
  add.add("9.15", S, sn);

  // ---- group 10: ears, in each ear's own frame ----
  for (int s : {1, -1}) {
    const bool left = s > 0;
    auto local = [&](int i) {
      return refhead::ear_local(Vec3(V(i, 0) * s, V(i, 1), V(i, 2)));
    };
    // The ear: vertices standing out of the head inside the ear's outline.
    const std::vector<int> ear = pk.where([&](int i) {
      if (V(i, 0) * s < 0.05) return false;
      const Vec3 l = local(i);
      return std::pow(l.x() / 0.036, 2) + std::pow(l.y() / 0.021, 2) < 1.0 && l.z() > -0.004;
    });
    auto pick = [&](const std::function<double(const Vec3 &)> &score) {
      int best = -1;
      double best_s = -std::numeric_limits<double>::infinity();
      for (int i : ear) {
        const double sc = score(local(i));
        if (sc > best_s) {
          best_s = sc;
          best = i;
        }
      }
      return best;
    };
    add.add(left ? "10.1" : "10.2", S, pick([](const Vec3 &l) { return l.x() + 0.3 * l.z(); }));
    add.add(left ? "10.3" : "10.4", S,
            pick([](const Vec3 &l) { return l.y() + 0.3 * l.z() - 2.0 * std::abs(l.x()); }));
    add.add(left ? "10.5" : "10.6", S, pick([](const Vec3 &l) { return -l.x() + 0.3 * l.z(); }));
    // Contact points: where the ear's front edge meets the face.
    add.add(left ? "10.9" : "10.10", S,
            pick([](const Vec3 &l) { return -l.y() - 3.0 * std::abs(l.x() - 0.015) - 2.0 * l.z(); }));
    add.add(left ? "10.7" : "10.8", S,
            pick([](const Vec3 &l) { return -l.y() - 3.0 * std::abs(l.x() + 0.017) - 2.0 * l.z(); }));
  }

  // ---- group 11: hairline and skull ----
  add.add("11.1", S, pk.nearest(Vec3(0, hd.hairline_y, 0), midline, Vec3(0, 1, 0)));
  // The hairline's corners over the temples (the painted hair's border).
  for (int s : {1, -1}) {
    const double phi = 0.62, r = 0.075;  // head_shape's temple key point
    const Vec3 at(s * r * std::sin(phi), refhead::hairline_y(phi), hd.axis_z + r * std::cos(phi));
    add.add(s > 0 ? "11.3" : "11.2", S,
            pk.nearest(at, [&](int i) { return V(i, 0) * s > 0 && V(i, 2) > 0.0; }, xy));
  }
  add.add("11.4", S, skin.top);
  // No hair part: the hair is zero thick, so 11.5 coincides with 11.4.
  add.add("11.5", S, skin.top);
  {
    const std::vector<int> back =
        pk.where([&](int i) { return V(i, 0) == 0.0 && V(i, 2) < hd.axis_z && V(i, 1) > -0.06; });
    add.add("11.6", S, pk.extreme(back, Vec3(0, 0, -1)));
  }
  std::sort(fdps.points.begin(), fdps.points.end(),
            [](const FdpPoint &a, const FdpPoint &b) { return a.id < b.id; });
  return add.missing;
}

}  // namespace

Expected<RefHead> make_reference_head(const RefHeadOptions &options) {
  const int n = options.skin_vertices;
  if (n < 1000 || n > 100000)
    return Status::error("reference head: skin_vertices must be in 1000..100000, got " +
                         std::to_string(n));
  const HeadDesign &hd = refhead::head_design();
  Expected<SkinMesh> skin = refhead::build_skin(n);
  if (!skin) return skin.status();

  const int detail = std::clamp((int)std::lround(std::sqrt((double)n) / 5.0), 16, 48);
  const Vec3 el = hd.eye_centre, er(-el.x(), el.y(), el.z());
  const PartMesh eye_l = refhead::make_eyeball(el, hd.eye_radius, hd.iris_radius, hd.pupil_radius, detail);
  const PartMesh eye_r = refhead::make_eyeball(er, hd.eye_radius, hd.iris_radius, hd.pupil_radius, detail);
  const double edge_y = hd.mouth_y - 0.0015, front_z = 0.0885;
  const PartMesh teeth_u = refhead::make_teeth(true, edge_y, front_z, detail);
  const PartMesh teeth_l = refhead::make_teeth(false, edge_y, front_z, detail);
  const PartMesh tongue = refhead::make_tongue(edge_y - 0.0015, front_z - 0.0085, detail);

  RefHead head;
  Scene &sc = head.scene;
  sc.name = "refhead";
  sc.units = "m";
  sc.source = "make_reference_head(" + std::to_string(n) + ")";
  {
    Part p;
    p.name = "skin";
    p.kind = PartKind::Skin;
    p.V = skin->V;
    p.F = skin->F;
    p.TC = skin->TC;
    p.FTC = skin->FTC;
    p.C = skin->C;
    p.diffuse = Vec3(0.86, 0.66, 0.55);
    sc.parts.push_back(std::move(p));
  }
  sc.parts.push_back(make_part("eye_left", PartKind::EyeLeft, eye_l, Vec3(0.94, 0.92, 0.88)));
  sc.parts.push_back(make_part("eye_right", PartKind::EyeRight, eye_r, Vec3(0.94, 0.92, 0.88)));
  sc.parts.push_back(make_part("teeth_upper", PartKind::TeethUpper, teeth_u, Vec3(0.93, 0.91, 0.84)));
  sc.parts.push_back(make_part("teeth_lower", PartKind::TeethLower, teeth_l, Vec3(0.93, 0.91, 0.84)));
  sc.parts.push_back(make_part("tongue", PartKind::Tongue, tongue, Vec3(0.80, 0.42, 0.45)));

  head.fdps.source = sc.source;
  const std::string missing = place_fdps(*skin, sc, eye_l, eye_r, teeth_u, teeth_l, tongue, head.fdps);
  if (!missing.empty())
    return Status::error("reference head: internal error: no vertex found for FDP " + missing +
                         " at " + std::to_string(n) + " skin vertices");
  return head;
}

}  // namespace afmb
