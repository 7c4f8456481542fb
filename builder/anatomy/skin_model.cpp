#include "anatomy/skin_model.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "core/normals.h"

namespace afmb {

namespace {

// The three tetrahedra of a slab prism, as corners: 0-2 the upper triangle,
// 3-5 the lower one. A fixed split; every element uses the same.
constexpr int kTets[3][4] = {{0, 1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4, 5}};

double tet_volume(const Eigen::Vector3d &p0, const Eigen::Vector3d &p1, const Eigen::Vector3d &p2,
                  const Eigen::Vector3d &p3) {
  return (p1 - p0).dot((p2 - p0).cross(p3 - p0)) / 6.0;
}

// The six corners of slab `slab` of element f: nodes (3 below the other 3)
// and their rows in element_volume()'s gradient (-1 for the skull's corners,
// which are never solved for).
void slab_corners(const SkinModel &m, int f, int slab, int node[6], int row[6]) {
  for (int k = 0; k < 3; ++k) {
    node[k] = m.node(slab, m.F(f, k));
    node[3 + k] = m.node(slab + 1, m.F(f, k));
    row[k] = slab * 3 + k;
    row[3 + k] = slab < 2 ? (slab + 1) * 3 + k : -1;
  }
}

// Spring indices by node pair, open addressing with linear probing. The
// unordered_map it replaced allocated a node per spring: Song's whole skin
// (86,000 springs) took 65 ms to build, 43 ms with this index; the 10k
// head's (299,000) 276 and 165 ms (first builds in a process; a benchmark
// scratch program).
class PairIndex {
 public:
  explicit PairIndex(size_t expected) { rehash(expected); }

  // The value stored for `key`; else stores `value` for it and returns -1.
  int find_or_insert(uint64_t key, int value) {
    if (2 * (size_ + 1) > keys_.size()) rehash(keys_.size());
    size_t i = slot(key);
    for (; keys_[i] != kEmpty; i = (i + 1) & (keys_.size() - 1))
      if (keys_[i] == key) return values_[i];
    keys_[i] = key;
    values_[i] = value;
    ++size_;
    return -1;
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t{0};  // no node pair: nodes are ints
  size_t slot(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  // At least twice `count` slots, a power of two; the entries kept.
  void rehash(size_t count) {
    int bits = 4;
    while ((size_t{1} << bits) < 2 * count) ++bits;
    std::vector<uint64_t> keys(size_t{1} << bits, kEmpty);
    std::vector<int> values(keys.size());
    keys_.swap(keys);
    values_.swap(values);
    shift_ = 64 - bits;
    size_ = 0;
    for (size_t i = 0; i < keys.size(); ++i)
      if (keys[i] != kEmpty) find_or_insert(keys[i], values[i]);
  }
  std::vector<uint64_t> keys_;
  std::vector<int> values_;
  int shift_ = 60;
  size_t size_ = 0;
};

}  // namespace

double SkinModel::stiffness(const Spring &s) const {
  if (s.slab == 2 && s.kind != SpringKind::Layer) {
    // A bone tie: one end on the hypodermis, the other on the skull.
    const int hypo = layer_of(s.a) == kHypodermis ? s.a : s.b;
    if (skull_free[static_cast<size_t>(vertex_of(hypo))]) return 0.0;
  }
  return s.k;
}

namespace {

// The least-squares sphere through points (#P x 3): |p|^2 = 2 c . p + k with
// k = r^2 - |c|^2, linear in (c, k). None when the points are too few or
// stray from it by more than a tenth of the radius (rms).
std::optional<EyeSphere> fit_sphere(const Eigen::MatrixXd &P) {
  if (P.rows() < 8) return std::nullopt;
  Eigen::MatrixXd A(P.rows(), 4);
  Eigen::VectorXd b(P.rows());
  const Eigen::RowVector3d mean = P.colwise().mean();  // centred: better conditioned
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::RowVector3d p = P.row(i) - mean;
    A.row(i) << 2 * p, 1.0;
    b[i] = p.squaredNorm();
  }
  const Eigen::Vector4d x = A.colPivHouseholderQr().solve(b);
  const Eigen::Vector3d c = x.head<3>();
  const double r2 = x[3] + c.squaredNorm();
  if (!(r2 > 0)) return std::nullopt;
  EyeSphere s;
  s.centre = c + mean.transpose();
  s.radius = std::sqrt(r2);
  double err = 0;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const double e = (P.row(i).transpose() - s.centre).norm() - s.radius;
    err += e * e;
  }
  if (std::sqrt(err / static_cast<double>(P.rows())) > 0.1 * s.radius) return std::nullopt;
  return s;
}

// Per vertex of V (#V x 3, unit normals N): the eyeball in `eyes` it lies
// over, or -1 (SkinModel::eye_of: outside the sphere, within half a radius
// of its surface, and the line inward along its normal meets the sphere).
std::vector<int8_t> over_eyeballs(const Eigen::MatrixXd &V, const Eigen::MatrixXd &N, const std::vector<uint8_t> &used,
                                  const std::vector<EyeSphere> &eyes) {
  std::vector<int8_t> out(static_cast<size_t>(V.rows()), -1);
  for (size_t eye = 0; eye < eyes.size(); ++eye) {
    const EyeSphere &ball = eyes[eye];
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      if (!used[static_cast<size_t>(v)] || out[static_cast<size_t>(v)] >= 0) continue;
      const Eigen::Vector3d q = V.row(v).transpose() - ball.centre;
      const double d = q.norm(), along = q.dot(N.row(v).transpose());
      // Inward along -normal, the line comes nearest the centre `along` in.
      if (d < ball.radius || d > 1.5 * ball.radius || along <= 0) continue;
      if (q.squaredNorm() - along * along < ball.radius * ball.radius) out[static_cast<size_t>(v)] = static_cast<int8_t>(eye);
    }
  }
  return out;
}

}  // namespace

