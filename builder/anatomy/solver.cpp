#include "anatomy/solver.h"

#include "anatomy/block_ldlt.h"

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace afmb {

namespace {

using Vec = Eigen::VectorXd;
using SpMat = Eigen::SparseMatrix<double>;
using Ldlt = BlockLdlt;

// Elements whose rest volume is this small relative to the mean are left out
// of the volume term: seen edge-on from the centre, their volume says nothing.
constexpr double kVolumeFloor = 1e-3;

// A 3x3 block of the Hessian inside the CSC value array: entry (r, c) is at
// base + c * stride + r. base < 0: the block is not stored (a fixed node).
struct Block {
  int base = -1, stride = 0;
};

struct Element {
  int f;
  int local[9];   // local node per gradient row (layers 0-2), -1 when fixed
  int global[12]; // the element's nodes, layers 0-3
  double weight;  // volume term: k_v / |V0|, 0 for an element seen edge-on
  double shape;   // shape term: k_s V_nom / R^2 (R: radius of gyration at rest)
  // Per slab: the collapse floor, k_c x the slab's share of V_nom, and each
  // layer's own volume term, k_l / |V_s0|; 0 where off or where the slab
  // holds no tissue (slab_holds_tissue). The slab's signed rest volume where
  // either is on (0 elsewhere), and whether any slab has a layer term.
  double collapse[3];
  double layer_weight[3];
  double slab_rest[3];
  bool layered;
};

// The collapse floor's profile psi(J) = ((j0 - J) / j0)^3 below the knee j0,
// 0 above (C2 there), and its first two derivatives in J.
struct FloorValue {
  double e = 0, d1 = 0, d2 = 0;
};
FloorValue collapse_floor(double J, double j0) {
  if (J >= j0) return {};
  const double u = (j0 - J) / j0;
  return {u * u * u, -3 * u * u / j0, 6 * u / (j0 * j0)};
}

// The floor of slab `sl` of element `el` at X.
FloorValue slab_floor(const SkinModel &m, const Eigen::MatrixXd &X, const Element &el, int sl) {
  return collapse_floor(element_volume(m, X, el.f, nullptr, sl) / el.slab_rest[sl], m.params.collapse_knee);
}

// The unknowns of one dynamic set and the fixed sparsity of their Hessian:
// 3x3 blocks between nodes joined by a spring or a lip pair (ties) or sharing
// an element. Built once per set; every linearisation writes values into the
// same pattern.
struct System {
  const SkinModel &m;
  std::vector<int> nodes;  // free nodes, global
  std::vector<int> local;  // global node -> local index, or -1
  std::vector<int> springs;
  std::vector<double> spring_k;                  // per spring: SkinModel::stiffness
  std::vector<std::array<int, 2>> spring_local;  // per spring: its ends' local nodes, or -1
  std::vector<int> lips;  // SkinModel::lip_pairs with a free node, when in contact
  std::vector<Element> elements;
  std::vector<uint8_t> rejects;  // per local node: held above its skull plane
  std::vector<int8_t> eye;       // per local node: the eyeball (SkinModel::eyes) it is held off, or -1
  // Per local node j: its sorted block neighbours i <= j (itself included),
  // the rows of column j in `pattern`.
  std::vector<std::vector<int>> adj;
  // The tangent is stored on and above its diagonal only (blocks (i, j),
  // i <= j; a block below is the transpose of its mirror): those below are
  // left out (base < 0) here.
  std::vector<std::array<Block, 4>> tie_blocks;     // per spring, then per lip pair: aa, bb, ab, ba
  std::vector<Block> element_blocks;                // 81 per element, (i, j) at 9 i + j
  std::vector<Block> diagonal;                      // per local node
  SpMat pattern;  // dofs x dofs, the upper triangle's blocks (adj), values unset
  // Per local node i, the terms of the energy it is in (moved_energy_change):
  // terms[term_start[i] .. term_start[i + 1]), element e as e, tie q as -1 - q.
  std::vector<int> term_start, terms;
  int dofs() const { return 3 * static_cast<int>(nodes.size()); }
  size_t ties() const { return springs.size() + lips.size(); }
  // The two nodes of tie q: spring q, or lip pair q - springs.size().
  std::pair<int, int> tie(size_t q) const {
    if (q < springs.size()) {
      const Spring &s = m.springs[static_cast<size_t>(springs[q])];
      return {s.a, s.b};
    }
    const LipPair &p = m.lip_pairs[static_cast<size_t>(lips[q - springs.size()])];
    return {p.upper, p.lower};
  }

  // Block (i, j), i <= j.
  Block block(int i, int j) const {
    const std::vector<int> &col = adj[static_cast<size_t>(j)];
    const auto pos = std::lower_bound(col.begin(), col.end(), i) - col.begin();
    return Block{pattern.outerIndexPtr()[3 * j] + 3 * static_cast<int>(pos), 3 * static_cast<int>(col.size())};
  }

  // With `contact`, the lip pairs with a free node join as ties.
  System(const SkinModel &model, const std::vector<int> &vertices, bool contact) : m(model) {
    local.assign(static_cast<size_t>(kTissueLayers * m.n), -1);
    for (int v : vertices) {
      if (v < 0 || v >= m.n || !m.in_mesh[static_cast<size_t>(v)]) continue;
      for (int l = 0; l < kSkull; ++l) {
        const int g = m.node(l, v);
        if (local[static_cast<size_t>(g)] >= 0) continue;
        local[static_cast<size_t>(g)] = static_cast<int>(nodes.size());
        nodes.push_back(g);
        // Over an eyeball the epidermis slides on the eye, not the bone; near
        // one (the lid margin's underside, the eye corners) it keeps its
        // skull plane until it meets the ball (update_contacts).
        const int8_t over = l == kEpidermis ? m.eye_of[static_cast<size_t>(v)] : int8_t(-1);
        eye.push_back(l == kEpidermis ? m.eye_near[static_cast<size_t>(v)] : int8_t(-1));
        rejects.push_back(over < 0 && skull_rejects(m, v) ? 1 : 0);
      }
    }
    std::vector<uint8_t> seen(m.springs.size(), 0);
    for (int g : nodes)
      for (int s : m.node_springs[static_cast<size_t>(g)])
        if (!seen[static_cast<size_t>(s)]) {
          seen[static_cast<size_t>(s)] = 1;
          if (m.stiffness(m.springs[static_cast<size_t>(s)]) > 0) springs.push_back(s);
        }
    std::sort(springs.begin(), springs.end());
    for (int si : springs) {
      const Spring &s = m.springs[static_cast<size_t>(si)];
      spring_k.push_back(m.stiffness(s));
      spring_local.push_back({local[static_cast<size_t>(s.a)], local[static_cast<size_t>(s.b)]});
    }
    for (size_t p = 0; contact && p < m.lip_pairs.size(); ++p) {
      const LipPair &lp = m.lip_pairs[p];
      if (local[static_cast<size_t>(lp.upper)] >= 0 || local[static_cast<size_t>(lp.lower)] >= 0)
        lips.push_back(static_cast<int>(p));
    }
    double mean = 0;
    for (int f = 0; f < m.F.rows(); ++f) mean += std::abs(m.rest_volume[f]);
    mean /= std::max<Eigen::Index>(1, m.F.rows());
    std::vector<uint8_t> fseen(static_cast<size_t>(m.F.rows()), 0);
    for (int v : vertices) {
      if (v < 0 || v >= m.n) continue;
      for (int f : m.vertex_faces[static_cast<size_t>(v)]) {
        if (fseen[static_cast<size_t>(f)]) continue;
        fseen[static_cast<size_t>(f)] = 1;
        const double v0 = std::abs(m.rest_volume[f]);
        Element e;
        e.f = f;
        for (int l = 0; l < kTissueLayers; ++l)
          for (int k = 0; k < 3; ++k) {
            e.global[l * 3 + k] = m.node(l, m.F(f, k));
            if (l < kSkull) e.local[l * 3 + k] = local[static_cast<size_t>(e.global[l * 3 + k])];
          }
        e.weight = v0 < kVolumeFloor * mean ? 0.0 : m.params.volume_modulus / v0;
        // Divided by the element's squared radius of gyration at rest, the
        // shape energy is modulus x volume x (relative displacement / size)^2:
        // a strain energy, the same at every mesh resolution. The nominal
        // volume, not |V0|: a prism seen edge-on from the centre (lip curls)
        // has almost no volume but still holds tissue; without its shape
        // term it shears flat and flips.
        Eigen::Matrix<double, 12, 3> p;
        for (int k = 0; k < 12; ++k) p.row(k) = m.X0.row(e.global[k]);
        const double gyration2 = (p.rowwise() - p.colwise().mean()).squaredNorm() / 12.0;
        e.shape = gyration2 > 0 ? m.params.shape_modulus * m.nominal_volume[f] / gyration2 : 0.0;
        e.layered = false;
        for (int sl = 0; sl < 3; ++sl) {
          const bool holds = (m.params.collapse_modulus > 0 || m.params.layer_volume_modulus > 0) &&
                             slab_holds_tissue(m, f, sl);
          e.slab_rest[sl] = holds ? element_volume(m, m.X0, f, nullptr, sl) : 0.0;
          e.collapse[sl] = holds && m.params.collapse_modulus > 0
                               ? m.params.collapse_modulus * slab_nominal_volume(m, f, sl)
                               : 0.0;
          e.layer_weight[sl] = holds && m.params.layer_volume_modulus > 0 && e.slab_rest[sl] != 0
                                   ? m.params.layer_volume_modulus / std::abs(e.slab_rest[sl])
                                   : 0.0;
          e.layered = e.layered || e.layer_weight[sl] > 0;
        }
        elements.push_back(e);
      }
    }
    std::sort(elements.begin(), elements.end(), [](const Element &a, const Element &b) { return a.f < b.f; });
    build_pattern();
  }

  void build_pattern() {
    const int nn = static_cast<int>(nodes.size());
    // Each node's neighbours: the free nodes of its elements and ties,
    // gathered once each (a node sits in a dozen elements of 9 nodes: sorting
    // every repeat cost Song's AFM a tenth of its time).
    std::vector<int> start(static_cast<size_t>(nn) + 1, 0), incident;
    for (const Element &e : elements)
      for (int i : e.local)
        if (i >= 0) ++start[static_cast<size_t>(i) + 1];
    for (size_t q = 0; q < ties(); ++q) {
      const auto [a, b] = tie(q);
      for (int g : {a, b})
        if (const int i = local[static_cast<size_t>(g)]; i >= 0) ++start[static_cast<size_t>(i) + 1];
    }
    for (int i = 0; i < nn; ++i) start[static_cast<size_t>(i) + 1] += start[static_cast<size_t>(i)];
    // incident[start[i] ..]: element e as e, tie q as -1 - q.
    incident.resize(static_cast<size_t>(start.back()));
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t e = 0; e < elements.size(); ++e)
      for (int i : elements[e].local)
        if (i >= 0) incident[static_cast<size_t>(fill[static_cast<size_t>(i)]++)] = static_cast<int>(e);
    for (size_t q = 0; q < ties(); ++q) {
      const auto [a, b] = tie(q);
      for (int g : {a, b})
        if (const int i = local[static_cast<size_t>(g)]; i >= 0)
          incident[static_cast<size_t>(fill[static_cast<size_t>(i)]++)] = -1 - static_cast<int>(q);
    }
    adj.assign(static_cast<size_t>(nn), {});
    std::vector<int> mark(static_cast<size_t>(nn), -1);
    Eigen::Index nnz = 0;
    for (int i = 0; i < nn; ++i) {
      std::vector<int> &a = adj[static_cast<size_t>(i)];
      auto add = [&](int j) {
        if (j >= 0 && mark[static_cast<size_t>(j)] != i) mark[static_cast<size_t>(j)] = i, a.push_back(j);
      };
      add(i);
      for (int p = start[static_cast<size_t>(i)]; p < start[static_cast<size_t>(i) + 1]; ++p) {
        const int x = incident[static_cast<size_t>(p)];
        if (x >= 0) {
          for (int j : elements[static_cast<size_t>(x)].local) add(j);
        } else {
          const auto [ga, gb] = tie(static_cast<size_t>(-1 - x));
          add(local[static_cast<size_t>(ga)]), add(local[static_cast<size_t>(gb)]);
        }
      }
      std::sort(a.begin(), a.end());
      a.erase(std::upper_bound(a.begin(), a.end(), i), a.end());  // on and above the diagonal
      nnz += 9 * static_cast<Eigen::Index>(a.size());
    }
    const int n = dofs();
    pattern.resize(n, n);
    pattern.resizeNonZeros(nnz);
    int *outer = pattern.outerIndexPtr(), *inner = pattern.innerIndexPtr();
    int k = 0;
    for (int j = 0; j < nn; ++j)
      for (int c = 0; c < 3; ++c) {
        outer[3 * j + c] = k;
        for (int i : adj[static_cast<size_t>(j)])
          for (int r = 0; r < 3; ++r) inner[k++] = 3 * i + r;
      }
    outer[n] = k;
    std::fill(pattern.valuePtr(), pattern.valuePtr() + nnz, 0.0);
    diagonal.resize(static_cast<size_t>(nn));
    for (int i = 0; i < nn; ++i) diagonal[static_cast<size_t>(i)] = block(i, i);
    term_start = start;
    terms = incident;
    // The blocks each tie and element adds to, column by column: with
    // the column's row positions at hand (`row_at`), no search.
    tie_blocks.assign(ties(), {});
    element_blocks.assign(81 * elements.size(), Block{});
    std::vector<int> row_at(static_cast<size_t>(nn), -1);
    for (int j = 0; j < nn; ++j) {
      const std::vector<int> &col = adj[static_cast<size_t>(j)];
      for (size_t p = 0; p < col.size(); ++p) row_at[static_cast<size_t>(col[p])] = static_cast<int>(p);
      const int base = outer[3 * j], stride = 3 * static_cast<int>(col.size());
      auto at = [&](int i) { return Block{base + 3 * row_at[static_cast<size_t>(i)], stride}; };
      for (int p = start[static_cast<size_t>(j)]; p < start[static_cast<size_t>(j) + 1]; ++p) {
        const int x = incident[static_cast<size_t>(p)];
        if (x >= 0) {
          const Element &e = elements[static_cast<size_t>(x)];
          for (int c = 0; c < 9; ++c) {
            if (e.local[c] != j) continue;
            Block *out = &element_blocks[81 * static_cast<size_t>(x)];
            for (int r = 0; r < 9; ++r)
              if (e.local[r] >= 0 && e.local[r] <= j) out[9 * r + c] = at(e.local[r]);
          }
        } else {
          const size_t q = static_cast<size_t>(-1 - x);
          const auto [ga, gb] = tie(q);
          const int a = local[static_cast<size_t>(ga)], b = local[static_cast<size_t>(gb)];
          std::array<Block, 4> &bl = tie_blocks[q];
          if (j == a) {
            bl[0] = at(a);
            if (b >= 0 && b < a) bl[3] = at(b);  // (b, a)
          } else {
            bl[1] = at(b);
            if (a >= 0 && a < b) bl[2] = at(a);  // (a, b)
          }
        }
      }
    }
  }
};

// Tension of a biphasic spring at length l, and its derivative. Stiffness k
// up to the knee strain, ratio x k beyond knee + w, ramping linearly in
// between (w = knee): the tension is C1, so Newton does not cycle on the kink.
void tension(const Spring &s, double k, double l, double *t, double *dt) {
  const double e = (l - s.rest) / s.rest, a = std::abs(e), sg = e >= 0 ? 1.0 : -1.0;
  const double w = s.knee, extra = s.ratio - 1;
  if (a <= s.knee) {
    *t = k * s.rest * e;
    *dt = k;
  } else if (a <= s.knee + w) {
    const double x = a - s.knee;
    *t = k * s.rest * (e + sg * extra * x * x / (2 * w));
    *dt = k * (1 + extra * x / w);
  } else {
    *t = k * s.rest * (e + sg * extra * (w / 2 + (a - s.knee - w)));
    *dt = k * s.ratio;
  }
}

// Energy of a biphasic spring at length l: the integral of tension().
double spring_energy(const Spring &s, double k, double l) {
  const double e = (l - s.rest) / s.rest, a = std::abs(e);
  const double w = s.knee, extra = s.ratio - 1;
  double u = e * e / 2;
  if (a > s.knee + w) {
    const double y = a - s.knee - w;
    u += extra * (w * w / 6 + w / 2 * y + y * y / 2);
  } else if (a > s.knee) {
    const double x = a - s.knee;
    u += extra * x * x * x / (6 * w);
  }
  return k * s.rest * s.rest * u;
}

template <class M>
void add_block(double *values, Block b, const M &B) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) values[b.base + c * b.stride + r] += B(r, c);
}

