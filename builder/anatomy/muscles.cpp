#include "anatomy/muscles.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

namespace afmb {

namespace {

constexpr double kHalfPi = 1.5707963267948966;

double segment_distance(const Eigen::Vector3d &p, const Eigen::Vector3d &a, const Eigen::Vector3d &b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

Status missing(const MuscleDef &d, const std::vector<FdpId> &ids) {
  std::string list;
  for (const FdpId &id : ids) list += (list.empty() ? "" : ", ") + id.str();
  return Status::error(std::string("muscle ") + d.name + " needs FDP" + (ids.size() > 1 ? "s " : " ") + list);
}

// A dead load: force c w_i u_i on each influence vertex, shared by the
// layers it acts on, u_i its direction at rest (`direction` of the vertex
// and each node's rest position; zero: no force); potential
// -c sum_i w_i (p_i - p0_i) . u_i over those nodes, by their share.
template <class Direction>
double dead_load(const SkinModel &skin, const Muscle &m, double c, const Direction &direction,
                 const Eigen::MatrixXd &X, Eigen::MatrixXd *F) {
  double energy = 0;
  // The layers that share it: a muscle inside the tissue it moves, the
  // three evenly; a linear muscle, its force layer (the dermis) and the
  // epidermis by TissueParams::skin_load_share; else its force layer.
  const bool whole = muscle_table()[static_cast<size_t>(m.def)].whole_thickness;
  const double epidermis = !whole && m.kind == MuscleKind::Linear ? skin.params.skin_load_share : 0.0;
  const int first = whole || epidermis > 0 ? kEpidermis : m.force_layer;
  const int last = whole ? kHypodermis : m.force_layer;
  for (size_t i = 0; i < m.influence.size(); ++i)
    for (int layer = first; layer <= last; ++layer) {
      const double share = whole ? 1.0 / 3 : layer == m.force_layer ? 1 - epidermis : epidermis;
      const int node = skin.node(layer, m.influence[i]);
      const Eigen::Vector3d x0 = skin.X0.row(node);
      const Eigen::Vector3d u = direction(m.influence[i], x0);
      energy -= c * share * m.weight[i] * (X.row(node).transpose() - x0).dot(u);
      if (F) F->row(node) += (c * share * m.weight[i]) * u.transpose();
    }
  return energy;
}

// The unit direction in which a linear muscle pulls skin vertex v, whose
// force node rests at x0, along its PullLine: toward the attachment's skull
// node, or its key point (a push from below the skin: from the skull node,
// a tissue's depth behind, the push came out of the face); for a muscle
// that lies along the bone, the skull line's part in the skin's tangent
// plane at v, at full length, since the fibre wraps over the skull and the
// bone takes its normal part (zero where the attachment lies along the
// normal).
Eigen::Vector3d linear_pull(const SkinModel &skin, const Muscle &m, int v, const Eigen::Vector3d &x0) {
  const PullLine line = muscle_table()[static_cast<size_t>(m.def)].line;
  const Eigen::Vector3d a = line == PullLine::Key ? m.key_a : Eigen::Vector3d(skin.X0.row(m.node_a).transpose());
  const Eigen::Vector3d d = (a - x0).normalized();
  if (line != PullLine::Surface) return d;
  const Eigen::Vector3d nrm = skin.normal.row(v).transpose();
  const Eigen::Vector3d t = d - nrm.dot(d) * nrm;
  const double len = t.norm();
  return len > 1e-6 ? Eigen::Vector3d(t / len) : Eigen::Vector3d::Zero();
}

// Breadth-first search over the skin mesh from vertex `start` through the
// vertices `inside` accepts. Returns the vertices reached, sorted (none when
// `start` is not inside).
template <class Inside>
std::vector<int> grow_region(const SkinModel &skin, int start, const Inside &inside) {
  std::vector<int> out;
  if (start < 0 || start >= skin.n || !inside(start)) return out;
  std::vector<uint8_t> seen(static_cast<size_t>(skin.n), 0);
  std::deque<int> queue{start};
  seen[static_cast<size_t>(start)] = 1;
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    out.push_back(v);
    for (int u : skin.neighbours[static_cast<size_t>(v)])
      if (!seen[static_cast<size_t>(u)] && inside(u)) {
        seen[static_cast<size_t>(u)] = 1;
        queue.push_back(u);
      }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The lid's turn about its axis: the offset of p from the axis line and
// its distance rho from it.
struct AxisOffset {
  Eigen::Vector3d d;  // p - c without its component along the axis
  double rho;
};
AxisOffset axis_offset(const Muscle &m, const Eigen::Vector3d &p) {
  Eigen::Vector3d d = p - m.epicentre;
  d -= d.dot(m.axis) * m.axis;
  return {d, d.norm()};
}
// The angle from a to b about the axis (positive: the sense of axis x a).
double turn(const Muscle &m, const Eigen::Vector3d &a, const Eigen::Vector3d &b) {
  return std::atan2(m.axis.dot(a.cross(b)), a.dot(b));
}
// Nodes nearer the axis than this share of the eyeball's radius get no lid
// load: their pull would grow as 1 / rho.
constexpr double kLidAxisFloor = 0.5;
// The tarsus: the part of the lid's turn from the margin (alpha 0) to its
// area's far edge that it spans.
constexpr double kTarsusShare = 0.3;
// Across the lid the load falls to nothing at the eye's corners, as
// cos(pi/2 q^2) on an upper lid and cos(pi/2 q) on a lower one (q: 0 over
// the margin's key point, 1 at a corner). An upper margin rises and falls
// over nearly its whole width; a lower one moves in its middle, held at the
// corners. With q^2 on the lower lids, the 10k head's lower margin two
// thirds of the way to its inner corner took 0.75 of the middle's load,
// came down 3 mm with the middle's 3.5 and turned the triangle between it,
// the corner and the skin below over: its lids lowered (FAPs 21, 22) stopped
// at 86 % of the reference, and its lower drivers found no equilibrium at
// +100 % (calibrated to half of it). With q, 0.48 there: both reach.

Status place_lid(const SkinModel &skin, const Eigen::Vector3d &outer, const Eigen::Vector3d &inner, Muscle &m) {
  m.force_layer = kEpidermis;
  m.node_a = nearest_node(skin, kEpidermis, m.key_a);
  m.node_b = nearest_node(skin, kEpidermis, m.key_b);
  const int va = skin.vertex_of(m.node_a);
  const Eigen::Vector3d a = skin.X0.row(m.node_a), b = skin.X0.row(m.node_b);
  // The eyeball the margin lies on: within half a radius of its surface (a
  // lower margin faces up, away from it, and is not SkinModel::eye_of).
  double nearest = 0.5;
  for (size_t e = 0; e < skin.eyes.size(); ++e) {
    const double off = std::abs((a - skin.eyes[e].centre).norm() / skin.eyes[e].radius - 1);
    if (off < nearest) nearest = off, m.eye = static_cast<int>(e);
  }
  if (m.eye < 0)
    return Status::error("muscle " + m.name + ": its lid margin does not lie on an eyeball (no eye part there)");
  const EyeSphere &eye = skin.eyes[static_cast<size_t>(m.eye)];
  m.epicentre = eye.centre;
  m.length = (a - b).norm();
  if (!(m.length > 0)) return Status::error("muscle " + m.name + ": the lid margins map to one point");
  // Turning about +x takes the front of the eyeball down: the upper lid's way.
  const double side = a.y() > b.y() ? 1.0 : -1.0;
  m.axis = Eigen::Vector3d(side, 0, 0);
  const double mid = 0.5 * (a.y() + b.y());
  const AxisOffset oa = axis_offset(m, a);
  // The lid: the skin reached from the margin on its side of the opening,
  // within the eyeball's width and half a radius of its surface. That takes
  // in the margin's underside and the skin turning into the socket behind
  // it, which point away from the eyeball and are not SkinModel::eye_of.
  auto in_lid = [&](int v) {
    if (!skin.in_mesh[static_cast<size_t>(v)]) return false;
    const Eigen::Vector3d p = skin.X0.row(skin.node(kEpidermis, v));
    return (p.y() - mid) * side > 0 && std::abs(p.x() - eye.centre.x()) < eye.radius &&
           (p - eye.centre).norm() < 1.5 * eye.radius;
  };
  const std::vector<int> area = grow_region(skin, va, in_lid);
  std::vector<double> alpha, across;
  for (int v : area) {
    const Eigen::Vector3d p = skin.X0.row(skin.node(kEpidermis, v));
    alpha.push_back(-turn(m, oa.d, axis_offset(m, p).d));  // away from the opening
    // 0 over the margin's key point, 1 at the corner on p's side.
    const double corner = (p.x() - a.x()) * (outer.x() - a.x()) >= 0 ? outer.x() : inner.x();
    across.push_back(corner != a.x() ? std::min(1.0, (p.x() - a.x()) / (corner - a.x())) : 1.0);
  }
  double alpha_max = 0;
  for (double x : alpha) alpha_max = std::max(alpha_max, x);
  // The opening the lid closes, across it: at each x, the turn from this
  // lid's margin to the other lid's. A lid turned as a whole (face_model.h,
  // place_turned_lid) turns each vertex by its x's share of the turn at a's
  // x, so that the whole margin meets the other lid together; little toward
  // the corners, where the lids meet at rest.
  auto other_lid = [&](int v) {
    if (!skin.in_mesh[static_cast<size_t>(v)]) return false;
    const Eigen::Vector3d p = skin.X0.row(skin.node(kEpidermis, v));
    return (p.y() - mid) * side < 0 && std::abs(p.x() - eye.centre.x()) < eye.radius &&
           (p - eye.centre).norm() < 1.5 * eye.radius;
  };
  const std::vector<int> other = grow_region(skin, skin.vertex_of(m.node_b), other_lid);
  // Only the skin over the eyeball (SkinModel::eye_of) bounds the opening:
  // the margin's underside turns into the socket, further than the margin.
  // Each margin is the envelope of its skin's turns, as points (x, turn):
  // for this lid the highest of turn - K |x - x_v|, for the other the lowest
  // of turn + K |x - x_v|, K one radian per sixth of the eyeball's radius:
  // through the margin's vertices and linear between them, and continuous
  // in x (a window's extremes jump as vertices enter it, and a jump in the
  // share between two vertices of the margin turned one below the other).
  auto over = [&](int v) { return skin.eye_of[static_cast<size_t>(v)] == m.eye; };
  std::vector<Eigen::Vector2d> own_points, far_points;
  for (size_t i = 0; i < area.size(); ++i)
    if (over(area[i])) own_points.emplace_back(skin.X0(skin.node(kEpidermis, area[i]), 0), -alpha[i]);
  for (int v : other) {
    const Eigen::Vector3d p = skin.X0.row(skin.node(kEpidermis, v));
    if (over(v)) far_points.emplace_back(p.x(), turn(m, oa.d, axis_offset(m, p).d));
  }
  const double slope = 6 / eye.radius;
  auto gap = [&](double x) {  // NaN where either lid has no skin over the eyeball
    double own = -std::numeric_limits<double>::infinity(), far = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d &q : own_points) own = std::max(own, q.y() - slope * std::abs(x - q.x()));
    for (const Eigen::Vector2d &q : far_points) far = std::min(far, q.y() + slope * std::abs(x - q.x()));
    return std::isfinite(own) && std::isfinite(far) ? far - own : std::numeric_limits<double>::quiet_NaN();
  };
  const double gap_a = gap(a.x());
  m.closing_turn = std::isfinite(gap_a) ? std::max(gap_a, 0.0) : 0.0;
  const double band = kTarsusShare * alpha_max;
  for (size_t i = 0; i < area.size(); ++i) {
    const double g = alpha[i] <= 0 ? 1.0 : std::pow(1 - alpha[i] / alpha_max, 4);
    const double q = across[i];
    const double h = std::cos(kHalfPi * (side > 0 ? q * q : q));
    const double w = skin.area[area[i]] * g * h;
    if (!(w > 0)) continue;
    m.influence.push_back(area[i]);
    m.weight.push_back(w);
    const bool on_tarsus = alpha[i] <= band;
    const double gx = gap(skin.X0(skin.node(kEpidermis, area[i]), 0));
    const double share = !(gap_a > 0) ? 0.0 : std::isfinite(gx) ? std::clamp(gx / gap_a, 0.0, 1.0) : h;
    m.tarsus.push_back(on_tarsus);
    m.turn_share.push_back(on_tarsus ? share : share * std::pow(1 - (alpha[i] - band) / (alpha_max - band), 2));
  }
  return Status::ok();
}

// The node of `layer` a key point maps to: the nearest (section 3.2), except
// that a key point that is one FDP keeps the FDP's own vertex among vertices
// at the same place. A closed mouth's lip line has two vertices at each
// point, one per lip (the generated heads): by index order mentalis' insertion
// 2.8 went to the upper lip's vertex, 2.6's, and its calibration measured the
// upper lip.
int key_node(const SkinModel &skin, const FdpSet &fdps, int layer, const Keypoint &k, const Eigen::Vector3d &p) {
  const int best = nearest_node(skin, layer, p);
  if (best < 0 || k.terms.size() != 1 || k.terms[0].second != 1) return best;
  const FdpPoint *f = fdps.find(k.terms[0].first, skin.part);
  if (!f || f->vertex < 0 || f->vertex >= skin.n || !skin.in_mesh[static_cast<size_t>(f->vertex)]) return best;
  const int v = skin.vertex_of(best);
  const bool same_place = skin.X0.row(skin.node(kEpidermis, v)) == skin.X0.row(skin.node(kEpidermis, f->vertex)) &&
                          skin.X0.row(best) == skin.X0.row(skin.node(layer, f->vertex));
  return same_place ? skin.node(layer, f->vertex) : best;
}

}  // namespace

Expected<Muscle> place_muscle(const SkinModel &skin, const FdpSet &fdps, int def) {
  const MuscleDef &d = muscle_table()[static_cast<size_t>(def)];
  Muscle m;
  m.def = def;
  m.name = d.name;
  m.kind = d.kind;
  m.sense = d.sense;
  m.width = d.width;
  std::vector<Keypoint> keys;
  std::vector<FdpId> absent;
  for (const char *text : {d.attachment_or_major, d.insertion_or_minor, d.epicentre, d.corner_outer, d.corner_inner}) {
    if (!text) continue;
    Expected<Keypoint> k = parse_keypoint(text);
    if (!k) return k.status();
    for (const FdpId &id : missing_fdps(*k, fdps))
      if (std::find(absent.begin(), absent.end(), id) == absent.end()) absent.push_back(id);
    keys.push_back(*k);
  }
  if (!absent.empty()) return missing(d, absent);
  m.key_a = eval_keypoint(keys[0], fdps);
  m.key_b = eval_keypoint(keys[1], fdps);

  if (d.kind == MuscleKind::Linear) {
    m.force_layer = kDermis;
    m.node_a = key_node(skin, fdps, kSkull, keys[0], m.key_a);
    m.node_b = key_node(skin, fdps, kDermis, keys[1], m.key_b);
    // A muscle inside the tissue it moves (whole_thickness) has no skull
    // attachment: its fibre runs from the key point itself. The skull node
    // nearest a point inside the mouth or the nose, or beside the nose's
    // tip, can lie anywhere (the 2,000-vertex head's lip drivers took one
    // on a cheek, to one side).
    const Eigen::Vector3d a = d.whole_thickness ? m.key_a : Eigen::Vector3d(skin.X0.row(m.node_a).transpose());
    const Eigen::Vector3d b = skin.X0.row(m.node_b);
    m.length = (b - a).norm();
    if (!(m.length > 0))
      return Status::error(std::string("muscle ") + d.name + ": attachment and insertion map to one point");
    const double reach = m.width * m.length;
    for (int v = 0; v < skin.n; ++v) {
      if (!skin.in_mesh[static_cast<size_t>(v)]) continue;
      const Eigen::Vector3d p = skin.X0.row(skin.node(kDermis, v));
      if (segment_distance(p, a, b) >= reach) continue;
      const double D = (p - a).norm();
      const double cosa = D > 0 ? (p - a).dot(b - a) / (D * m.length) : 0.0;
      double radial = 0;
      if (D <= m.length) radial = std::sin(kHalfPi * D / m.length);
      else if (D <= m.length + reach) radial = std::cos(kHalfPi * (D - m.length) / reach);
      const double w = skin.area[v] * std::max(0.0, cosa) * radial;
      if (w <= 0) continue;
      m.influence.push_back(v);
      m.weight.push_back(w);
    }
  } else if (d.kind == MuscleKind::Lid) {
    if (keys.size() != 4) return Status::error(std::string("muscle ") + d.name + ": the table lacks its corners");
    if (Status st = place_lid(skin, eval_keypoint(keys[2], fdps), eval_keypoint(keys[3], fdps), m); !st) return st;
  } else {
    m.force_layer = kHypodermis;
    m.epicentre = eval_keypoint(keys[2], fdps);
    m.node_a = key_node(skin, fdps, kHypodermis, keys[0], m.key_a);
    m.node_b = key_node(skin, fdps, kHypodermis, keys[1], m.key_b);
    m.semi_a = std::abs(skin.X0(m.node_a, 0) - m.epicentre.x());
    m.semi_b = std::abs(skin.X0(m.node_b, 1) - m.epicentre.y());
    if (!(m.semi_a > 0) || !(m.semi_b > 0))
      return Status::error(std::string("muscle ") + d.name + ": a semi-axis has zero length");
    // The influence area is found on the skin's surface, where the FDPs are:
    // the ellipse through the key points themselves, the skin vertices
    // tested. (With the hypodermis nodes, traced toward the centre of
    // gravity, against the FDPs' epicentre, Song's mouth ellipse was 0.86
    // units high and its area missed the upper lip: the lower lip's inner
    // nodes rise toward the mouth's centre, the upper lip's away from it.)
    m.area_a = std::abs(m.key_a.x() - m.epicentre.x());
    m.area_b = std::abs(m.key_b.y() - m.epicentre.y());
    if (!(m.area_a > 0) || !(m.area_b > 0))
      return Status::error(std::string("muscle ") + d.name + ": a semi-axis has zero length");
    // Equation 2's normal at the epicentre: the epicentre lies in an
    // orifice, where there is no skin; the vertex nearest it is on the rim,
    // turned into the orifice (Song's eyes' pointed down, its mouth's up),
    // and the skin within the ellipse folds into the socket and the mouth
    // (the mean of its normals on Song's whole skin pointed backward). The
    // paper's intent is the front of the face: +z, the gaze of the MPEG-4
    // neutral frame, as it notes for equation 1: a normal's z.
    for (int v = 0; v < skin.n; ++v) {
      if (!skin.in_mesh[static_cast<size_t>(v)]) continue;
      const Eigen::Vector3d p = skin.X0.row(skin.node(kEpidermis, v));
      const double ex = (p.x() - m.epicentre.x()) / m.area_a, ey = (p.y() - m.epicentre.y()) / m.area_b;
      const double rho = std::sqrt(ex * ex + ey * ey);
      if (rho > m.width) continue;                                    // equation 1
      if (skin.normal(v, 2) < 0) continue;                            // equation 2
      const double g = rho <= 1 ? 1.0 : std::cos(kHalfPi * (rho - 1) / (m.width - 1));
      const double w = skin.area[v] * g;
      if (w <= 0) continue;
      m.influence.push_back(v);
      m.weight.push_back(w);
    }
  }
  if (m.influence.empty())
    return Status::error(std::string("muscle ") + d.name + ": no skin node in its influence area");
  return m;
}

Expected<MouthWindow> mouth_window(const FdpSet &fdps) {
  auto need = [&](const char *id) -> const FdpPoint * { return fdps.find(*FdpId::parse(id)); };
  const FdpPoint *p22 = need("2.2"), *p24 = need("2.4"), *p25 = need("2.5");
  if (!p22 || !p24 || !p25) return Status::error("mouth window needs FDPs 2.2, 2.4 and 2.5");
  MouthWindow w;
  if (const FdpPoint *p = need("9.15")) {
    w.top = p->pos.y();
  } else if (const FdpPoint *t = need("9.3"), *u = need("8.1"); t && u) {
    w.top = t->pos.y() + (u->pos.y() - t->pos.y()) / 4;  // the FAPU's nose-base rule
  } else {
    return Status::error("mouth window needs FDP 9.15, or 9.3 and 8.1");
  }
  if (const FdpPoint *p = need("2.11")) w.bottom = p->pos.y() - std::abs((p->pos.y() - p22->pos.y()) / 2);
  else if (const FdpPoint *c = need("2.1")) w.bottom = c->pos.y();
  else return Status::error("mouth window needs FDP 2.11 or 2.1");
  w.left = std::min(p24->pos.x(), p25->pos.x());
  w.right = std::max(p24->pos.x(), p25->pos.x());
  return w;
}

std::vector<int> mouth_window_search(const SkinModel &skin, const MouthWindow &w, int start) {
  auto inside = [&](int v) {
    const Eigen::Vector3d p = skin.X0.row(v);
    return p.x() > w.left && p.x() < w.right && p.y() > w.bottom && p.y() < w.top;
  };
  return grow_region(skin, start, inside);
}

Expected<MouthLips> mouth_lips(const SkinModel &skin, const FdpSet &fdps) {
  Expected<MouthWindow> w = mouth_window(fdps);
  if (!w) return w.status();
  auto start = [&](const char *id) {
    const FdpPoint *p = fdps.find(*FdpId::parse(id), skin.part);
    if (p->part == skin.part && p->vertex >= 0) return p->vertex;
    return skin.vertex_of(nearest_node(skin, kEpidermis, p->pos));
  };
  MouthLips lips;
  lips.upper = mouth_window_search(skin, *w, start("2.2"));
  lips.lower = mouth_window_search(skin, *w, start("2.3"));
  return lips;
}

void remove_from_influence(Muscle &m, const std::vector<int> &vertices) {
  std::vector<int> inf;
  std::vector<double> w, share;
  std::vector<char> tarsus;
  const bool lid = !m.turn_share.empty();
  for (size_t i = 0; i < m.influence.size(); ++i)
    if (!std::binary_search(vertices.begin(), vertices.end(), m.influence[i])) {
      inf.push_back(m.influence[i]);
      w.push_back(m.weight[i]);
      if (lid) share.push_back(m.turn_share[i]), tarsus.push_back(m.tarsus[i]);
    }
  m.influence = std::move(inf);
  m.weight = std::move(w);
  m.turn_share = std::move(share);
  m.tarsus = std::move(tarsus);
}

double muscle_load(const SkinModel &skin, const Muscle &m, double tension, const Eigen::MatrixXd &X,
                   Eigen::MatrixXd *F, NodeBlocks *K) {
  if (tension == 0) return 0.0;
  const double s = m.sense * tension;
  double energy = 0;
  if (m.kind == MuscleKind::Linear) {
    // Directions at rest: a pull toward a moving point is stable, a push
    // away from one (mentalis, negative contractions) is not, transversally.
    energy = dead_load(skin, m, s, [&](int v, const Eigen::Vector3d &x0) { return linear_pull(skin, m, v, x0); }, X,
                       F);
  } else if (m.kind == MuscleKind::Lid) {
    if (m.eye < 0 || static_cast<size_t>(m.eye) >= skin.eyes.size()) return 0.0;  // a model without its eyeball
    const double radius = skin.eyes[static_cast<size_t>(m.eye)].radius, floor = kLidAxisFloor * radius;
    for (size_t i = 0; i < m.influence.size(); ++i) {
      for (int layer = kEpidermis; layer <= kHypodermis; ++layer) {
        const int node = skin.node(layer, m.influence[i]);
        const AxisOffset o0 = axis_offset(m, skin.X0.row(node));
        if (o0.rho < floor) continue;
        const AxisOffset o = axis_offset(m, X.row(node));
        const double c = s * m.weight[i] / 3 * o0.rho * o0.rho / radius;  // potential -c theta
        energy -= c * turn(m, o0.d, o.d);
        const double rr = o.rho * o.rho;
        if (F) F->row(node) += (c / rr) * m.axis.cross(o.d).transpose();
        if (K) {
          // The Hessian of -c theta is alpha R in (y, z), R = [2yz, z^2 - y^2;
          // z^2 - y^2, -2yz] / rho^2 (a reflection) and alpha = -c axis.x / rho^2:
          // indefinite, eigenvalues +-|alpha|. Its positive part goes into the
          // tangent (with the whole of it the tangent was indefinite and CG
          // stalled on the 2k head's lids; without any, Newton crawled).
          const double y = o.d.y() / o.rho, z = o.d.z() / o.rho, alpha = -c * m.axis.x() / rr;
          Eigen::Matrix2d R;
          R << 2 * y * z, z * z - y * y, z * z - y * y, -2 * y * z;
          Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
          H.block<2, 2>(1, 1) = 0.5 * std::abs(alpha) * (Eigen::Matrix2d::Identity() + (alpha > 0 ? 1.0 : -1.0) * R);
          K->emplace_back(node, H);
        }
      }
    }
  } else if (s < 0) {
    // Widening: a dead load outward along the rest direction from the
    // epicentre. A push away from the moving epicentre direction would be
    // unstable around it (negative stiffness across the radius).
    energy = dead_load(skin, m, -s, [&](int, const Eigen::Vector3d &x0) {
      const Eigen::Vector3d d0(x0.x() - m.epicentre.x(), x0.y() - m.epicentre.y(), 0.0);
      return d0.norm() > 0 ? Eigen::Vector3d(d0.normalized()) : Eigen::Vector3d::Zero().eval();
    }, X, F);
  } else {
    const double floor = m.semi_b / 3;
    for (size_t i = 0; i < m.influence.size(); ++i) {
      const int node = skin.node(m.force_layer, m.influence[i]);
      const Eigen::Vector3d d(X(node, 0) - m.epicentre.x(), X(node, 1) - m.epicentre.y(), 0.0);
      const double r = d.norm();
      energy += s * m.weight[i] * (r >= floor ? r : r * r / (2 * floor) + floor / 2);
      if (F) F->row(node) -= (s * m.weight[i] / std::max(r, floor)) * d.transpose();
      if (K) {
        // Hessian of s w h(r) in x-y: s w (I - u u^T) / r beyond the floor
        // (the pull turns with the node), s w I / floor within it.
        Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
        H(0, 0) = H(1, 1) = 1;
        if (r >= floor) {
          const Eigen::Vector3d u = d / r;
          H = (H - u * u.transpose()) / r;
        } else {
          H /= floor;
        }
        K->emplace_back(node, (s * m.weight[i]) * H);
      }
    }
  }
  return energy;
}

double muscle_action(const SkinModel &skin, const Muscle &m, const Eigen::MatrixXd &X, Eigen::MatrixXd *gradient) {
  if (m.kind == MuscleKind::Linear) {
    // Along the insertion's own pull.
    const Eigen::Vector3d b0 = skin.X0.row(m.node_b), b = X.row(m.node_b);
    const Eigen::Vector3d dir = m.sense * linear_pull(skin, m, skin.vertex_of(m.node_b), b0);
    if (gradient) gradient->row(m.node_b) += dir.transpose();
    return (b - b0).dot(dir);
  }
  if (m.kind == MuscleKind::Lid) {
    const AxisOffset o0 = axis_offset(m, skin.X0.row(m.node_a)), o = axis_offset(m, X.row(m.node_a));
    if (gradient && o.rho > 0) gradient->row(m.node_a) += (o0.rho / (o.rho * o.rho)) * m.axis.cross(o.d).transpose();
    return o0.rho * turn(m, o0.d, o.d);
  }
  const bool minor = muscle_table()[static_cast<size_t>(m.def)].calibrate_minor;
  const int node = minor ? m.node_b : m.node_a;
  auto offset = [&](const Eigen::MatrixXd &P) {
    return Eigen::Vector2d(P(node, 0) - m.epicentre.x(), P(node, 1) - m.epicentre.y());
  };
  const Eigen::Vector2d d = offset(X);
  if (gradient && d.norm() > 0) gradient->row(node).head<2>() -= d.normalized().transpose();
  return offset(skin.X0).norm() - d.norm();
}

double muscle_action_target(const Muscle &m, bool maximum) {
  const MuscleDef &d = muscle_table()[static_cast<size_t>(m.def)];
  const double scale = m.kind != MuscleKind::Sphincter ? m.length : (d.calibrate_minor ? m.semi_b : m.semi_a);
  return maximum ? d.max_fraction * m.range_max * scale : -d.min_fraction * m.range_min * scale;
}

}  // namespace afmb