double eye_clearance_in(const SkinModel &m, int v, const Eigen::MatrixXd &X, const std::vector<char> *among) {
  const int8_t eye = m.eye_near[static_cast<size_t>(v)];
  const Eigen::RowVector3d x = X.row(m.node(kEpidermis, v)), x0 = m.X0.row(v);
  double grown = 0;
  for (int u : m.neighbours[static_cast<size_t>(v)])
    if (m.eye_near[static_cast<size_t>(u)] == eye && (!among || (*among)[static_cast<size_t>(u)]))
      grown = std::max(grown, (x - X.row(m.node(kEpidermis, u))).squaredNorm() - (x0 - m.X0.row(u)).squaredNorm());
  return m.eye_clearance[static_cast<size_t>(v)] + kChordDip * grown / m.eyes[static_cast<size_t>(eye)].radius;
}

std::vector<EyeSphere> fit_eyeballs(const Scene &scene) {
  std::vector<EyeSphere> eyes;
  for (PartKind kind : {PartKind::EyeLeft, PartKind::EyeRight}) {
    const int e = scene.find_kind(kind);
    if (e < 0) continue;
    std::optional<EyeSphere> ball = fit_sphere(scene.parts[static_cast<size_t>(e)].V);
    if (!ball) continue;
    ball->part = e;
    eyes.push_back(*ball);
  }
  return eyes;
}

std::vector<int8_t> near_eyeballs(const Eigen::MatrixXd &V, const std::vector<uint8_t> &used,
                                  const std::vector<EyeSphere> &eyes, double band) {
  std::vector<int8_t> out(static_cast<size_t>(V.rows()), -1);
  for (size_t eye = 0; eye < eyes.size(); ++eye)
    for (Eigen::Index v = 0; v < V.rows(); ++v) {
      if (!used[static_cast<size_t>(v)] || out[static_cast<size_t>(v)] >= 0) continue;
      const double d = (V.row(v).transpose() - eyes[eye].centre).norm();
      if (d >= eyes[eye].radius && d <= (1 + band) * eyes[eye].radius) out[static_cast<size_t>(v)] = static_cast<int8_t>(eye);
    }
  return out;
}