// A tie's Hessian (B symmetric): B on its nodes' own blocks, -B between
// them, in the one of (a, b) and (b, a) above the diagonal (a fixed node's
// blocks are not stored).
void add_tie(double *values, const std::array<Block, 4> &bl, const Eigen::Matrix3d &B) {
  if (bl[0].base >= 0) add_block(values, bl[0], B);
  if (bl[1].base >= 0) add_block(values, bl[1], B);
  if (bl[2].base >= 0) add_block(values, bl[2], -B);
  if (bl[3].base >= 0) add_block(values, bl[3], -B);
}

// The internal force at X into *r (dofs; the shape term pulls toward `ref`)
// and/or the Hessian into *K (the system's pattern) and *diag (its
// diagonal), in one pass over the springs and elements: a Newton step needs
// both at the same X. Either pair may be null. The Hessian: springs, the
// shape term and the volume term. `curvature`, 0..1: the share of its
// indefinite parts kept (a compressed spring's negative transverse
// stiffness, the volume's own curvature k_v (V - V0) / |V0| d2V/dp2 beside
// its Gauss-Newton part). 1 is the full tangent, with which Newton
// converges quadratically near an equilibrium, where K is definite anyway;
// 0 the projected one, positive semi-definite everywhere; the solver tries
// a half in between (solve_equilibrium).
void assemble(const System &sys, const Eigen::MatrixXd &X, const Eigen::MatrixXd *ref, Vec *r, SpMat *K, Vec *diag,
              double curvature) {
  const SkinModel &m = sys.m;
  if (r) r->setZero(sys.dofs());
  double *val = nullptr;
  if (K) {
    if (K->nonZeros() != sys.pattern.nonZeros()) *K = sys.pattern;
    val = K->valuePtr();
    std::fill(val, val + K->nonZeros(), 0.0);
  }
  for (size_t q = 0; q < sys.springs.size(); ++q) {
    const Spring &s = m.springs[static_cast<size_t>(sys.springs[q])];
    const Eigen::Vector3d d = X.row(s.b) - X.row(s.a);
    const double l = std::max(d.norm(), 1e-12 * s.rest);
    double t, dt;
    tension(s, sys.spring_k[q], l, &t, &dt);
    if (r) {
      const Eigen::Vector3d f = t * d / l;  // pulls a toward b when stretched
      const auto [la, lb] = sys.spring_local[q];
      if (la >= 0) r->segment<3>(3 * la) += f;
      if (lb >= 0) r->segment<3>(3 * lb) -= f;
    }
    if (K) {
      const Eigen::Vector3d u = d / l;
      const double geo = (t >= 0 ? t : curvature * t) / l;
      const Eigen::Matrix3d B = (dt - geo) * u * u.transpose() + geo * Eigen::Matrix3d::Identity();
      add_tie(val, sys.tie_blocks[q], B);
    }
  }
  // Lip pairs: the force pushes the upper vertex up; d2E/ds2 up up^T, up = +y
  // (lip_contact.h).
  for (size_t i = 0; i < sys.lips.size(); ++i) {
    const LipPair &p = m.lip_pairs[static_cast<size_t>(sys.lips[i])];
    const LipContactValue c = lip_contact_energy(p, X(p.upper, 1) - X(p.lower, 1));
    if (r && c.d1 != 0) {
      const int la = sys.local[static_cast<size_t>(p.upper)], lb = sys.local[static_cast<size_t>(p.lower)];
      if (la >= 0) (*r)[3 * la + 1] -= c.d1;
      if (lb >= 0) (*r)[3 * lb + 1] += c.d1;
    }
    if (K && c.d2 > 0) {
      Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
      B(1, 1) = c.d2;
      add_tie(val, sys.tie_blocks[sys.springs.size() + i], B);
    }
  }
  Eigen::Matrix<double, 9, 3> g, gs[3];  // gs: per slab
  VolumeHessian H;
  auto push = [&](const Element &el, double c, const Eigen::Matrix<double, 9, 3> &grad) {
    for (int k = 0; k < 9; ++k)
      if (el.local[k] >= 0) r->segment<3>(3 * el.local[k]) += c * grad.row(k).transpose();
  };
  for (size_t e = 0; e < sys.elements.size(); ++e) {
    const Element &el = sys.elements[e];
    // With each layer's own volume, the slabs' volumes and gradients once;
    // the element's are their sums.
    const bool layered = el.layered;
    double vs[3] = {0, 0, 0};
    if (layered) {
      g.setZero();
      for (int sl = 0; sl < 3; ++sl) {
        vs[sl] = element_volume(m, X, el.f, &gs[sl], sl);
        g += gs[sl];
      }
    }
    double excess = 0;  // k_v (V - V0) / |V0|: the weight of the volume's own curvature
    if (el.weight > 0) {
      const double v = layered ? vs[0] + vs[1] + vs[2] : element_volume(m, X, el.f, &g);
      if (r) push(el, -el.weight * (v - m.rest_volume[el.f]), g);
      if (K && curvature > 0) excess = curvature * el.weight * (v - m.rest_volume[el.f]);
      if (excess != 0) element_volume_hessian(m, X, el.f, &H);
    }
    // Per slab, along its volume's gradient: the floor's force where it is
    // squeezed, and the layer's own volume term's; their Gauss-Newton parts
    // c grad grad^T in both tangents, the floor's w psi''(J) / V0^2 and the
    // layer's k_l / |V_s0|. The slab volume's own curvature is left out:
    // with the floor's w psi'(J) / V0 d2V/dp2 the full tangent turned
    // indefinite more often (Song's AFM at k_c = 0.3: 2,816 factorisations
    // against 2,030).
    double gauss[3] = {0, 0, 0};
    for (int sl = 0; sl < 3; ++sl) {
      double force = 0;
      if (el.collapse[sl] > 0) {
        const double v0 = el.slab_rest[sl];
        const FloorValue p = layered ? collapse_floor(vs[sl] / v0, m.params.collapse_knee) : slab_floor(m, X, el, sl);
        force -= el.collapse[sl] * p.d1 / v0;
        if (K && p.d2 > 0) gauss[sl] += el.collapse[sl] * p.d2 / (v0 * v0);
      }
      if (el.layer_weight[sl] > 0) {
        force -= el.layer_weight[sl] * (vs[sl] - el.slab_rest[sl]);
        if (K) gauss[sl] += el.layer_weight[sl];
      }
      if ((!r || force == 0) && gauss[sl] == 0) continue;
      if (!layered) element_volume(m, X, el.f, &gs[sl], sl);
      if (r && force != 0) push(el, force, gs[sl]);
    }
    if (r && el.shape > 0) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int k = 0; k < 12; ++k) mean += (X.row(el.global[k]) - ref->row(el.global[k])).transpose();
      mean /= 12.0;
      for (int k = 0; k < 9; ++k)
        if (el.local[k] >= 0)
          r->segment<3>(3 * el.local[k]) -=
              el.shape * ((X.row(el.global[k]) - ref->row(el.global[k])).transpose() - mean);
    }
    if (!K) continue;
    // Each pair once: block (i, j), or its transpose as block (j, i) where
    // that is the one above K's diagonal.
    for (int i = 0; i < 9; ++i)
      for (int j = i; j < 9; ++j) {
        const Block b = sys.element_blocks[81 * e + static_cast<size_t>(9 * i + j)],
                    bt = sys.element_blocks[81 * e + static_cast<size_t>(9 * j + i)];
        if (b.base < 0 && bt.base < 0) continue;
        Eigen::Matrix3d B = Eigen::Matrix3d::Identity() * (el.shape * ((i == j ? 1.0 : 0.0) - 1.0 / 12.0));
        if (el.weight > 0) B.noalias() += el.weight * g.row(i).transpose() * g.row(j);
        // Slab sl's gradient has rows 3 sl .. 3 sl + 5 only.
        for (int sl = 0; sl < 3; ++sl)
          if (gauss[sl] != 0 && i >= 3 * sl && j < 3 * sl + 6)
            B.noalias() += gauss[sl] * gs[sl].row(i).transpose() * gs[sl].row(j);
        if (excess != 0 && i != j) {
          // excess * H.block(i, j), i < j, written out: the call and its
          // 3 x 3 temporary were 13 % of assemble() (perf, Song's AFM).
          const Eigen::Vector3d w = excess * H.upper[VolumeHessian::pair(i, j)];
          B(0, 1) -= w.z(), B(0, 2) += w.y(), B(1, 0) += w.z(), B(1, 2) -= w.x(), B(2, 0) -= w.y(), B(2, 1) += w.x();
        }
        if (b.base >= 0) add_block(val, b, B);
        else add_block(val, bt, B.transpose());
      }
  }
  if (!K) return;
  diag->resize(sys.dofs());
  for (size_t i = 0; i < sys.diagonal.size(); ++i) {
    const Block b = sys.diagonal[i];
    for (int q = 0; q < 3; ++q) (*diag)[3 * static_cast<Eigen::Index>(i) + q] = val[b.base + q * b.stride + q];
  }
}

