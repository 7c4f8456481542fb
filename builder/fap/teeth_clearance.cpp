#include "fap/teeth_clearance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "anatomy/jaw.h"
#include "core/edge_paths.h"
#include "core/normals.h"
#include "core/part_kind.h"

namespace afmb {
namespace {

constexpr double kNone = -std::numeric_limits<double>::infinity();

// The 1D parabolic dilation of n values a stride apart, in place: out(i) =
// max over |i - k| <= reach of in(k) - drop[|i - k|], drop[m] = (m cell)^2 /
// (2 rho) (drop_table). The line is gathered first and the drops looked up:
// the division per pair took 1.4 % of Song's AFM's CPU, on one thread.
void dilate_line(double *z, int n, int stride, int reach, const std::vector<double> &drop, std::vector<double> &line,
                 std::vector<double> &tmp) {
  line.resize(static_cast<size_t>(n));
  tmp.assign(static_cast<size_t>(n), kNone);
  for (int i = 0; i < n; ++i) line[static_cast<size_t>(i)] = z[static_cast<ptrdiff_t>(i) * stride];
  for (int k = 0; k < n; ++k) {
    const double zk = line[static_cast<size_t>(k)];
    if (zk == kNone) continue;
    for (int i = std::max(0, k - reach); i <= std::min(n - 1, k + reach); ++i) {
      double &best = tmp[static_cast<size_t>(i)];
      best = std::max(best, zk - drop[static_cast<size_t>(std::abs(i - k))]);
    }
  }
  for (int i = 0; i < n; ++i) z[static_cast<ptrdiff_t>(i) * stride] = tmp[static_cast<size_t>(i)];
}

// drop[m] = (m cell)^2 / (2 rho), m = 0 .. reach.
std::vector<double> drop_table(double cell, double rho, int reach) {
  std::vector<double> drop(static_cast<size_t>(reach) + 1);
  for (int m = 0; m <= reach; ++m) {
    const double d = m * cell;
    drop[static_cast<size_t>(m)] = d * d / (2 * rho);
  }
  return drop;
}

}  // namespace

double DepthMap::at(double x, double y) const {
  const double u = (x - x0) / cell, w = (y - y0) / cell;
  if (!(u >= 0) || !(w >= 0) || u > nx - 1 || w > ny - 1) return kNone;
  const int i = std::min(static_cast<int>(u), std::max(nx - 2, 0)),
            j = std::min(static_cast<int>(w), std::max(ny - 2, 0));
  const int i1 = std::min(i + 1, nx - 1), j1 = std::min(j + 1, ny - 1);
  const double fu = u - i, fw = w - j;
  const double a = z[static_cast<size_t>(j * nx + i)], b = z[static_cast<size_t>(j * nx + i1)],
               c = z[static_cast<size_t>(j1 * nx + i)], d = z[static_cast<size_t>(j1 * nx + i1)];
  if (a == kNone || b == kNone || c == kNone || d == kNone) return std::max({a, b, c, d});
  return (1 - fw) * ((1 - fu) * a + fu * b) + fw * ((1 - fu) * c + fu * d);
}

DepthMap front_depth(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F, double cell, double margin) {
  DepthMap m;
  m.cell = cell;
  if (V.rows() == 0 || F.rows() == 0) return m;
  const Eigen::Vector2d lo = V.leftCols(2).colwise().minCoeff().transpose().array() - margin,
                        hi = V.leftCols(2).colwise().maxCoeff().transpose().array() + margin;
  m.x0 = lo.x(), m.y0 = lo.y();
  m.nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)) + 1;
  m.ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)) + 1;
  m.z.assign(static_cast<size_t>(m.nx) * static_cast<size_t>(m.ny), kNone);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    // Only the triangles facing forward: a flank seen from the front faces
    // the cheek, not the skin in front.
    if (!(area > kFacing * (b - a).cross(c - a).norm())) continue;
    const int i0 = std::max(0, static_cast<int>(std::ceil((std::min({a.x(), b.x(), c.x()}) - m.x0) / cell))),
              i1 = std::min(m.nx - 1, static_cast<int>(std::floor((std::max({a.x(), b.x(), c.x()}) - m.x0) / cell))),
              j0 = std::max(0, static_cast<int>(std::ceil((std::min({a.y(), b.y(), c.y()}) - m.y0) / cell))),
              j1 = std::min(m.ny - 1, static_cast<int>(std::floor((std::max({a.y(), b.y(), c.y()}) - m.y0) / cell)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const double x = m.x0 + i * cell, y = m.y0 + j * cell;
        const double wa = ((b.x() - x) * (c.y() - y) - (c.x() - x) * (b.y() - y)) / area,
                     wb = ((c.x() - x) * (a.y() - y) - (a.x() - x) * (c.y() - y)) / area, wc = 1 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        double &z = m.z[static_cast<size_t>(j * m.nx + i)];
        z = std::max(z, wa * a.z() + wb * b.z() + wc * c.z());
      }
  }
  return m;
}