TissueParams unlayered_tissue(TissueParams p) {
  p.skin_load_share = 0;
  p.layer_volume_modulus = 0;
  p.collapse_modulus = 0;
  return p;
}

namespace {

// The tissue's springs (deduplicated by node pair; stiffness accumulates
// per prism), the nodes' masses and SkinModel::node_springs.
void add_springs(SkinModel &m, const TissueParams &params) {
  const int n = m.n;
  // About 15 springs a triangle (5 kinds a corner, over 3 slabs, shared).
  const size_t expected = 16 * static_cast<size_t>(m.F.rows());
  PairIndex index(expected);
  m.springs.reserve(expected);
  auto spring = [&](int a, int b, SpringKind kind, int slab) -> Spring & {
    if (a > b) std::swap(a, b);
    const uint64_t key = static_cast<uint64_t>(a) << 32 | static_cast<uint32_t>(b);
    if (const int at = index.find_or_insert(key, static_cast<int>(m.springs.size())); at >= 0)
      return m.springs[static_cast<size_t>(at)];
    Spring sp;
    sp.a = a;
    sp.b = b;
    sp.rest = (m.X0.row(a) - m.X0.row(b)).norm();
    sp.kind = kind;
    sp.slab = static_cast<uint8_t>(slab);
    sp.knee = params.slab[slab].knee;
    sp.ratio = params.slab[slab].ratio;
    m.springs.push_back(sp);
    return m.springs.back();
  };
  auto add = [&](int a, int b, SpringKind kind, int slab, double volume) {
    Spring &sp = spring(a, b, kind, slab);
    if (sp.rest > 0) sp.k += volume / (sp.rest * sp.rest);
  };
  m.mass = Eigen::VectorXd::Zero(kTissueLayers * n);
  const double cs = params.crossed_share;
  for (int f = 0; f < m.F.rows(); ++f) {
    for (int slab = 0; slab < 3; ++slab) {
      int node[6], row[6];
      slab_corners(m, f, slab, node, row);
      double vp = 0;
      for (const auto &t : kTets)
        vp += tet_volume(m.X0.row(node[t[0]]), m.X0.row(node[t[1]]), m.X0.row(node[t[2]]),
                         m.X0.row(node[t[3]]));
      vp = std::abs(vp);
      for (int k = 0; k < 6; ++k) m.mass[node[k]] += params.density * vp / 6.0;
      const double e = params.slab[slab].modulus;
      for (int k = 0; k < 3; ++k) {
        const int k2 = (k + 1) % 3;
        const double upper = slab == 0 ? 1.0 + params.epidermis_surface : 1.0;
        add(node[k], node[k2], SpringKind::Layer, slab, upper * e * vp * (1 - cs) / 12.0);
        if (slab < 2)  // no springs within the bone
          add(node[3 + k], node[3 + k2], SpringKind::Layer, slab, e * vp * (1 - cs) / 12.0);
        add(node[k], node[3 + k], SpringKind::Connecting, slab, e * vp * (1 - cs) / 6.0);
        add(node[k], node[3 + k2], SpringKind::Crossed, slab, e * vp * cs / 6.0);
        add(node[k2], node[3 + k], SpringKind::Crossed, slab, e * vp * cs / 6.0);
      }
    }
  }
  m.node_springs.assign(static_cast<size_t>(kTissueLayers * n), {});
  for (size_t i = 0; i < m.springs.size(); ++i) {
    m.node_springs[static_cast<size_t>(m.springs[i].a)].push_back(static_cast<int>(i));
    m.node_springs[static_cast<size_t>(m.springs[i].b)].push_back(static_cast<int>(i));
  }
}

}  // namespace