// The Hessian alone (assemble()).
void linearise(const System &sys, const Eigen::MatrixXd &X, SpMat &K, Vec &diag, double curvature = 0) {
  assemble(sys, X, nullptr, nullptr, &K, &diag, curvature);
}

// Adds the load's Hessian (ForceField) at X to K and diag.
void add_load_stiffness(const System &sys, const ForceField &load, const Eigen::MatrixXd &X, SpMat &K, Vec &diag) {
  if (!load) return;
  NodeBlocks blocks;
  load(X, nullptr, &blocks);
  for (const auto &[node, B] : blocks) {
    const int l = node >= 0 && node < static_cast<int>(sys.local.size()) ? sys.local[static_cast<size_t>(node)] : -1;
    if (l < 0) continue;
    add_block(K.valuePtr(), sys.diagonal[static_cast<size_t>(l)], B);
    for (int q = 0; q < 3; ++q) diag[3 * l + q] += B(q, q);
  }
}

// The rows of a 4n x 3 field at the free nodes, as a dofs vector.
Vec gather_rows(const System &sys, const Eigen::MatrixXd &F) {
  Vec v(sys.dofs());
  for (size_t i = 0; i < sys.nodes.size(); ++i) v.segment<3>(3 * static_cast<int>(i)) = F.row(sys.nodes[i]).transpose();
  return v;
}