void drape(DepthMap &map, double rho) {
  if (!(rho > 0) || map.nx == 0) return;
  const int reach = static_cast<int>(std::ceil(2 * rho / map.cell));
  const std::vector<double> drop = drop_table(map.cell, rho, reach);
  std::vector<double> line, tmp;
  for (int j = 0; j < map.ny; ++j)
    dilate_line(map.z.data() + static_cast<ptrdiff_t>(j) * map.nx, map.nx, 1, reach, drop, line, tmp);
  for (int i = 0; i < map.nx; ++i) dilate_line(map.z.data() + i, map.ny, map.nx, reach, drop, line, tmp);
}

TeethClearance teeth_clearance(const Scene &scene, const FaceModel &model, const SimMesh *sim) {
  TeethClearance c;
  Eigen::Index nv = 0, nf = 0;
  const std::vector<int> parts = scene.find_kinds({PartKind::TeethLower});
  for (int p : parts) nv += scene.parts[static_cast<size_t>(p)].V.rows(), nf += scene.parts[static_cast<size_t>(p)].F.rows();
  if (nf == 0 || !(model.fapu.mw0 > 0) || !(model.fapu.mns0 > 0)) return c;
  Eigen::MatrixXd TV(nv, 3);
  Eigen::MatrixXi TF(nf, 3);
  nv = nf = 0;
  for (int p : parts) {
    const Part &part = scene.parts[static_cast<size_t>(p)];
    TV.middleRows(nv, part.V.rows()) = part.V;
    TF.middleRows(nf, part.F.rows()) = part.F.array() + static_cast<int>(nv);
    nv += part.V.rows(), nf += part.F.rows();
  }
  c.cap = kTeethClearance * model.fapu.mns0;
  c.rho = kTeethDrape * model.fapu.mns0;
  c.rest = front_depth(TV, TF, kTeethCell * model.fapu.mw0, 2 * c.rho);
  drape(c.rest, c.rho);
  c.teeth_V = std::move(TV);
  c.teeth_F = std::move(TF);
  const bool lifted = sim && sim->decimated;
  c.sim = lifted ? sim : nullptr;
  const SkinModel &skin = model.tissue;
  c.skin = &skin;
  c.skin_V = lifted ? sim->skin_V : Eigen::MatrixXd(skin.X0.topRows(skin.n));
  const Eigen::MatrixXi &F = lifted ? sim->skin_F : skin.F;
  // The jaw's share per fine vertex.
  const std::vector<double> coarse = jaw_shares(model.jaw, skin.n);
  Eigen::VectorXd share(c.skin_V.rows());
  for (Eigen::Index v = 0; v < share.size(); ++v) {
    if (!lifted) {
      share(v) = coarse[static_cast<size_t>(v)];
      continue;
    }
    share(v) = 0;
    for (int i = 0; i < 3; ++i) share(v) += sim->binding.weight(v, i) * coarse[static_cast<size_t>(sim->binding.corner(v, i))];
  }
  const Eigen::MatrixXd N = vertex_normals(c.skin_V, F);
  std::vector<double> clearance;
  for (Eigen::Index v = 0; v < c.skin_V.rows(); ++v) {
    if (!(N(v, 2) > kFacing) || share(v) < 0.5) continue;
    const double e = c.rest.at(c.skin_V(v, 0), c.skin_V(v, 1));
    // Behind the teeth (inside the mouth) or off their reach: free.
    const double gap = c.skin_V(v, 2) - e;
    if (e == kNone || gap < 0) continue;
    c.vertices.push_back(static_cast<int>(v));
    clearance.push_back(std::min(gap, c.cap));
  }
  c.clearance = Eigen::Map<Eigen::VectorXd>(clearance.data(), static_cast<Eigen::Index>(clearance.size()));
  return c;
}