Expected<SkinModel> build_skin_model(const Scene &scene, int part, const TissueParams &params, SkinBuild build) {
  if (part < 0 || part >= static_cast<int>(scene.parts.size()))
    return Status::error("skin model: no skin part");
  const Part &p = scene.parts[static_cast<size_t>(part)];
  if (p.F.rows() == 0) return Status::error("skin model: part '" + p.name + "' has no triangles");
  if (!(params.skull_scale > 0 && params.skull_scale < 1) || !(params.dermis_depth > 0) ||
      !(params.dermis_depth < params.hypodermis_depth) || !(params.hypodermis_depth < 1))
    return Status::error("skin model: need 0 < skull_scale < 1 and 0 < dermis_depth < "
                         "hypodermis_depth < 1");
  if (!(params.collapse_modulus >= 0) || !(params.collapse_knee > 0 && params.collapse_knee <= 1))
    return Status::error("skin model: need collapse_modulus >= 0 and 0 < collapse_knee <= 1");
  if (!(params.lip_contact_modulus >= 0)) return Status::error("skin model: need lip_contact_modulus >= 0");
  if (!(params.layer_volume_modulus >= 0)) return Status::error("skin model: need layer_volume_modulus >= 0");
  if (!(params.skin_load_share >= 0 && params.skin_load_share <= 1))
    return Status::error("skin model: need 0 <= skin_load_share <= 1");

  SkinModel m;
  m.part = part;
  m.params = params;
  m.n = static_cast<int>(p.V.rows());
  m.F = p.F;
  const int n = m.n;

  // Centre of gravity of the surface, areas and normals.
  m.area = Eigen::VectorXd::Zero(n);
  m.normal = vertex_normals(p.V, m.F);
  m.in_mesh.assign(static_cast<size_t>(n), 0);
  m.vertex_faces.assign(static_cast<size_t>(n), {});
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double total = 0;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = p.V.row(m.F(f, 0)), b = p.V.row(m.F(f, 1)), d = p.V.row(m.F(f, 2));
    const Eigen::Vector3d nrm = (b - a).cross(d - a);  // twice the area
    const double ar = 0.5 * nrm.norm();
    c += ar * (a + b + d) / 3.0;
    total += ar;
    for (int k = 0; k < 3; ++k) {
      const int v = m.F(f, k);
      m.area[v] += ar / 3.0;
      m.in_mesh[static_cast<size_t>(v)] = 1;
      m.vertex_faces[static_cast<size_t>(v)].push_back(f);
    }
  }
  c /= total;
  m.centre = c;
  // The centre must be inside: most of the surface must face away from it.
  double outward = 0;
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = p.V.row(m.F(f, 0)), b = p.V.row(m.F(f, 1)), d = p.V.row(m.F(f, 2));
    const Eigen::Vector3d nrm = (b - a).cross(d - a);
    if (nrm.dot((a + b + d) / 3.0 - c) > 0) outward += 0.5 * nrm.norm();
  }
  if (outward < 0.7 * total)
    return Status::error("skin part '" + p.name + "': only " +
                         std::to_string(static_cast<int>(100 * outward / total)) +
                         " % of its surface faces away from its centre of gravity (a head gives "
                         "over 70 %): not a face, or its triangles face inward");

  // Surfaces: scaled copies around c.
  const double s = params.skull_scale;
  const double depth[kTissueLayers] = {0, params.dermis_depth, params.hypodermis_depth, 1};
  m.X0.resize(kTissueLayers * n, 3);
  m.thickness.resize(n);
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d p0 = p.V.row(v);
    m.thickness[v] = (1 - s) * (p0 - c).norm();
    for (int l = 0; l < kTissueLayers; ++l)
      m.X0.row(m.node(l, v)) = (c + (1 - depth[l] * (1 - s)) * (p0 - c)).transpose();
  }

  if (build == SkinBuild::Tissue) add_springs(m, params);

  m.neighbours.assign(static_cast<size_t>(n), {});
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      m.neighbours[static_cast<size_t>(m.F(f, k))].push_back(m.F(f, (k + 1) % 3));
      m.neighbours[static_cast<size_t>(m.F(f, k))].push_back(m.F(f, (k + 2) % 3));
    }
  for (auto &nb : m.neighbours) {
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
  }
  m.rest_volume.resize(m.F.rows());
  m.nominal_volume.resize(m.F.rows());
  for (int f = 0; f < m.F.rows(); ++f) {
    m.rest_volume[f] = element_volume(m, m.X0, f);
    const Eigen::Vector3d a = m.X0.row(m.F(f, 0)), b = m.X0.row(m.F(f, 1)), d = m.X0.row(m.F(f, 2));
    m.nominal_volume[f] = 0.5 * (b - a).cross(d - a).norm() *
                          (m.thickness[m.F(f, 0)] + m.thickness[m.F(f, 1)] + m.thickness[m.F(f, 2)]) / 3.0;
  }
  m.skull_free.assign(static_cast<size_t>(n), 0);

  m.eyes = fit_eyeballs(scene);
  m.eye_of = over_eyeballs(p.V, m.normal, m.in_mesh, m.eyes);
  m.eye_near = near_eyeballs(p.V, m.in_mesh, m.eyes);
  m.eye_clearance.assign(static_cast<size_t>(n), 0.0);
  for (int v = 0; v < n; ++v) {
    const int8_t over = m.eye_of[static_cast<size_t>(v)];
    if (over >= 0) {  // what lies under it is the eye, not bone
      m.skull_free[static_cast<size_t>(v)] = 1;
      m.eye_near[static_cast<size_t>(v)] = over;
    }
    if (const int8_t e = m.eye_near[static_cast<size_t>(v)]; e >= 0) hold_off_eyeball(m, v, e);
  }
  return m;
}