// The inverse: a dofs vector into the free nodes' rows of P (4n x 3).
void scatter_rows(const System &sys, const Vec &x, Eigen::MatrixXd &P) {
  for (size_t i = 0; i < sys.nodes.size(); ++i) P.row(sys.nodes[i]) = x.segment<3>(3 * static_cast<int>(i)).transpose();
}

// Internal plus external force on the free nodes; with K and diag, the
// internal Hessian too (assemble()) and the load's.
void net_force(const System &sys, const ForceField &forces, const Eigen::MatrixXd &ref,
               const Eigen::MatrixXd &X, Vec &r, SpMat *K = nullptr, Vec *diag = nullptr, double curvature = 0) {
  assemble(sys, X, &ref, &r, K, diag, curvature);
  if (forces) {
    Eigen::MatrixXd F = Eigen::MatrixXd::Zero(X.rows(), 3);
    forces(X, &F, nullptr);
    r += gather_rows(sys, F);
  }
  if (K) add_load_stiffness(sys, forces, X, *K, *diag);
}

// Tie q's energy (spring q, or lip pair q - springs.size()) added to e.
void add_tie_energy(const System &sys, size_t q, const Eigen::MatrixXd &X, double &e) {
  const SkinModel &m = sys.m;
  if (q < sys.springs.size()) {
    const Spring &s = m.springs[static_cast<size_t>(sys.springs[q])];
    e += spring_energy(s, sys.spring_k[q], (X.row(s.b) - X.row(s.a)).norm());
  } else {
    const LipPair &p = m.lip_pairs[static_cast<size_t>(sys.lips[q - sys.springs.size()])];
    e += lip_contact_energy(p, X(p.upper, 1) - X(p.lower, 1)).e;
  }
}

// An element's energy added to e, term by term: its volume, its slabs'
// floors and layer terms, its shape.
void add_element_energy(const System &sys, const Element &el, const Eigen::MatrixXd &ref, const Eigen::MatrixXd &X,
                        double &e) {
  const SkinModel &m = sys.m;
  const bool layered = el.layered;
  double vs[3] = {0, 0, 0};
  if (layered)
    for (int sl = 0; sl < 3; ++sl) vs[sl] = element_volume(m, X, el.f, nullptr, sl);
  if (el.weight > 0) {
    const double dv = (layered ? vs[0] + vs[1] + vs[2] : element_volume(m, X, el.f)) - m.rest_volume[el.f];
    e += 0.5 * el.weight * dv * dv;
  }
  for (int sl = 0; sl < 3; ++sl) {
    if (el.collapse[sl] > 0)
      e += el.collapse[sl] * (layered ? collapse_floor(vs[sl] / el.slab_rest[sl], m.params.collapse_knee)
                                      : slab_floor(m, X, el, sl)).e;
    if (el.layer_weight[sl] > 0) {
      const double dv = vs[sl] - el.slab_rest[sl];
      e += 0.5 * el.layer_weight[sl] * dv * dv;
    }
  }
  if (el.shape > 0) {
    Eigen::Matrix<double, 12, 3> d;
    for (int k = 0; k < 12; ++k) d.row(k) = X.row(el.global[k]) - ref.row(el.global[k]);
    e += 0.5 * el.shape * (d.rowwise() - d.colwise().mean()).squaredNorm();
  }
}

// The tissue's potential energy: springs, lips, volume and shape terms.
double internal_energy(const System &sys, const Eigen::MatrixXd &ref, const Eigen::MatrixXd &X) {
  double e = 0;
  for (size_t q = 0; q < sys.ties(); ++q) add_tie_energy(sys, q, X, e);
  for (const Element &el : sys.elements) add_element_energy(sys, el, ref, X, e);
  return e;
}

// A node the contacts moved: its local index and where it was.
struct MovedNode {
  int local;
  Eigen::Vector3d from;
};

// How much internal_energy() changed when the contacts moved `moved` to
// their places in X: the terms those nodes are in, summed at both places (X
// is put back as it was), not the whole sum.
double moved_energy_change(const System &sys, const Eigen::MatrixXd &ref, Eigen::MatrixXd &X,
                           const std::vector<MovedNode> &moved) {
  std::vector<int> terms;
  for (const MovedNode &n : moved)
    terms.insert(terms.end(), sys.terms.begin() + sys.term_start[static_cast<size_t>(n.local)],
                 sys.terms.begin() + sys.term_start[static_cast<size_t>(n.local) + 1]);
  std::sort(terms.begin(), terms.end());
  terms.erase(std::unique(terms.begin(), terms.end()), terms.end());
  auto sum = [&] {
    double e = 0;
    for (int t : terms) {
      if (t >= 0) add_element_energy(sys, sys.elements[static_cast<size_t>(t)], ref, X, e);
      else add_tie_energy(sys, static_cast<size_t>(-1 - t), X, e);
    }
    return e;
  };
  const double after = sum();
  std::vector<Eigen::Vector3d> to;
  for (const MovedNode &n : moved) {
    const int g = sys.nodes[static_cast<size_t>(n.local)];
    to.push_back(X.row(g).transpose());
    X.row(g) = n.from.transpose();
  }
  const double before = sum();
  for (size_t k = 0; k < moved.size(); ++k) X.row(sys.nodes[static_cast<size_t>(moved[k].local)]) = to[k].transpose();
  return after - before;
}

// Total potential energy at X: the tissue's `internal` energy there
// (internal_energy()) plus the external load's.
double total_energy(double internal, const ForceField &forces, const Eigen::MatrixXd &X) {
  return forces ? internal + forces(X, nullptr, nullptr) : internal;
}

// Skull and eyeball contacts: per local node, the constraint normal (zero:
// free), and whether it is the eyeball's.
struct Contacts {
  Eigen::MatrixXd normal;       // nodes x 3
  std::vector<uint8_t> on_eye;  // per node: held off its eyeball (else, with a normal, by its skull plane)
  int active = 0;

  void filter(Vec &v) const {
    if (!active) return;
    for (int i = 0; i < normal.rows(); ++i) {
      const Eigen::Vector3d nn = normal.row(i);
      if (nn.squaredNorm() == 0) continue;
      Eigen::Ref<Vec> s = v.segment(3 * i, 3);
      s -= nn * nn.dot(s);
    }
  }

  // K -> S K S + (I - S) d: the filtered system, whose solution has no
  // component along a held node's normal (S = I - n n^T on held nodes).
  void filter(const System &sys, SpMat &K) const {
    if (!active) return;
    double *val = K.valuePtr();
    for (size_t j = 0; j < sys.adj.size(); ++j) {
      const Eigen::Vector3d nj = normal.row(static_cast<Eigen::Index>(j));
      const bool hj = nj.squaredNorm() > 0;
      for (size_t p = 0; p < sys.adj[j].size(); ++p) {
        const int i = sys.adj[j][p];
        const Eigen::Vector3d ni = normal.row(i);
        const bool hi = ni.squaredNorm() > 0;
        if (!hi && !hj) continue;
        const Block b{K.outerIndexPtr()[3 * j] + 3 * static_cast<int>(p), 3 * static_cast<int>(sys.adj[j].size())};
        Eigen::Map<Eigen::Matrix3d, 0, Eigen::OuterStride<>> B(val + b.base, Eigen::OuterStride<>(b.stride));
        Eigen::Matrix3d M = B;
        if (hi) M -= ni * (ni.transpose() * M);
        if (hj) M -= (M * nj) * nj.transpose();
        if (hi && static_cast<size_t>(i) == j) M += (B.trace() / 3) * ni * ni.transpose();
        B = M;
      }
    }
  }
};

