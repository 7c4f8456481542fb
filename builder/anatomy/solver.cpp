#include "anatomy/solver.h"

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>

namespace afmb {

struct FactorCache::Entry {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> ldlt;
  bool ok = false;
};

FactorCache::FactorCache() = default;
FactorCache::~FactorCache() = default;
FactorCache::Entry *FactorCache::find(const std::vector<int> &vertices) const {
  auto it = entries_.find(vertices);
  return it == entries_.end() ? nullptr : it->second.get();
}
FactorCache::Entry *FactorCache::insert(const std::vector<int> &vertices, std::unique_ptr<Entry> e) {
  Entry *raw = e.get();
  entries_[vertices] = std::move(e);
  return raw;
}
void FactorCache::clear() { entries_.clear(); }

const char *solver_name(SolverKind kind) {
  switch (kind) {
    case SolverKind::Newton: return "newton";
    case SolverKind::ImplicitEuler: return "implicit-euler";
    case SolverKind::NewtonJacobi: return "newton-jacobi";
  }
  return "?";
}

bool solver_from_name(const std::string &name, SolverKind *kind) {
  for (SolverKind k : {SolverKind::Newton, SolverKind::ImplicitEuler, SolverKind::NewtonJacobi})
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

using Vec = Eigen::VectorXd;
using SpMat = Eigen::SparseMatrix<double>;

// Elements whose rest volume is this small relative to the mean are left out
// of the volume term: seen edge-on from the centre, their volume says nothing.
constexpr double kVolumeFloor = 1e-3;
// Newton refactorises the tangent when a linear solve needed more CG
// iterations than this with the current preconditioner.
constexpr int kRefactorAfter = 30;

struct Element {
  int f;
  int local[9];   // local node per gradient row (layers 0-2), -1 when fixed
  int global[12]; // the element's nodes, layers 0-3
  double weight;  // volume term: k_v / |V0|, 0 for an element seen edge-on
  double shape;   // shape term: k_s |V0| / area
};

struct System {
  const SkinModel &m;
  std::vector<int> nodes;  // free nodes, global
  std::vector<int> local;  // global node -> local index, or -1
  std::vector<int> springs;
  std::vector<Element> elements;
  std::vector<uint8_t> rejects;  // per local node
  int dofs() const { return 3 * static_cast<int>(nodes.size()); }

  System(const SkinModel &model, const std::vector<int> &vertices) : m(model) {
    local.assign(static_cast<size_t>(kTissueLayers * m.n), -1);
    for (int v : vertices) {
      if (v < 0 || v >= m.n || !m.in_mesh[static_cast<size_t>(v)]) continue;
      for (int l = 0; l < kSkull; ++l) {
        const int g = m.node(l, v);
        if (local[static_cast<size_t>(g)] >= 0) continue;
        local[static_cast<size_t>(g)] = static_cast<int>(nodes.size());
        nodes.push_back(g);
        rejects.push_back(skull_rejects(m, v) ? 1 : 0);
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
        const Eigen::Vector3d a = m.X0.row(e.global[0]), b = m.X0.row(e.global[1]), c = m.X0.row(e.global[2]);
        const double area = 0.5 * (b - a).cross(c - a).norm();
        e.shape = area > 0 ? m.params.shape_modulus * v0 / area : 0.0;
        elements.push_back(e);
      }
    }
    std::sort(elements.begin(), elements.end(), [](const Element &a, const Element &b) { return a.f < b.f; });
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

// State of one linearisation: the spring Hessian, the volume gradients.
struct Linearisation {
  SpMat K;                 // springs only, dofs x dofs, PSD
  std::vector<Eigen::Matrix<double, 9, 3>> grad;  // per element
  Vec diag;                // diagonal of the whole Hessian (springs + volume)
};

void linearise(const System &sys, const Eigen::MatrixXd &X, Linearisation &lin) {
  const SkinModel &m = sys.m;
  const int n = sys.dofs();
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(sys.springs.size() * 36);
  for (int si : sys.springs) {
    const Spring &s = m.springs[static_cast<size_t>(si)];
    const Eigen::Vector3d d = X.row(s.b) - X.row(s.a);
    const double l = std::max(d.norm(), 1e-12 * s.rest);
    const Eigen::Vector3d u = d / l;
    double t, dt;
    tension(s, m.stiffness(s), l, &t, &dt);
    const Eigen::Matrix3d B =
        dt * u * u.transpose() + std::max(t, 0.0) / l * (Eigen::Matrix3d::Identity() - u * u.transpose());
    const int la = sys.local[static_cast<size_t>(s.a)], lb = sys.local[static_cast<size_t>(s.b)];
    const int ends[2] = {la, lb};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        if (ends[i] < 0 || ends[j] < 0) continue;
        const double sign = i == j ? 1.0 : -1.0;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) trip.emplace_back(3 * ends[i] + r, 3 * ends[j] + c, sign * B(r, c));
      }
  }
  // Shape term: k_s (delta_ij - 1/12) I per pair of the element's free nodes.
  for (const Element &el : sys.elements) {
    if (el.shape <= 0) continue;
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j) {
        if (el.local[i] < 0 || el.local[j] < 0) continue;
        const double v = el.shape * ((i == j ? 1.0 : 0.0) - 1.0 / 12.0);
        for (int k = 0; k < 3; ++k) trip.emplace_back(3 * el.local[i] + k, 3 * el.local[j] + k, v);
      }
  }
  lin.K.resize(n, n);
  lin.K.setFromTriplets(trip.begin(), trip.end());
  lin.diag = lin.K.diagonal();
  lin.grad.resize(sys.elements.size());
  for (size_t e = 0; e < sys.elements.size(); ++e) {
    const Element &el = sys.elements[e];
    if (el.weight == 0) {
      lin.grad[e].setZero();
      continue;
    }
    element_volume(m, X, el.f, &lin.grad[e]);
    for (int r = 0; r < 9; ++r)
      if (el.local[r] >= 0)
        for (int k = 0; k < 3; ++k) lin.diag[3 * el.local[r] + k] += el.weight * lin.grad[e](r, k) * lin.grad[e](r, k);
  }
}

// out = K p (springs and the Gauss-Newton volume term).
void hessian_times(const System &sys, const Linearisation &lin, const Vec &p, Vec &out) {
  out.noalias() = lin.K * p;
  for (size_t e = 0; e < sys.elements.size(); ++e) {
    const Element &el = sys.elements[e];
    double dot = 0;
    for (int r = 0; r < 9; ++r)
      if (el.local[r] >= 0) dot += lin.grad[e].row(r).dot(p.segment<3>(3 * el.local[r]));
    dot *= el.weight;
    for (int r = 0; r < 9; ++r)
      if (el.local[r] >= 0) out.segment<3>(3 * el.local[r]) += dot * lin.grad[e].row(r).transpose();
  }
}

// Internal plus external force on the free nodes.
void net_force(const System &sys, const ForceField &forces, const Eigen::MatrixXd &ref,
               const Eigen::MatrixXd &X, Vec &r) {
  const SkinModel &m = sys.m;
  r.setZero(sys.dofs());
  for (int si : sys.springs) {
    const Spring &s = m.springs[static_cast<size_t>(si)];
    const Eigen::Vector3d d = X.row(s.b) - X.row(s.a);
    const double l = std::max(d.norm(), 1e-12 * s.rest);
    double t, dt;
    tension(s, m.stiffness(s), l, &t, &dt);
    const Eigen::Vector3d f = t * d / l;  // pulls a toward b when stretched
    const int la = sys.local[static_cast<size_t>(s.a)], lb = sys.local[static_cast<size_t>(s.b)];
    if (la >= 0) r.segment<3>(3 * la) += f;
    if (lb >= 0) r.segment<3>(3 * lb) -= f;
  }
  Eigen::Matrix<double, 9, 3> g;
  for (const Element &el : sys.elements) {
    if (el.weight > 0) {
      const double v = element_volume(m, X, el.f, &g);
      const double c = -el.weight * (v - m.rest_volume[el.f]);
      for (int k = 0; k < 9; ++k)
        if (el.local[k] >= 0) r.segment<3>(3 * el.local[k]) += c * g.row(k).transpose();
    }
    if (el.shape > 0) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int k = 0; k < 12; ++k) mean += (X.row(el.global[k]) - ref.row(el.global[k])).transpose();
      mean /= 12.0;
      for (int k = 0; k < 9; ++k)
        if (el.local[k] >= 0)
          r.segment<3>(3 * el.local[k]) -= el.shape * ((X.row(el.global[k]) - ref.row(el.global[k])).transpose() - mean);
    }
  }
  if (forces) {
    Eigen::MatrixXd F = Eigen::MatrixXd::Zero(X.rows(), 3);
    forces(X, &F);
    for (size_t i = 0; i < sys.nodes.size(); ++i) r.segment<3>(3 * static_cast<int>(i)) += F.row(sys.nodes[i]).transpose();
  }
}