double rest_eye_clearance(double rest, double longest_sq, double radius) {
  // The skin between held nodes dips toward the ball (kChordDip).
  return std::clamp(rest, 0.0, std::max(kEyeClearance * radius, kChordDip * longest_sq / radius));
}

void hold_off_eyeball(SkinModel &m, int v, int eye) {
  const EyeSphere &ball = m.eyes[static_cast<size_t>(eye)];
  const Eigen::RowVector3d p = m.X0.row(m.node(kEpidermis, v));
  double longest_sq = 0;
  for (int u : m.neighbours[static_cast<size_t>(v)])
    longest_sq = std::max(longest_sq, (p - m.X0.row(m.node(kEpidermis, u))).squaredNorm());
  m.eye_near[static_cast<size_t>(v)] = static_cast<int8_t>(eye);
  m.eye_clearance[static_cast<size_t>(v)] =
      rest_eye_clearance((p.transpose() - ball.centre).norm() - ball.radius, longest_sq, ball.radius);
}

int nearest_node(const SkinModel &m, int layer, const Eigen::Vector3d &p) {
  int best = -1;
  double bd = 0;
  for (int v = 0; v < m.n; ++v) {
    if (!m.in_mesh[static_cast<size_t>(v)]) continue;
    const double d = (m.X0.row(m.node(layer, v)).transpose() - p).squaredNorm();
    if (best < 0 || d < bd) best = v, bd = d;
  }
  return best < 0 ? -1 : m.node(layer, best);
}

double element_volume(const SkinModel &m, const Eigen::MatrixXd &X, int f, Eigen::Matrix<double, 9, 3> *gradient,
                      int only) {
  if (gradient) gradient->setZero();
  double v = 0;
  for (int slab = std::max(only, 0); slab < (only < 0 ? 3 : only + 1); ++slab) {
    int node[6], row[6];
    slab_corners(m, f, slab, node, row);
    for (const auto &t : kTets) {
      const Eigen::Vector3d p0 = X.row(node[t[0]]), p1 = X.row(node[t[1]]), p2 = X.row(node[t[2]]),
                            p3 = X.row(node[t[3]]);
      v += tet_volume(p0, p1, p2, p3);
      if (!gradient) continue;
      // d/dp1 = (p2-p0)x(p3-p0)/6 and cyclic; d/dp0 = -(sum of the others).
      const Eigen::Vector3d g1 = (p2 - p0).cross(p3 - p0) / 6.0;
      const Eigen::Vector3d g2 = (p3 - p0).cross(p1 - p0) / 6.0;
      const Eigen::Vector3d g3 = (p1 - p0).cross(p2 - p0) / 6.0;
      const Eigen::Vector3d g[4] = {-(g1 + g2 + g3), g1, g2, g3};
      for (int c = 0; c < 4; ++c)
        if (row[t[c]] >= 0) gradient->row(row[t[c]]) += g[c].transpose();
    }
  }
  return v;
}