TeethPush keep_before_teeth(const TeethClearance &c, const Eigen::Affine3d &jaw, Eigen::MatrixXd &D) {
  TeethPush out;
  out.push = Eigen::VectorXd::Zero(D.rows());
  if (c.vertices.empty()) return out;
  DepthMap front = front_depth(moved_points(jaw, c.teeth_V), c.teeth_F, c.rest.cell, 2 * c.rho);
  drape(front, c.rho);
  const Eigen::MatrixXd P = c.skin_V + (c.sim ? lift_displacement(*c.sim, D) : D);
  // Per kept vertex in the front's reach: its depth and the depth it must
  // reach.
  struct Need {
    int v;
    double z, goal;
  };
  std::vector<Need> need;
  for (size_t k = 0; k < c.vertices.size(); ++k) {
    const int v = c.vertices[k];
    const double e = front.at(P(v, 0), P(v, 1));
    if (e == kNone) continue;
    const double goal = e + c.clearance(static_cast<Eigen::Index>(k));
    if (goal > P(v, 2)) {
      ++out.pushed;
      out.deepest = std::max(out.deepest, goal - P(v, 2));
    }
    need.push_back({v, P(v, 2), goal});
  }
  if (out.pushed == 0) return out;
  if (!c.sim) {
    for (const Need &n : need) out.push(n.v) = std::max(0.0, n.goal - n.z);
  } else {
    // Cyclic projection onto each unmet z_v + sum_i w_i push(c_i) >= goal.
    const SkinBinding &b = c.sim->binding;
    auto lifted = [&](const Need &n) {
      double z = n.z;
      for (int i = 0; i < 3; ++i) z += b.weight(n.v, i) * out.push(b.corner(n.v, i));
      return z;
    };
    const double tolerance = 1e-3 * c.cap;
    for (int sweep = 0; sweep < 200; ++sweep) {
      double worst = 0;
      for (const Need &n : need) {
        const double r = n.goal - lifted(n);
        double w2 = 0;
        for (int i = 0; i < 3; ++i) w2 += b.weight(n.v, i) * b.weight(n.v, i);
        if (!(r > 0) || !(w2 > 0)) continue;
        worst = std::max(worst, r);
        for (int i = 0; i < 3; ++i) out.push(b.corner(n.v, i)) += b.weight(n.v, i) * r / w2;
      }
      if (worst <= tolerance) break;
    }
    for (const Need &n : need) out.left = std::max(out.left, n.goal - lifted(n));
    if (out.left <= tolerance) out.left = 0;
  }
  // Spread: each moved vertex takes its neighbours along, by
  // push(u) w(d / (kTeethSpread push(u))), w(t) = (1 - t^2)^2, d along the
  // mesh's edges; the largest of these per vertex. Alone, the pushed
  // vertices stood out, and untangling their folds let teeth out again
  // (teeth_clearance.h).
  const SkinModel &skin = *c.skin;
  const Eigen::VectorXd own = out.push;
  for (Eigen::Index u = 0; u < own.size(); ++u) {
    if (!(own(u) > 0)) continue;
    const double reach = kTeethSpread * own(u);
    const std::vector<double> d = edge_path_distances(skin.X0, skin.neighbours, {static_cast<int>(u)}, reach);
    for (Eigen::Index v = 0; v < own.size(); ++v) {
      const double t = d[static_cast<size_t>(v)] / reach;
      if (t < 1) out.push(v) = std::max(out.push(v), own(u) * (1 - t * t) * (1 - t * t));
    }
  }
  D.col(2) += out.push;
  return out;
}

}  // namespace afmb