// Puts penetrating nodes back on their skull plane, or on the sphere of the
// eyeball they lie near (grown by their clearance), and activates them. On
// an eyeball the constraint plane is the sphere's tangent plane at the node,
// renewed at every update; a held node is kept on the sphere. Returns the
// largest correction; with `moved_nodes`, appends each node it moved.
double update_contacts(const System &sys, Eigen::MatrixXd &X, Contacts &c,
                       std::vector<MovedNode> *moved_nodes = nullptr) {
  const SkinModel &m = sys.m;
  if (c.normal.rows() != static_cast<Eigen::Index>(sys.nodes.size())) {
    c.normal = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(sys.nodes.size()), 3);
    c.on_eye.assign(sys.nodes.size(), 0);
  }
  double moved = 0;
  c.active = 0;
  for (size_t i = 0; i < sys.nodes.size(); ++i) {
    const Eigen::Index row = static_cast<Eigen::Index>(i);
    // An active node stays active for the rest of the solve: releasing
    // nodes the residual pulls off the bone makes the active set chatter.
    const bool was = c.normal.row(row).squaredNorm() > 0;
    const int g = sys.nodes[i];
    if (sys.eye[i] >= 0) {
      const EyeSphere &e = m.eyes[static_cast<size_t>(sys.eye[i])];
      const Eigen::Vector3d q = X.row(g).transpose() - e.centre;
      const double d = q.norm();
      if (!(d > 0)) continue;
      const double gap = d - e.radius - eye_clearance_in(m, m.vertex_of(g), X);
      // Once on the eye, a node stays on it; a node that also has a skull
      // plane leaves it for the eye when it meets the ball.
      const bool on = (was && c.on_eye[i]) || gap < 0;
      if (on || !sys.rejects[i]) {
        const Eigen::Vector3d nn = q / d;
        if (on && gap != 0) {
          if (moved_nodes) moved_nodes->push_back({static_cast<int>(i), X.row(g).transpose()});
          X.row(g) -= gap * nn.transpose();
          moved = std::max(moved, std::abs(gap));
        }
        c.normal.row(row) = on ? Eigen::RowVector3d(nn.transpose()) : Eigen::RowVector3d::Zero();
        c.on_eye[i] = on;
        c.active += on;
        continue;
      }
    }
    if (!sys.rejects[i]) continue;
    const int v = m.vertex_of(g);
    const Eigen::Vector3d nn = m.normal.row(v);
    const Eigen::Vector3d skull = X.row(m.node(kSkull, v));
    const double gap = (X.row(g).transpose() - skull).dot(nn);
    const bool on = was || gap < 0;
    if (gap < 0) {
      if (moved_nodes) moved_nodes->push_back({static_cast<int>(i), X.row(g).transpose()});
      X.row(g) -= gap * nn.transpose();
      moved = std::max(moved, -gap);
    }
    c.normal.row(row) = on ? Eigen::RowVector3d(nn.transpose()) : Eigen::RowVector3d::Zero();
    c.active += on;
  }
  return moved;
}

// Jacobi estimate of the remaining displacement: max |r_i| / K_ii.
double displacement_estimate(const Vec &r, const Vec &diag) {
  double worst = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (diag[i] > 0) worst = std::max(worst, std::abs(r[i]) / diag[i]);
  return worst;
}

double max_node_motion(const Vec &dx) {
  double worst = 0;
  for (Eigen::Index i = 0; i + 2 < dx.size(); i += 3) worst = std::max(worst, dx.segment<3>(i).norm());
  return worst;
}

// Baraff and Witkin's modified PCG: solves A x = b in the subspace the
// filter leaves free. `apply` computes A p, `precondition` z = P^-1 r.
// Stops early, setting *indefinite, when A shows a direction of
// non-positive curvature.
template <class Apply, class Precondition>
int filtered_pcg(const Apply &apply, const Precondition &precondition, const Contacts &c, const Vec &b,
                 Vec &x, int max_iter, double relative, bool *indefinite = nullptr) {
  if (indefinite) *indefinite = false;
  x.setZero(b.size());
  Vec r = b;
  c.filter(r);
  Vec z(b.size()), q(b.size());
  precondition(r, z);
  c.filter(z);
  Vec p = z;
  double delta = r.dot(z);
  const double delta0 = delta;
  if (!(delta0 > 0)) return 0;
  int it = 0;
  for (; it < max_iter; ++it) {
    if (delta <= relative * relative * delta0) break;
    apply(p, q);
    c.filter(q);
    const double pq = p.dot(q);
    if (!(pq > 0)) {
      if (indefinite) *indefinite = true;
      break;
    }
    const double alpha = delta / pq;
    x += alpha * p;
    r -= alpha * q;
    precondition(r, z);
    c.filter(z);
    const double next = r.dot(z);
    p = z + (next / delta) * p;
    delta = next;
  }
  return it;
}

// out = K x for K on the system's pattern, a 3 x 3 block per pair of coupled
// nodes (System::block), stored on and above the diagonal: block (i, j),
// i < j, also stands for (j, i) as its transpose. A ninth of the index work
// of Eigen's scalar product (on Song's whole simulation mesh 1.8 times
// faster), and half the memory of the whole matrix.
void block_multiply(const System &sys, const SpMat &K, const Vec &x, Vec &out) {
  out.setZero(x.size());
  const double *val = K.valuePtr();
  const double *xs = x.data();
  double *os = out.data();
  for (size_t j = 0; j < sys.adj.size(); ++j) {
    const std::vector<int> &col = sys.adj[j];
    // The block's three columns, each its column's 3 rows at 3 p.
    const double *c0 = val + K.outerIndexPtr()[3 * j], *c1 = c0 + 3 * col.size(), *c2 = c1 + 3 * col.size();
    const double x0 = xs[3 * j], x1 = xs[3 * j + 1], x2 = xs[3 * j + 2];
    double s0 = 0, s1 = 0, s2 = 0;  // row j of K times x
    for (size_t p = 0; p < col.size(); ++p) {
      const double *b0 = c0 + 3 * p, *b1 = c1 + 3 * p, *b2 = c2 + 3 * p;
      const size_t i = static_cast<size_t>(col[p]);
      if (i == j) {
        for (int r = 0; r < 3; ++r) os[3 * j + r] += b0[r] * x0 + b1[r] * x1 + b2[r] * x2;
        continue;
      }
      const double y0 = xs[3 * i], y1 = xs[3 * i + 1], y2 = xs[3 * i + 2];
      for (int r = 0; r < 3; ++r) os[3 * i + r] += b0[r] * x0 + b1[r] * x1 + b2[r] * x2;
      s0 += b0[0] * y0 + b0[1] * y1 + b0[2] * y2;
      s1 += b1[0] * y0 + b1[1] * y1 + b1[2] * y2;
      s2 += b2[0] * y0 + b2[1] * y1 + b2[2] * y2;
    }
    os[3 * j] += s0, os[3 * j + 1] += s1, os[3 * j + 2] += s2;
  }
}

// dst = src, where both have the system's pattern: the values only (the
// factorised copy is made at every refresh; its indices never change).
void copy_values(const SpMat &src, SpMat &dst) {
  if (dst.nonZeros() != src.nonZeros() || dst.rows() != src.rows()) dst = src;
  else std::copy(src.valuePtr(), src.valuePtr() + src.nonZeros(), dst.valuePtr());
}

bool finite(const Vec &v) { return v.allFinite(); }

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

// One dynamic set's system, its symbolic factorisation (the fill-reducing
// ordering), and the rest-state factorisation once needed.
struct FactorCache::Entry {
  std::unique_ptr<System> sys;
  Ldlt symbolic;  // analysed on the pattern; factorised per Newton step
  bool analysed = false;  // the pattern is made of 3 x 3 blocks, 3 nodes per vertex (always, by construction)
  std::unique_ptr<Ldlt> rest;
  bool rest_ok = false;
  int refresh_after = 0;  // newton: CG iterations worth a refactorisation (0: not known yet)
  bool factored = false;  // `symbolic` holds a usable factorisation (of the last solve's tangent)
};

FactorCache::FactorCache() = default;
FactorCache::~FactorCache() = default;
FactorCache::Entry *FactorCache::find(const std::vector<int> &vertices, bool lip_contact) const {
  auto it = entries_.find({lip_contact, vertices});
  return it == entries_.end() ? nullptr : it->second.get();
}
FactorCache::Entry *FactorCache::insert(const std::vector<int> &vertices, bool lip_contact, std::unique_ptr<Entry> e) {
  Entry *raw = e.get();
  entries_[{lip_contact, vertices}] = std::move(e);
  return raw;
}
void FactorCache::clear() { entries_.clear(); }

SolveCounts SolveCounts::operator-(const SolveCounts &o) const {
  return {solves - o.solves, failed - o.failed, iterations - o.iterations, cg_iterations - o.cg_iterations,
          factorisations - o.factorisations, assemblies - o.assemblies, energies - o.energies};
}

std::string SolveCounts::text() const {
  char b[256];
  std::snprintf(b, sizeof b,
                "%lld solves (%lld failed), %lld Newton iterations, %lld CG iterations, %lld factorisations, "
                "%lld tangents assembled, %lld energies",
                solves, failed, iterations, cg_iterations, factorisations, assemblies, energies);
  return b;
}

void add_work(SolveStats &into, const SolveStats &more) {
  into.iterations += more.iterations;
  into.cg_iterations += more.cg_iterations;
  into.factorisations += more.factorisations;
  into.half_steps += more.half_steps;
  into.chord_steps += more.chord_steps;
  into.assemblies += more.assemblies;
  into.energies += more.energies;
  into.carried_energies += more.carried_energies;
  into.carried_energy_gap = std::max(into.carried_energy_gap, more.carried_energy_gap);
  into.seconds += more.seconds;
}

SolveCounts SolveTotals::counts() const {
  return {solves.load(), failed.load(), iterations.load(), cg_iterations.load(), factorisations.load(),
          assemblies.load(), energies.load()};
}

const char *solver_name(SolverKind kind) {
  switch (kind) {
    case SolverKind::Newton: return "newton";
    case SolverKind::NewtonRest: return "newton-rest";
    case SolverKind::ImplicitEuler: return "implicit-euler";
    case SolverKind::NewtonJacobi: return "newton-jacobi";
  }
  return "?";
}