Eigen::Matrix3d VolumeHessian::block(int i, int j) const {
  if (i == j) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d w = i < j ? upper[pair(i, j)] : Eigen::Vector3d(-upper[pair(j, i)]);
  Eigen::Matrix3d s;
  s << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return s;
}

void element_volume_hessian(const SkinModel &m, const Eigen::MatrixXd &X, int f, VolumeHessian *H) {
  for (Eigen::Vector3d &w : H->upper) w.setZero();
  for (int slab = 0; slab < 3; ++slab) {
    int node[6], row[6];
    slab_corners(m, f, slab, node, row);
    for (const auto &t : kTets) {
      // V = a . (b x c) / 6 with a, b, c = p1 - p0, p2 - p0, p3 - p0: the
      // mixed derivatives in (a, b), (a, c), (b, c) are the cross-product
      // matrices of -c / 6, b / 6, -a / 6, and p0, which moves all three
      // edges the other way, gets minus their sums.
      const Eigen::Vector3d p0 = X.row(node[t[0]]);
      const Eigen::Vector3d a = X.row(node[t[1]]).transpose() - p0, b = X.row(node[t[2]]).transpose() - p0,
                            c = X.row(node[t[3]]).transpose() - p0;
      Eigen::Vector3d w[4][4];  // w[i][j] for the tet's points i < j
      w[1][2] = -c / 6, w[1][3] = b / 6, w[2][3] = -a / 6;
      w[0][1] = w[1][2] + w[1][3], w[0][2] = w[2][3] - w[1][2], w[0][3] = -w[1][3] - w[2][3];
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const int ri = row[t[i]], rj = row[t[j]];
          if (ri < 0 || rj < 0) continue;
          if (ri < rj)
            H->upper[VolumeHessian::pair(ri, rj)] += w[i][j];
          else
            H->upper[VolumeHessian::pair(rj, ri)] -= w[i][j];
        }
    }
  }
}

void element_tet_volumes(const SkinModel &m, const Eigen::MatrixXd &X, int f, double out[9]) {
  for (int slab = 0; slab < 3; ++slab) {
    int node[6], row[6];
    slab_corners(m, f, slab, node, row);
    for (int t = 0; t < 3; ++t)
      out[slab * 3 + t] = tet_volume(X.row(node[kTets[t][0]]), X.row(node[kTets[t][1]]),
                                     X.row(node[kTets[t][2]]), X.row(node[kTets[t][3]]));
  }
}

double slab_nominal_volume(const SkinModel &m, int f, int slab) {
  const double depth[4] = {0, m.params.dermis_depth, m.params.hypodermis_depth, 1};
  return (depth[slab + 1] - depth[slab]) * m.nominal_volume[f];
}

bool slab_holds_tissue(const SkinModel &m, int f, int slab) {
  if (slab == 2)
    for (int k = 0; k < 3; ++k)
      if (m.skull_free[static_cast<size_t>(m.F(f, k))]) return false;
  return std::abs(element_volume(m, m.X0, f, nullptr, slab)) >= 0.25 * slab_nominal_volume(m, f, slab);
}

std::vector<std::pair<int, int>> turned_slabs(const SkinModel &m, const Eigen::MatrixXd &X) {
  std::vector<std::pair<int, int>> out;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int slab = 0; slab < 3; ++slab)
      if (slab_holds_tissue(m, f, slab) &&
          element_volume(m, m.X0, f, nullptr, slab) * element_volume(m, X, f, nullptr, slab) <= 0)
        out.emplace_back(f, slab);
  return out;
}

}  // namespace afmb