// Total potential energy of the system: springs, volume, external load.
double total_energy(const System &sys, const ForceField &forces, const Eigen::MatrixXd &ref,
                    const Eigen::MatrixXd &X) {
  const SkinModel &m = sys.m;
  double e = 0;
  for (int si : sys.springs) {
    const Spring &s = m.springs[static_cast<size_t>(si)];
    e += spring_energy(s, m.stiffness(s), (X.row(s.b) - X.row(s.a)).norm());
  }
  for (const Element &el : sys.elements) {
    if (el.weight > 0) {
      const double dv = element_volume(m, X, el.f) - m.rest_volume[el.f];
      e += 0.5 * el.weight * dv * dv;
    }
    if (el.shape > 0) {
      Eigen::Matrix<double, 12, 3> d;
      for (int k = 0; k < 12; ++k) d.row(k) = X.row(el.global[k]) - ref.row(el.global[k]);
      e += 0.5 * el.shape * (d.rowwise() - d.colwise().mean()).squaredNorm();
    }
  }
  if (forces) e += forces(X, nullptr);
  return e;
}

// Skull contacts: per local node, the constraint normal (zero: free).
struct Contacts {
  Eigen::MatrixXd normal;  // nodes x 3
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
};

// Puts penetrating nodes back on their skull plane and activates them.
// Returns the largest correction.
double update_contacts(const System &sys, Eigen::MatrixXd &X, Contacts &c) {
  const SkinModel &m = sys.m;
  if (c.normal.rows() != static_cast<Eigen::Index>(sys.nodes.size()))
    c.normal = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(sys.nodes.size()), 3);
  double moved = 0;
  c.active = 0;
  for (size_t i = 0; i < sys.nodes.size(); ++i) {
    if (!sys.rejects[i]) continue;
    const int g = sys.nodes[i];
    const int v = m.vertex_of(g);
    const Eigen::Vector3d nn = m.normal.row(v);
    const Eigen::Vector3d skull = X.row(m.node(kSkull, v));
    const double gap = (X.row(g).transpose() - skull).dot(nn);
    // An active node stays active for the rest of the solve: releasing
    // nodes the residual pulls off the bone makes the active set chatter.
    const bool on = c.normal.row(static_cast<Eigen::Index>(i)).squaredNorm() > 0 || gap < 0;
    if (gap < 0) {
      X.row(g) -= gap * nn.transpose();
      moved = std::max(moved, -gap);
    }
    c.normal.row(static_cast<Eigen::Index>(i)) = on ? Eigen::RowVector3d(nn.transpose()) : Eigen::RowVector3d::Zero();
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
template <class Apply, class Precondition>
int filtered_pcg(const Apply &apply, const Precondition &precondition, const Contacts &c, const Vec &b,
                 Vec &x, int max_iter, double relative) {
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
    if (!(pq > 0)) break;
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

bool finite(const Vec &v) { return v.allFinite(); }

FactorCache::Entry *rest_factor(const System &sys, const std::vector<int> &vertices, FactorCache *cache,
                                std::unique_ptr<FactorCache::Entry> &own) {
  if (cache)
    if (FactorCache::Entry *e = cache->find(vertices)) return e;
  auto e = std::make_unique<FactorCache::Entry>();
  Linearisation rest;
  linearise(sys, sys.m.X0, rest);
  // The volume term's rank-one blocks are left out: springs alone are SPD
  // and close enough for a preconditioner.
  e->ldlt.compute(rest.K);
  e->ok = e->ldlt.info() == Eigen::Success;
  if (cache) return cache->insert(vertices, std::move(e));
  own = std::move(e);
  return own.get();
}

}  // namespace

Eigen::MatrixXd residual_forces(const SkinModel &model, const std::vector<int> &vertices,
                                const ForceField &forces, const Eigen::MatrixXd &reference,
                                const Eigen::MatrixXd &X) {
  System sys(model, vertices);
  Vec r;
  net_force(sys, forces, reference, X, r);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(X.rows(), 3);
  for (size_t i = 0; i < sys.nodes.size(); ++i) out.row(sys.nodes[i]) = r.segment<3>(3 * static_cast<int>(i)).transpose();
  return out;
}

SolveStats solve_equilibrium(const SkinModel &model, const std::vector<int> &vertices,
                             const ForceField &forces, const Eigen::MatrixXd &reference, Eigen::MatrixXd &X,
                             const SolverOptions &options, FactorCache *cache) {
  const auto start = std::chrono::steady_clock::now();
  SolveStats st;
  auto done = [&](bool ok, std::string message) {
    st.converged = ok;
    st.message = std::move(message);
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return st;
  };
  if (!(options.tolerance > 0)) return done(false, "solver: tolerance must be positive");
  System sys(model, vertices);
  const int n = sys.dofs();
  st.unknowns = n;
  if (n == 0) return done(true, "");

  auto gather = [&](const Eigen::MatrixXd &P, Vec &x) {
    x.resize(n);
    for (size_t i = 0; i < sys.nodes.size(); ++i) x.segment<3>(3 * static_cast<int>(i)) = P.row(sys.nodes[i]).transpose();
  };
  auto scatter = [&](const Vec &x, Eigen::MatrixXd &P) {
    for (size_t i = 0; i < sys.nodes.size(); ++i) P.row(sys.nodes[i]) = x.segment<3>(3 * static_cast<int>(i)).transpose();
  };

  Contacts contacts;
  update_contacts(sys, X, contacts);
  Linearisation lin;
  Vec r, dx, x0, trial;
  const double tol = options.tolerance;

  std::unique_ptr<FactorCache::Entry> own;
  FactorCache::Entry *factor = nullptr;
  if (options.kind == SolverKind::Newton) {
    factor = rest_factor(sys, vertices, cache, own);
    if (!factor->ok) return done(false, "solver: the rest-state Hessian of the dynamic set is singular");
  }
  auto jacobi = [&](const Vec &diag) {
    return [&diag](const Vec &in, Vec &out) { out = in.cwiseQuotient(diag.cwiseMax(1e-300)); };
  };

  if (options.kind == SolverKind::ImplicitEuler) {
    const int max_steps = options.max_iterations > 0 ? options.max_iterations : 2000;
    Vec mass(n);
    for (size_t i = 0; i < sys.nodes.size(); ++i) mass.segment<3>(3 * static_cast<int>(i)).setConstant(model.mass[sys.nodes[i]]);
    linearise(sys, X, lin);
    const double t0 = std::sqrt(mass.mean() / std::max(lin.diag.mean(), 1e-300));
    const double h = options.time_step * t0, gamma = options.damping / t0;
    Vec v = Vec::Zero(n), dv, Kv(n), b(n);
    for (int step = 0; step < max_steps; ++step) {
      net_force(sys, forces, reference, X, r);
      if (step > 0) linearise(sys, X, lin);
      st.residual = displacement_estimate([&] { Vec f = r; contacts.filter(f); return f; }(), lin.diag);
      if (!finite(r)) return done(false, "implicit-euler: non-finite force at step " + std::to_string(step));
      if (step > 0 && st.residual < tol && st.last_step < tol) {
        st.contacts = contacts.active;
        return done(true, "");
      }
      hessian_times(sys, lin, v, Kv);
      b = h * (r - gamma * mass.cwiseProduct(v) - h * Kv);
      const Vec adiag = (1 + h * gamma) * mass + h * h * lin.diag;
      auto apply = [&](const Vec &p, Vec &out) {
        hessian_times(sys, lin, p, out);
        out = (1 + h * gamma) * mass.cwiseProduct(p) + h * h * out;
      };
      st.cg_iterations += filtered_pcg(apply, jacobi(adiag), contacts, b, dv, options.max_cg, options.cg_relative);
      if (!finite(dv)) return done(false, "implicit-euler: non-finite velocity at step " + std::to_string(step));
      v += dv;
      contacts.filter(v);
      gather(X, x0);
      x0 += h * v;
      scatter(x0, X);
      st.last_step = h * max_node_motion(v);
      update_contacts(sys, X, contacts);
      st.iterations = step + 1;
    }
    st.contacts = contacts.active;
    return done(false, "implicit-euler: no equilibrium after " + std::to_string(max_steps) +
                           " steps (remaining displacement " + std::to_string(st.residual) + ")");
  }

  // Newton (factorised or Jacobi preconditioner).
  std::unique_ptr<FactorCache::Entry> fresh;
  const int max_it = options.max_iterations > 0 ? options.max_iterations : 200;
  for (int it = 0;; ++it) {
    net_force(sys, forces, reference, X, r);
    if (!finite(r)) return done(false, solver_name(options.kind) + std::string(": non-finite force"));
    linearise(sys, X, lin);
    Vec rf = r;
    contacts.filter(rf);
    st.residual = displacement_estimate(rf, lin.diag);
    if (it > 0 && st.residual < tol && st.last_step < tol) break;
    if (it >= max_it) {
      st.contacts = contacts.active;
      return done(false, std::string(solver_name(options.kind)) + ": no equilibrium after " +
                             std::to_string(max_it) + " iterations (remaining displacement " +
                             std::to_string(st.residual) + ")");
    }
    auto apply = [&](const Vec &p, Vec &out) { hessian_times(sys, lin, p, out); };
    if (factor) {
      // The rest factorisation preconditions while it is close; when the
      // tangent has drifted (CG needed many iterations), factorise the
      // current one for the rest of this solve.
      const Eigen::SimplicialLDLT<SpMat, Eigen::Lower> &ldlt = fresh ? fresh->ldlt : factor->ldlt;
      const int cg = filtered_pcg(apply, [&](const Vec &in, Vec &out) { out = ldlt.solve(in); }, contacts, rf,
                                  dx, options.max_cg, options.cg_relative);
      st.cg_iterations += cg;
      if (cg > kRefactorAfter) {
        if (!fresh) fresh = std::make_unique<FactorCache::Entry>();
        fresh->ldlt.compute(lin.K);
        if (fresh->ldlt.info() != Eigen::Success) fresh.reset();
      }
    }
    else {
      st.cg_iterations += filtered_pcg(apply, jacobi(lin.diag), contacts, rf, dx, options.max_cg,
                                       options.cg_relative);
    }
    if (!finite(dx)) return done(false, std::string(solver_name(options.kind)) + ": non-finite step");
    // Backtracking (Armijo) on the total energy: the loads are conservative.
    gather(X, x0);
    const double e0 = total_energy(sys, forces, reference, X), slope = rf.dot(dx);
    double alpha = 1;
    Eigen::MatrixXd Xt = X;
    for (int ls = 0; ls < 12; ++ls, alpha *= 0.5) {
      trial = x0 + alpha * dx;
      scatter(trial, Xt);
      const double e = total_energy(sys, forces, reference, Xt);
      if (std::isfinite(e) && e <= e0 - 1e-4 * alpha * std::max(slope, 0.0)) break;
    }
    if (!finite(trial)) return done(false, std::string(solver_name(options.kind)) + ": non-finite step");
    scatter(trial, X);
    st.last_step = alpha * max_node_motion(dx);
    st.last_step = std::max(st.last_step, update_contacts(sys, X, contacts));
    st.iterations = it + 1;
  }
  st.contacts = contacts.active;
  return done(true, "");
}

}  // namespace afmb