bool solver_from_name(const std::string &name, SolverKind *kind) {
  for (SolverKind k : kSolverKinds)
    if (name == solver_name(k)) {
      *kind = k;
      return true;
    }
  return false;
}

bool skull_rejects(const SkinModel &m, int v) {
  if (m.skull_free[static_cast<size_t>(v)]) return false;
  const Eigen::Vector3d out = m.X0.row(v).transpose() - m.centre;
  return m.normal.row(v).dot(out) > 0.3 * out.norm();
}

namespace {

// The cached system of `vertices` (built and analysed on first use).
FactorCache::Entry *entry_for(const SkinModel &model, const std::vector<int> &vertices, bool lip_contact,
                              FactorCache *cache, std::unique_ptr<FactorCache::Entry> &own) {
  if (cache)
    if (FactorCache::Entry *e = cache->find(vertices, lip_contact); e && &e->sys->m == &model) return e;
  auto e = std::make_unique<FactorCache::Entry>();
  e->sys = std::make_unique<System>(model, vertices, lip_contact);
  // A vertex's three free nodes (consecutive in System::nodes) share their
  // neighbours: one 9 x 9 pivot block (block_ldlt.h); the pattern is the
  // upper triangle. Together 1.27 times less CPU for Song's AFM than a node
  // at a time on the whole matrix, the same report to 1.1e-5 units
  // (docs/anatomy.md, "Solver").
  if (e->sys->dofs() > 0) e->analysed = e->symbolic.analyze(e->sys->pattern, 3, true);
  if (cache) return cache->insert(vertices, lip_contact, std::move(e));
  own = std::move(e);
  return own.get();
}

// The rest-state Hessian's factorisation, computed once per entry.
const Ldlt *rest_factor(FactorCache::Entry &e) {
  if (!e.rest) {
    e.rest = std::make_unique<Ldlt>(e.symbolic);
    SpMat K;
    Vec diag;
    linearise(*e.sys, e.sys->m.X0, K, diag);
    e.rest_ok = e.analysed && e.rest->factorize(K) != Ldlt::Result::kSingular;
  }
  return e.rest_ok ? e.rest.get() : nullptr;
}

}  // namespace

Eigen::MatrixXd residual_forces(const SkinModel &model, const std::vector<int> &vertices,
                                const ForceField &forces, const Eigen::MatrixXd &reference,
                                const Eigen::MatrixXd &X, bool lip_contact) {
  System sys(model, vertices, lip_contact);
  Vec r;
  net_force(sys, forces, reference, X, r);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(X.rows(), 3);
  scatter_rows(sys, r, out);
  return out;
}

Expected<Eigen::MatrixXd> linear_response(const SkinModel &model, const std::vector<int> &vertices,
                                          const ForceField &load, FactorCache *cache) {
  std::unique_ptr<FactorCache::Entry> own;
  FactorCache::Entry *e = entry_for(model, vertices, false, cache, own);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(model.X0.rows(), 3);
  if (e->sys->dofs() == 0) return out;
  const Ldlt *rest = rest_factor(*e);
  if (!rest) return Status::error("linear response: the rest-state Hessian is singular");
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(model.X0.rows(), 3);
  load(model.X0, &F, nullptr);  // the tissue's own stiffness: the wave's reach
  Vec u;
  rest->solve(gather_rows(*e->sys, F), u);
  if (!finite(u)) return Status::error("linear response: non-finite displacement");
  scatter_rows(*e->sys, u, out);
  return out;
}

SolveStats solve_equilibrium(const SkinModel &model, const std::vector<int> &vertices,
                             const ForceField &forces, const Eigen::MatrixXd &reference, Eigen::MatrixXd &X,
                             const SolverOptions &options, FactorCache *cache, LoadControl *control) {
  const auto start = std::chrono::steady_clock::now();
  SolveStats st;
  auto done = [&](bool ok, std::string message) {
    st.converged = ok;
    st.message = std::move(message);
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (SolveTotals *t = options.totals) {
      ++t->solves;
      t->failed += !ok;
      t->iterations += st.iterations;
      t->cg_iterations += st.cg_iterations;
      t->factorisations += st.factorisations;
      t->assemblies += st.assemblies;
      t->energies += st.energies;
    }
    return st;
  };
  const std::string name = solver_name(options.kind);
  if (!(options.tolerance > 0)) return done(false, "solver: tolerance must be positive");
  if (control && options.kind == SolverKind::ImplicitEuler)
    return done(false, "solver: implicit-euler cannot solve for a tension (use a newton solver)");
  if (control && !(control->unit_load && control->action))
    return done(false, "solver: a load control needs a unit load and an action");
  if (control) control->capped = control->unreachable = false;
  std::unique_ptr<FactorCache::Entry> own;
  FactorCache::Entry *entry = entry_for(model, vertices, options.lip_contact, cache, own);
  const System &sys = *entry->sys;
  const int n = sys.dofs();
  st.unknowns = n;
  if (n == 0) return done(!control, control ? "solver: the dynamic set is empty" : "");
  if (!entry->analysed) return done(false, "solver: the tangent's pattern is not made of 3 x 3 blocks");

  Contacts contacts;
  update_contacts(sys, X, contacts);
  SpMat K;
  Vec diag, r, dx, x0, trial;
  const double tol = options.tolerance;
  auto jacobi = [](const Vec &d) {
    return [&d](const Vec &in, Vec &out) { out = in.cwiseQuotient(d.cwiseMax(1e-300)); };
  };

  if (options.kind == SolverKind::ImplicitEuler) {
    const int max_steps = options.max_iterations > 0 ? options.max_iterations : 2000;
    Vec mass(n);
    for (size_t i = 0; i < sys.nodes.size(); ++i) mass.segment<3>(3 * static_cast<int>(i)).setConstant(model.mass[sys.nodes[i]]);
    linearise(sys, X, K, diag);
    ++st.assemblies;
    const double t0 = std::sqrt(mass.mean() / std::max(diag.mean(), 1e-300));
    const double h = options.time_step * t0, gamma = options.damping / t0;
    add_load_stiffness(sys, forces, X, K, diag);
    Vec v = Vec::Zero(n), dv, Kv(n), b(n);
    for (int step = 0; step < max_steps; ++step) {
      // The first step's tangent is the one linearised above.
      net_force(sys, forces, reference, X, r, step > 0 ? &K : nullptr, &diag);
      st.assemblies += step > 0;
      st.residual = displacement_estimate([&] { Vec f = r; contacts.filter(f); return f; }(), diag);
      if (!finite(r)) return done(false, "implicit-euler: non-finite force at step " + std::to_string(step));
      if (step > 0 && st.residual < tol && st.last_step < tol) {
        st.contacts = contacts.active;
        return done(true, "");
      }
      block_multiply(sys, K, v, Kv);
      b = h * (r - gamma * mass.cwiseProduct(v) - h * Kv);
      const Vec adiag = (1 + h * gamma) * mass + h * h * diag;
      auto apply = [&](const Vec &p, Vec &out) {
        block_multiply(sys, K, p, out);
        out = (1 + h * gamma) * mass.cwiseProduct(p) + h * h * out;
      };
      st.cg_iterations += filtered_pcg(apply, jacobi(adiag), contacts, b, dv, options.max_cg, options.cg_relative);
      if (!finite(dv)) return done(false, "implicit-euler: non-finite velocity at step " + std::to_string(step));
      v += dv;
      contacts.filter(v);
      x0 = gather_rows(sys, X);
      x0 += h * v;
      scatter_rows(sys, x0, X);
      st.last_step = h * max_node_motion(v);
      update_contacts(sys, X, contacts);
      st.iterations = step + 1;
    }
    st.contacts = contacts.active;
    return done(false, "implicit-euler: no equilibrium after " + std::to_string(max_steps) +
                           " steps (remaining displacement " + number(st.residual) + ")");
  }

  // Newton. The step solves K dx = r on the filtered subspace:
  //   newton         CG preconditioned by a factorisation of the filtered
  //                  tangent (the first step always factorises), refreshed
  //                  for the next step once CG needed more than
  //                  Entry::refresh_after iterations (at least kRefresh), and
  //                  at once when a CG run reaches three times that;
  //   newton-rest    CG preconditioned by the rest-state factorisation,
  //                  shared by every solve on the set, until CG needs more
  //                  than kRefreshRest iterations; then as newton;
  //   newton-jacobi  CG with the Jacobi preconditioner.
  constexpr int kRefresh = 3, kRefreshRest = 30;
  constexpr double kHalfCurvature = 0.5;  // the half tangent's share of the indefinite parts
  // SolverOptions::keep_tangent: after a step that moved no node more than
  // this many tolerances (five AFM quanta) and less than a quarter of the
  // step before, the next keeps the last full tangent and assembles the
  // force alone, without the tangent's blocks (most of assemble()'s work).
  // Newton is then converging fast, the tangent has hardly changed over so
  // short a step, and a step on it (a chord step) converges about as fast.
  // Song's AFM: 9 % fewer tangents, as many Newton iterations, 3.1 % fewer
  // instructions (callgrind, one worker); the generated heads 11-14 % fewer
  // tangents. Without the quarter, a buckled stiff skin's solve crawled
  // along its flat equilibrium (Solver.TheHalfTangentCutsTheCrawlOnAStiffSkin:
  // 47 iterations instead of 35; with the seventy-second session's
  // preconditioner, no progress in 60); at 20 tolerances Song's AFM took
  // 3 % more iterations.
  constexpr double kKeepTangent = 10, kConverging = 0.25;
  const Ldlt *rest = nullptr;
  if (options.kind == SolverKind::NewtonRest) {
    rest = rest_factor(*entry);
    if (!rest) return done(false, "solver: the rest-state Hessian of the dynamic set is singular");
  }
  const Ldlt *factor = rest;
  bool refresh = options.kind == SolverKind::Newton;
  // A later solve on the same set (a target's search, a muscle's other
  // side) starts with the factorisation the last one ended on: its poses
  // lie near, and CG refreshes it once it costs more than a new one (Song's
  // AFM: 534 -> 497 factorisations, 4 % more CG iterations).
  if (refresh && entry->factored) refresh = false, factor = &entry->symbolic;
  SpMat Kf;  // the filtered tangent, factorised
  Eigen::MatrixXd unit_f;
  Vec g, u, w, cgrad;
  double t = control ? std::max(control->tension, 0.0) : 0.0;
  // Load control gives up once the tension passes this multiple of its
  // first estimate (the linear one from rest, or the tension it starts
  // from): the tissue has locked; or falls below its inverse: the load
  // moves the action the wrong way.
  constexpr double kUnreachable = 50;
  double t_ref = t;
  Eigen::MatrixXd Ac;
  auto load_at = [&](double tension) -> ForceField {
    if (!control) return forces;
    return [&, tension](const Eigen::MatrixXd &P, Eigen::MatrixXd *F, NodeBlocks *Kl) {
      double e = forces ? forces(P, F, Kl) : 0.0;
      NodeBlocks unit;
      if (!F) {
        e += tension * control->unit_load(P, nullptr, Kl ? &unit : nullptr);
      } else {
        Eigen::MatrixXd G = Eigen::MatrixXd::Zero(P.rows(), 3);
        e += tension * control->unit_load(P, &G, Kl ? &unit : nullptr);
        *F += tension * G;
      }
      if (Kl)
        for (const auto &[node, B] : unit) Kl->emplace_back(node, tension * B);
      return e;
    };
  };
  auto linear_solve = [&](const Vec &b, Vec &x, bool *indefinite, int max_cg) {
    auto apply = [&](const Vec &p, Vec &out) { block_multiply(sys, K, p, out); };
    // The factorisation preconditions in single precision: CG works in
    // double and stops on its own residual, and the float factors halve
    // the memory read per iteration (Song's AFM: the triangular solves
    // 3.5 -> 2.7 s of 13 s of CPU, as many CG iterations).
    if (factor)
      return filtered_pcg(apply, [&](const Vec &in, Vec &out) { factor->precondition(in, out); }, contacts, b, x,
                          max_cg, options.newton_forcing, indefinite);
    return filtered_pcg(apply, jacobi(diag), contacts, b, x, max_cg, options.newton_forcing, indefinite);
  };
  const int max_it = options.max_iterations > 0 ? options.max_iterations : 400;
  double action = 0;
  constexpr int kStall = 60;
  double best_distance = 0;
  int best_at = 0;
  int projected_run = 0;  // refreshes in a row that did not factorise the full tangent
  double shift = 1e-3;    // the last diagonal shift that made the full tangent definite
  bool half_failed = false;  // the half tangent was indefinite in this solve
  bool energy_known = false;  // known_energy is the tissue's energy at X (see the line search)
  double known_energy = 0;
  Eigen::MatrixXd Xt;  // the line search's trial positions
  bool full_tangent = false;  // K (and diag) hold a full tangent, the last step's or one it kept
  double step_before = 0;      // the step before the last (kKeepTangent)
  for (int it = 0;; ++it) {
    const ForceField load = load_at(t);
    const bool keep_tangent = options.keep_tangent && full_tangent && st.last_step < kKeepTangent * tol &&
                              st.last_step < kConverging * step_before;
    if (keep_tangent) {
      net_force(sys, load, reference, X, r);  // the force alone (kKeepTangent)
      ++st.chord_steps;
    } else {
      net_force(sys, load, reference, X, r, &K, &diag, 1.0);
      ++st.assemblies;
    }
    if (!finite(r)) return done(false, name + ": non-finite force");
    Vec rf = r;
    contacts.filter(rf);
    st.residual = displacement_estimate(rf, diag);
    if (control) {
      Ac = Eigen::MatrixXd::Zero(X.rows(), 3);
      action = control->action(X, &Ac);
      cgrad = gather_rows(sys, Ac);
      contacts.filter(cgrad);
      if (!(cgrad.squaredNorm() > 0)) return done(false, name + ": the controlled action does not depend on the dynamic set");
    }
    const bool on_target = !control || control->capped || std::abs(action - control->value) < tol;
    if (it > 0 && st.residual < tol && st.last_step < tol && on_target) break;
    // Stall: the distance to the solution (the remaining displacement, and
    // the action's from its value) has not halved its best for kStall
    // iterations. Newton then cycles (a lid turned 50 degrees: the line
    // search cuts to 1/2048, a fresh tangent leaps back, for all 400
    // iterations); a converging solve halves it every few.
    const double distance = st.residual + (control && !control->capped ? std::abs(action - control->value) : 0.0);
    if (it == 0 || distance < 0.5 * best_distance) best_distance = distance, best_at = it;
    if (it - best_at >= kStall) {
      st.contacts = contacts.active;
      std::string why = name + ": no equilibrium, no progress in " + std::to_string(kStall) +
                        " iterations (remaining displacement " + number(st.residual);
      if (control) why += ", action " + number(action) + " of " + number(control->value);
      return done(false, why + ")");
    }
    if (it >= max_it) {
      st.contacts = contacts.active;
      std::string why = name + ": no equilibrium after " + std::to_string(max_it) +
                        " iterations (remaining displacement " + number(st.residual);
      if (control) why += ", action " + number(action) + " of " + number(control->value);
      return done(false, why + ")");
    }
    // The full tangent while it is definite: Newton then converges
    // quadratically near the equilibrium. Where it is not (compressed
    // springs, strongly deformed elements), the projected one (linearise()).
    // Newton on the projected tangent converges linearly, and where the full
    // one stays indefinite to the end it crawls: a calibration of the 10k
    // head's mentalis took 134 iterations, the last 120 moving about twice
    // the tolerance each. So after two refreshes in a row on the projected
    // tangent, the full one with its diagonal raised by a factor 1 + mu is
    // tried first (mu from the last that worked, 1e-3 at first, then ten
    // and a hundred times that, at most 0.1): a Levenberg-Marquardt step
    // that keeps the curvature of the compressed springs and of the volume
    // term. The 10k head's model: 451 -> 341 Newton iterations; Song's AFM
    // 1,424 -> 1,362; the same models and reports.
    // Before the projected tangent, the one with half the indefinite parts
    // (kHalfCurvature, assemble()), kept where it is definite: it softens
    // the modes that a compressed stiff skin buckles along less than the
    // projected one, and Newton crawls less. Where it was not definite once,
    // the solve goes to the projected tangent directly after: most of the
    // half tangents of Song's AFM that the full one's failure led to were
    // indefinite too (52 of 69), each a factorisation thrown away. A 10
    // times stiffer epidermis then costs 28 % more Newton iterations over
    // every muscle on Song (36 % before) and 29 % on the 10k head (33 %);
    // docs/anatomy.md, "Solver and stopping rule".
    enum class Tangent { Full, Half, Shifted, Projected } tangent = Tangent::Full;
    // The full and the half tangent are kept only where definite.
    auto definite_only = [&] { return tangent == Tangent::Full || tangent == Tangent::Half; };
    auto project = [&] {
      if (tangent == Tangent::Half) half_failed = true;
      tangent = tangent == Tangent::Full && options.half_tangent && !half_failed ? Tangent::Half : Tangent::Projected;
      linearise(sys, X, K, diag, tangent == Tangent::Half ? kHalfCurvature : 0.0);
      ++st.assemblies;
      add_load_stiffness(sys, load, X, K, diag);
    };
    auto shifted = [&] {
      const SpMat unshifted = K;
      for (double mu : {shift, 10 * shift, 100 * shift}) {
        if (mu > 0.1) break;
        K = unshifted;
        for (Eigen::Index c = 0; c < K.outerSize(); ++c)
          for (SpMat::InnerIterator e(K, c); e; ++e)
            if (e.row() == e.col()) e.valueRef() *= 1 + mu;
        copy_values(K, Kf);
        contacts.filter(sys, Kf);
        ++st.factorisations;
        const Ldlt::Result res = entry->symbolic.factorize(Kf, true);
        entry->factored = entry->symbolic.complete();
        if (res == Ldlt::Result::kDefinite) {
          shift = mu;
          tangent = Tangent::Shifted;
          return true;
        }
      }
      K = unshifted;
      return false;
    };
    auto factorise = [&] {
      for (;;) {
        copy_values(K, Kf);
        contacts.filter(sys, Kf);
        // The full and the half tangent's stop at the first indefinite pivot.
        const Ldlt::Result res = entry->symbolic.factorize(Kf, definite_only());
        ++st.factorisations;
        const bool ok = res != Ldlt::Result::kSingular;
        entry->factored = entry->symbolic.complete();
        if (ok && (!definite_only() || res == Ldlt::Result::kDefinite)) break;
        if (tangent == Tangent::Projected) return false;
        if (tangent == Tangent::Full && projected_run >= 2 && shifted()) break;
        project();
      }
      factor = &entry->symbolic;
      if (entry->refresh_after == 0) {
        // A factorisation costs sum_j c_j^2 (c_j: scalar column j of L), a
        // CG iteration about 4 nnz(L) + nnz(K) (K's stored upper triangle
        // serves twice): refresh once CG spends a third of a factorisation.
        const double ratio = entry->symbolic.factor_flops() /
                             (4.0 * entry->symbolic.nonzeros() + 2.0 * static_cast<double>(K.nonZeros()));
        entry->refresh_after = std::max(kRefresh, static_cast<int>(ratio / 3));
      }
      return true;
    };
    bool fresh = refresh;
    if (refresh && !factorise()) return done(false, name + ": the tangent stiffness is singular");
    if (refresh) projected_run = tangent == Tangent::Full ? 0 : projected_run + 1;
    refresh = false;
    // newton: CG past a factorisation's worth of iterations (a stale
    // factorisation, say a projected one before a full tangent) stops, and
    // the step starts over with a fresh factorisation.
    const int cap = options.kind == SolverKind::Newton ? 3 * std::max(kRefresh, entry->refresh_after) : options.max_cg;
    bool indefinite = false;
    int cg = 0, cg2 = 0;
    double dt = 0;
    for (;;) {
      int c1 = linear_solve(rf, u, &indefinite, cap), c2 = 0;
      if (control && !indefinite) {
        unit_f = Eigen::MatrixXd::Zero(X.rows(), 3);
        control->unit_load(X, &unit_f, nullptr);
        g = gather_rows(sys, unit_f);
        c2 = linear_solve(g, w, &indefinite, cap);
      }
      cg += c1, cg2 += c2;
      if (options.kind == SolverKind::Newton && !fresh && !indefinite && std::max(c1, c2) >= cap) {
        if (!factorise()) return done(false, name + ": the tangent stiffness is singular");
        fresh = true;
        continue;
      }
      if (!indefinite || !definite_only()) break;
      project();  // CG met a direction of negative curvature
    }
    if (control) {
      cg = std::max(cg, cg2);
      // Bordered step: choose dt so that the linearised action of
      // X + u + dt w meets the target.
      const double cw = cgrad.dot(w);
      if (!(std::abs(cw) > 0) || !std::isfinite(cw)) return done(false, name + ": the load does not move the controlled action");
      double t_new = t + (control->value - action - cgrad.dot(u)) / cw;
      // Bounded steps: the tissue stiffens, and far from the equilibrium
      // the linearised action is a rough guide.
      if (t > 0) t_new = std::clamp(t_new, 0.5 * t, 4 * t);
      if (control->max_tension > 0 && (control->capped || t_new >= control->max_tension)) {
        control->capped = true;
        t_new = control->max_tension;
      }
      if (!(t_new > 0)) return done(false, name + ": the load moves the controlled action the wrong way");
      if (!std::isfinite(t_new)) return done(false, name + ": non-finite tension");
      if (t_ref == 0) t_ref = t_new;
      if (t_new > kUnreachable * t_ref) {
        control->unreachable = true;
        return done(false, name + ": the load cannot take the action to " + number(control->value) +
                               " (it reached " + number(action) + " at " + number(kUnreachable) +
                               " times the linear estimate of the tension)");
      }
      // The clamp halves a tension whose load moves the action the wrong
      // way at every step: fallen that far, it will not turn (Song's FAP 64
      // beyond its range: 40 iterations of halving).
      if (t_new < t_ref / kUnreachable)
        return done(false, name + ": the load moves the controlled action the wrong way (the tension fell to " +
                               number(t_new / t_ref) + " of its start)");
      dt = t_new - t;
      t = t_new;
      dx = u + dt * w;
    } else {
      dx = u;
    }
    st.cg_iterations += cg;
    st.half_steps += tangent == Tangent::Half;
    if (options.kind != SolverKind::NewtonJacobi &&
        cg > (options.kind == SolverKind::NewtonRest ? kRefreshRest : std::max(kRefresh, entry->refresh_after)))
      refresh = true;
    if (!finite(dx)) return done(false, name + ": non-finite step");
    // The stopping rule's last step (solver.h): the remaining displacement
    // is below tol, and so is this step and the action's gap after it. It is
    // taken whole and ends the solve, without the line search's energy and
    // another force and tangent to confirm (a solve's last iteration; Song's
    // AFM 3 % less CPU, the same reports).
    if (const double motion = max_node_motion(dx);
        it > 0 && st.residual < tol && motion < tol &&
        (!control || control->capped || std::abs(action + cgrad.dot(dx) - control->value) < tol)) {
      scatter_rows(sys, gather_rows(sys, X) + dx, X);
      const double held = update_contacts(sys, X, contacts);
      st.last_step = std::max(motion, held);
      st.iterations = it + 1;
      energy_known = false;
      if (st.last_step < tol) break;
      continue;
    }
    // Backtracking (Armijo) on the total energy: the loads are conservative.
    const ForceField next_load = load_at(t);
    Vec rn = rf;
    if (control) rn += dt * [&] { Vec gf = g; contacts.filter(gf); return gf; }();
    x0 = gather_rows(sys, X);
    st.energies += !energy_known;
    const double e0 = total_energy(energy_known ? known_energy : internal_energy(sys, reference, X), next_load, X);
    const double slope = rn.dot(dx);
    double alpha = 1, e_trial = 0, internal_trial = 0;
    // The trials differ from X in the set's rows only, which every trial
    // writes: one copy per solve, not per step.
    if (Xt.size() == 0) Xt = X;
    for (int ls = 0; ls < 12; ++ls) {
      trial = x0 + alpha * dx;
      scatter_rows(sys, trial, Xt);
      internal_trial = internal_energy(sys, reference, Xt);
      e_trial = total_energy(internal_trial, next_load, Xt);
      ++st.energies;
      if ((std::isfinite(e_trial) && e_trial <= e0 - 1e-4 * alpha * std::max(slope, 0.0)) || ls == 11) break;
      alpha *= 0.5;
    }
    // A whole step on the half, projected or shifted tangent may fall short: that
    // tangent is stiffer than the skin along a mode the compressed springs
    // soften, and Newton then crawls along it a step of the same length at a
    // time (the 10k head's zygomaticus major: 32 iterations). Twice, four and
    // eight times the step are tried while the energy keeps falling.
    double e_taken = e_trial, internal_taken = internal_trial;
    if (options.extend_steps && tangent != Tangent::Full && alpha == 1) {
      for (double longer : {2.0, 4.0, 8.0}) {
        const Vec further = x0 + longer * dx;
        scatter_rows(sys, further, Xt);
        const double internal = internal_energy(sys, reference, Xt), e = total_energy(internal, next_load, Xt);
        ++st.energies;
        if (!(std::isfinite(e) && e < e_taken)) break;
        e_taken = e, internal_taken = internal, trial = further, alpha = longer;
      }
    }
    if (!finite(trial)) return done(false, name + ": non-finite step");
    scatter_rows(sys, trial, X);
    step_before = st.last_step;
    st.last_step = alpha * max_node_motion(dx);
    std::vector<MovedNode> moved;
    const double held = update_contacts(sys, X, contacts, &moved);
    st.last_step = std::max(st.last_step, held);
    // The next step's line search starts from this tissue energy; only the
    // load's part is evaluated again (under load control its tension
    // changes). Where the contacts then moved nodes (after 88 % of Song's
    // steps, weighted by unknowns, half of those by under 0.03 of the
    // tolerance; a node held on an eyeball goes back onto the sphere after
    // every step), the terms those nodes are in are summed again at both
    // places and the difference added (moved_energy_change). Song's AFM: energies 3,880 ->
    // 2,578, the same AFM byte for byte.
    energy_known = true;
    known_energy = internal_taken;
    if (!moved.empty()) {
      known_energy += moved_energy_change(sys, reference, X, moved);
      ++st.carried_energies;
      if (options.check_carried_energy) {
        const double full = internal_energy(sys, reference, X);
        st.carried_energy_gap =
            std::max(st.carried_energy_gap, std::abs(known_energy - full) / std::max(std::abs(full), 1e-300));
      }
    }
    full_tangent = tangent == Tangent::Full;
    st.iterations = it + 1;
  }
  if (control) control->tension = t;
  st.contacts = contacts.active;
  return done(true, "");
}

}  // namespace afmb
