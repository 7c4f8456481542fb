#include "afm/afm_export.h"

#include <afm/draco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <array>

#include "core/atomic_file.h"
#include "core/normals.h"

namespace afmb {

namespace {

int16_t clamp16(long v) { return static_cast<int16_t>(std::clamp(v, -32767L, 32767L)); }
int16_t q14(double v) { return clamp16(std::lround(v * 16384.0)); }
uint8_t byte01(double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }

// #V x 3 area-weighted vertex normals of one part (zero rows become +z).
Eigen::MatrixXd part_normals(const Eigen::MatrixXd &V, const Eigen::MatrixXi &F) {
  Eigen::MatrixXd N = vertex_normals(V, F);
  for (Eigen::Index i = 0; i < N.rows(); ++i)
    if (N.row(i).isZero(0)) N.row(i) = Eigen::RowVector3d(0, 0, 1);
  return N;
}

struct Grid {
  float origin[3] = {0, 0, 0};
  float step = 1;
  int16_t q(double x, int axis) const {
    return clamp16(std::lround((x - static_cast<double>(origin[axis])) / static_cast<double>(step)));
  }
};

Grid position_grid(const Scene &scene) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Part &p : scene.parts)
    for (Eigen::Index i = 0; i < p.V.rows(); ++i) {
      lo = lo.cwiseMin(p.V.row(i).transpose());
      hi = hi.cwiseMax(p.V.row(i).transpose());
    }
  Grid g;
  if (!(lo.array() <= hi.array()).all()) return g;
  double half = 0;
  for (int k = 0; k < 3; ++k) {
    g.origin[k] = static_cast<float>(0.5 * (lo[k] + hi[k]));
    half = std::max({half, std::abs(hi[k] - g.origin[k]), std::abs(lo[k] - g.origin[k])});
  }
  // A hair above half/32767 so rounding never leaves the int16 range.
  g.step = half > 0 ? static_cast<float>(half / 32766.5) : 1.0f;
  return g;
}

// The order of n points that keeps each field's moved points in few runs:
// sorted by which fields move them (fields taken largest first), ties in
// index order. `fields` are #n x 3 displacements (others are ignored).
std::vector<int> membership_order(size_t n, const std::vector<const Eigen::MatrixXd *> &fields, double quantum) {
  std::vector<std::vector<char>> columns;
  std::vector<size_t> sizes;
  for (const Eigen::MatrixXd *D : fields) {
    if (!D || D->rows() != static_cast<Eigen::Index>(n)) continue;
    std::vector<char> moved(n, 0);
    size_t count = 0;
    for (size_t v = 0; v < n; ++v)
      if (D->row(static_cast<Eigen::Index>(v)).cwiseAbs().maxCoeff() >= quantum / 2) moved[v] = 1, ++count;
    if (count) columns.push_back(std::move(moved)), sizes.push_back(count);
  }
  std::vector<size_t> by_size(columns.size());
  std::iota(by_size.begin(), by_size.end(), size_t{0});
  std::stable_sort(by_size.begin(), by_size.end(), [&](size_t a, size_t b) { return sizes[a] > sizes[b]; });
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    for (size_t c : by_size) {
      char x = columns[c][static_cast<size_t>(a)], y = columns[c][static_cast<size_t>(b)];
      if (x != y) return x > y;  // moved points first, grouped by signature
    }
    return false;
  });
  return order;
}

// The lift's shape against the scene and the targets.
Status check_lift(const AfmContent &content) {
  const Scene &scene = *content.scene;
  const ControlLift &lift = content.lift;
  if (lift.control_count < 0 || (lift.control_count == 0 && !lift.parts.empty()))
    return Status::error("encode_afm: a lift without control points");
  if (lift.control_count == 0) {
    for (const MorphTarget &t : content.targets)
      if (t.controls.rows() > 0)
        return Status::error("encode_afm: target " + std::to_string(t.number) + " moves controls, and there is no lift");
    return Status::ok();
  }
  std::vector<char> seen(scene.parts.size(), 0);
  for (const SkinBinding &b : lift.parts) {
    if (b.part < 0 || static_cast<size_t>(b.part) >= scene.parts.size() || seen[static_cast<size_t>(b.part)])
      return Status::error("encode_afm: lift part " + std::to_string(b.part) + " unknown or listed twice");
    seen[static_cast<size_t>(b.part)] = 1;
    const std::string name = scene.parts[static_cast<size_t>(b.part)].name;
    if (b.corner.rows() != scene.parts[static_cast<size_t>(b.part)].V.rows() || b.corner.cols() != 3 ||
        b.weight.rows() != b.corner.rows() || b.weight.cols() != 3)
      return Status::error("encode_afm: the lift of part '" + name + "' is not #V x 3");
    if (b.corner.size() > 0 && (b.corner.minCoeff() < 0 || b.corner.maxCoeff() >= lift.control_count))
      return Status::error("encode_afm: the lift of part '" + name + "' names a control out of range");
    if (b.weight.size() > 0 && !(b.weight.minCoeff() >= 0 && b.weight.maxCoeff() <= 1))
      return Status::error("encode_afm: the lift of part '" + name + "' has a weight outside [0, 1]");
  }
  for (const MorphTarget &t : content.targets) {
    if (t.normals)
      return Status::error("encode_afm: a lifted AFM has no normal deltas (target " + std::to_string(t.number) + ")");
    if (t.controls.rows() != 0 && (t.controls.rows() != lift.control_count || t.controls.cols() != 3))
      return Status::error("encode_afm: target " + std::to_string(t.number) + ": controls are not #C x 3");
  }
  return Status::ok();
}

}  // namespace

double afm_position_quantum(const Scene &scene) { return static_cast<double>(position_grid(scene).step); }

std::vector<std::vector<int>> run_friendly_order(const Scene &scene,
                                                 const std::vector<MorphTarget> &targets,
                                                 double quantum) {
  std::vector<std::vector<int>> order(scene.parts.size());
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    std::vector<const Eigen::MatrixXd *> fields;
    for (const MorphTarget &t : targets)
      if (p < t.displacement.size()) fields.push_back(&t.displacement[p]);
    order[p] = membership_order(static_cast<size_t>(scene.parts[p].V.rows()), fields, quantum);
  }
  return order;
}

RenderVertices split_render_vertices(const Scene &scene, const std::vector<std::vector<int>> *order) {
  RenderVertices rv;
  rv.first.resize(scene.parts.size());
  rv.copies.resize(scene.parts.size());
  size_t next = 0;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const Part &part = scene.parts[p];
    rv.first[p] = static_cast<int>(next);
    auto &copies = rv.copies[p];
    copies.assign(static_cast<size_t>(part.V.rows()), {});
    const bool split = part.TC.rows() > 0 && part.FTC.rows() == part.F.rows();
    auto welded = [&](size_t i) {
      return order ? static_cast<size_t>((*order)[p][i]) : i;
    };
    if (!split) {
      for (size_t i = 0; i < copies.size(); ++i) copies[welded(i)].push_back(static_cast<uint32_t>(next++));
      continue;
    }
    // Distinct texcoords per welded vertex, in order of first use; copies of
    // one vertex stay adjacent so the order stays spatially coherent.
    std::vector<std::vector<int>> tcs(copies.size());
    for (Eigen::Index f = 0; f < part.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        auto &list = tcs[static_cast<size_t>(part.F(f, k))];
        if (std::find(list.begin(), list.end(), part.FTC(f, k)) == list.end())
          list.push_back(part.FTC(f, k));
      }
    for (size_t i = 0; i < copies.size(); ++i) {
      const size_t v = welded(i);
      size_t n = std::max<size_t>(1, tcs[v].size());
      for (size_t c = 0; c < n; ++c) copies[v].push_back(static_cast<uint32_t>(next++));
    }
  }
  rv.count = next;
  return rv;
}

RenderVertices afm_render_vertices(const AfmContent &content) {
  const Scene &scene = *content.scene;
  if (content.targets.empty()) return split_render_vertices(scene);
  std::vector<std::vector<int>> order = run_friendly_order(scene, content.targets, position_grid(scene).step);
  // Bound parts keep their file order: their targets live on the controls,
  // and a spatial order lets Draco predict the bindings.
  for (const SkinBinding &b : content.lift.parts)
    if (b.part >= 0 && static_cast<size_t>(b.part) < order.size())
      std::iota(order[static_cast<size_t>(b.part)].begin(), order[static_cast<size_t>(b.part)].end(), 0);
  return split_render_vertices(scene, &order);
}

Expected<std::vector<uint8_t>> encode_afm(const AfmContent &content, afm_profile profile) {
  if (!content.scene || !content.fdps) return Status::error("encode_afm: no scene or FDPs");
  const Scene &scene = *content.scene;
  if (scene.parts.empty()) return Status::error(scene.source + ": the scene has no parts");
  if (scene.parts.size() > 65535) return Status::error(scene.source + ": more than 65535 parts");
  const Grid grid = position_grid(scene);
  const ControlLift &lift = content.lift;
  if (Status st = check_lift(content); !st) return st;
  std::vector<char> bound(scene.parts.size(), 0);  // parts the controls move
  for (const SkinBinding &b : lift.parts) bound[static_cast<size_t>(b.part)] = 1;
  const RenderVertices rv = afm_render_vertices(content);
  if (rv.count > 0xFFFFFFF0u) return Status::error(scene.source + ": too many vertices for AFM");
  const size_t R = rv.count;

  bool any_tc = false, any_color = false;
  double umin[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double umax[2] = {-umin[0], -umin[1]};
  for (const Part &p : scene.parts) {
    any_color |= p.C.rows() == p.V.rows() && p.C.rows() > 0;
    if (p.TC.rows() > 0 && p.FTC.rows() == p.F.rows()) {
      any_tc = true;
      for (int k = 0; k < 2; ++k) {
        umin[k] = std::min(umin[k], p.TC.col(k).minCoeff());
        umax[k] = std::max(umax[k], p.TC.col(k).maxCoeff());
      }
    }
  }
  float uv_origin[2] = {0, 0}, uv_step[2] = {1, 1};
  if (any_tc)
    for (int k = 0; k < 2; ++k) {
      uv_origin[k] = static_cast<float>(umin[k]);
      uv_step[k] = umax[k] > umin[k] ? static_cast<float>((umax[k] - umin[k]) / 65535.0) : 1.0f;
    }

  std::vector<int16_t> px(R), py(R), pz(R), nx(R), ny(R), nz(R);
  std::vector<uint16_t> u(any_tc ? R : 0), v(any_tc ? R : 0);
  std::vector<uint8_t> rgba(any_color ? 4 * R : 0);
  std::vector<uint32_t> tris;
  std::vector<afm_part> parts(scene.parts.size());
  std::vector<Eigen::MatrixXd> normals(scene.parts.size());
  size_t tri_first = 0;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const Part &part = scene.parts[p];
    normals[p] = part_normals(part.V, part.F);
    const bool split = part.TC.rows() > 0 && part.FTC.rows() == part.F.rows();
    // Texcoord of each copy: copies were made in order of first corner use.
    std::vector<std::map<int, uint32_t>> copy_of_tc(static_cast<size_t>(part.V.rows()));
    if (split)
      for (Eigen::Index f = 0; f < part.F.rows(); ++f)
        for (int k = 0; k < 3; ++k) {
          size_t w = static_cast<size_t>(part.F(f, k));
          auto &m = copy_of_tc[w];
          if (!m.count(part.FTC(f, k))) {
            uint32_t r = rv.copies[p][w][m.size()];
            m[part.FTC(f, k)] = r;
            if (any_tc) {
              for (int c = 0; c < 2; ++c) {
                double t = part.TC(part.FTC(f, k), c);
                long qv = std::lround((t - uv_origin[c]) / static_cast<double>(uv_step[c]));
                (c == 0 ? u : v)[r] = static_cast<uint16_t>(std::clamp(qv, 0L, 65535L));
              }
            }
          }
        }
    for (Eigen::Index w = 0; w < part.V.rows(); ++w)
      for (uint32_t r : rv.copies[p][static_cast<size_t>(w)]) {
        px[r] = grid.q(part.V(w, 0), 0);
        py[r] = grid.q(part.V(w, 1), 1);
        pz[r] = grid.q(part.V(w, 2), 2);
        nx[r] = q14(normals[p](w, 0));
        ny[r] = q14(normals[p](w, 1));
        nz[r] = q14(normals[p](w, 2));
        if (any_color) {
          const bool has_c = part.C.rows() == part.V.rows() && part.C.rows() > 0;
          for (int c = 0; c < 3; ++c) rgba[4 * r + c] = byte01(has_c ? part.C(w, c) : part.diffuse[c]);
          rgba[4 * r + 3] = 255;
        }
      }
    for (Eigen::Index f = 0; f < part.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        size_t w = static_cast<size_t>(part.F(f, k));
        tris.push_back(split ? copy_of_tc[w].at(part.FTC(f, k)) : rv.copies[p][w][0]);
      }
    afm_part &a = parts[p];
    a.name = part.name.c_str();
    a.texture = part.texture.c_str();
    a.kind = static_cast<uint8_t>(part.kind);
    for (int c = 0; c < 3; ++c) a.diffuse[c] = byte01(part.diffuse[c]);
    a.diffuse[3] = 255;
    a.first_vertex = static_cast<uint32_t>(rv.first[p]);
    a.vertex_count = static_cast<uint32_t>((p + 1 < scene.parts.size() ? rv.first[p + 1] : R) - rv.first[p]);
    a.first_triangle = static_cast<uint32_t>(tri_first);
    a.triangle_count = static_cast<uint32_t>(part.F.rows());
    tri_first += static_cast<size_t>(part.F.rows());
  }

  // FDPs sit on the first copy of their welded vertex.
  std::vector<afm_fdp_point> fdps;
  for (const FdpPoint &f : content.fdps->points) {
    afm_fdp_point a{};
    a.group = static_cast<uint8_t>(f.id.group);
    a.index = static_cast<uint8_t>(f.id.index);
    a.vertex = AFM_NONE;
    if (f.part >= 0 && f.vertex >= 0 && static_cast<size_t>(f.part) < rv.copies.size() &&
        static_cast<size_t>(f.vertex) < rv.copies[static_cast<size_t>(f.part)].size())
      a.vertex = rv.copies[static_cast<size_t>(f.part)][static_cast<size_t>(f.vertex)][0];
    for (int k = 0; k < 3; ++k) a.pos[k] = static_cast<float>(f.pos[k]);
    fdps.push_back(a);
  }

  // Control points: numbered so each target's controls form few runs
  // (control_slot: model control -> file control; Draco's MTGT stream is 30 %
  // smaller on Song than with the simulation mesh's order), and the bound
  // render vertices with their Q15 weights.
  std::vector<int> control_slot(static_cast<size_t>(lift.control_count));
  std::vector<afm_run> lift_runs;
  std::vector<uint32_t> lift_c[3];
  std::vector<uint16_t> lift_w[2];
  afm_lift doc_lift{};
  if (lift.control_count > 0) {
    std::vector<const Eigen::MatrixXd *> fields;
    for (const MorphTarget &t : content.targets) fields.push_back(&t.controls);
    const std::vector<int> by_slot = membership_order(static_cast<size_t>(lift.control_count), fields, grid.step);
    for (size_t i = 0; i < by_slot.size(); ++i) control_slot[static_cast<size_t>(by_slot[i])] = static_cast<int>(i);
    std::vector<std::pair<uint32_t, std::array<uint32_t, 5>>> rows;  // render vertex: c0 c1 c2 w1 w2
    for (const SkinBinding &b : lift.parts)
      for (Eigen::Index w = 0; w < b.corner.rows(); ++w) {
        const long w1 = std::lround(b.weight(w, 1) * 32768.0), w2 = std::lround(b.weight(w, 2) * 32768.0);
        std::array<uint32_t, 5> row{};
        for (int k = 0; k < 3; ++k)
          row[static_cast<size_t>(k)] = static_cast<uint32_t>(control_slot[static_cast<size_t>(b.corner(w, k))]);
        row[3] = static_cast<uint32_t>(w1);
        row[4] = static_cast<uint32_t>(std::min(w2, 32768L - w1));  // the rounded pair stays within one
        for (uint32_t r : rv.copies[static_cast<size_t>(b.part)][static_cast<size_t>(w)]) rows.push_back({r, row});
      }
    std::sort(rows.begin(), rows.end(), [](const auto &x, const auto &y) { return x.first < y.first; });
    for (const auto &[r, row] : rows) {
      if (!lift_runs.empty() && lift_runs.back().start + lift_runs.back().length == r)
        lift_runs.back().length++;
      else
        lift_runs.push_back({r, 1});
      for (int k = 0; k < 3; ++k) lift_c[k].push_back(row[static_cast<size_t>(k)]);
      for (int k = 0; k < 2; ++k) lift_w[k].push_back(static_cast<uint16_t>(row[static_cast<size_t>(3 + k)]));
    }
    doc_lift.control_count = static_cast<uint32_t>(lift.control_count);
    doc_lift.run_count = static_cast<uint32_t>(lift_runs.size());
    doc_lift.runs = lift_runs.data();
    doc_lift.bound_count = static_cast<uint32_t>(rows.size());
    doc_lift.c0 = lift_c[0].data(), doc_lift.c1 = lift_c[1].data(), doc_lift.c2 = lift_c[2].data();
    doc_lift.w1 = lift_w[0].data(), doc_lift.w2 = lift_w[1].data();
  }

  // Morph targets: quantise, drop zero deltas, runs over render vertices
  // (a one-vertex gap is cheaper stored as zeros than as a new 8-byte run).
  struct TargetStore {
    std::vector<afm_run> runs;
    std::vector<int16_t> d[6];
  };
  std::vector<TargetStore> stores(content.targets.size());
  std::vector<afm_target> targets(content.targets.size());
  for (size_t t = 0; t < content.targets.size(); ++t) {
    const MorphTarget &mt = content.targets[t];
    TargetStore &s = stores[t];
    std::vector<Eigen::MatrixXd> moved_normals(scene.parts.size());
    for (size_t p = 0; p < scene.parts.size() && mt.normals; ++p)
      if (p < mt.displacement.size() && mt.displacement[p].rows() == scene.parts[p].V.rows())
        moved_normals[p] = part_normals(scene.parts[p].V + mt.displacement[p], scene.parts[p].F);
    // Quantised deltas by entry (render vertex, then control), then runs in
    // ascending order.
    std::vector<std::pair<uint32_t, std::array<int16_t, 6>>> moved;
    for (size_t p = 0; p < scene.parts.size(); ++p) {
      if (p >= mt.displacement.size() || mt.displacement[p].rows() == 0 || bound[p]) continue;
      const Eigen::MatrixXd &D = mt.displacement[p];
      if (D.rows() != scene.parts[p].V.rows() || D.cols() != 3)
        return Status::error("target " + std::to_string(mt.number) + ": displacement of part '" +
                             scene.parts[p].name + "' is not #V x 3");
      // lround of a NaN is unspecified: a broken target must not become
      // 16-bit garbage in the file.
      if (!D.allFinite())
        return Status::error("target " + std::to_string(mt.number) + ": displacement of part '" +
                             scene.parts[p].name + "' is not finite");
      for (Eigen::Index w = 0; w < D.rows(); ++w) {
        std::array<int16_t, 6> q{};
        for (int k = 0; k < 3; ++k)
          q[static_cast<size_t>(k)] = clamp16(std::lround(D(w, k) / static_cast<double>(grid.step)));
        if (mt.normals)
          for (int k = 0; k < 3; ++k)
            q[static_cast<size_t>(3 + k)] = q14(moved_normals[p](w, k) - normals[p](w, k));
        if (q == std::array<int16_t, 6>{}) continue;
        for (uint32_t r : rv.copies[p][static_cast<size_t>(w)]) moved.push_back({r, q});
      }
    }
    if (!mt.controls.allFinite())
      return Status::error("target " + std::to_string(mt.number) + ": a control's displacement is not finite");
    for (Eigen::Index c = 0; c < mt.controls.rows(); ++c) {
      std::array<int16_t, 6> q{};
      for (int k = 0; k < 3; ++k)
        q[static_cast<size_t>(k)] = clamp16(std::lround(mt.controls(c, k) / static_cast<double>(grid.step)));
      if (q != std::array<int16_t, 6>{})
        moved.push_back({static_cast<uint32_t>(R + static_cast<size_t>(control_slot[static_cast<size_t>(c)])), q});
    }
    std::sort(moved.begin(), moved.end(), [](const auto &x, const auto &y) { return x.first < y.first; });
    for (const auto &[r, q] : moved) {
      bool extend = !s.runs.empty() && s.runs.back().start + s.runs.back().length == r;
      // A one-vertex gap is cheaper stored as zeros than as a new 8-byte run.
      if (!extend && !s.runs.empty() && s.runs.back().start + s.runs.back().length + 1 == r) {
        s.runs.back().length++;
        for (auto &arr : s.d) arr.push_back(0);
        extend = true;
      }
      if (extend)
        s.runs.back().length++;
      else
        s.runs.push_back({r, 1});
      for (int k = 0; k < 6; ++k) s.d[k].push_back(q[static_cast<size_t>(k)]);
    }
    afm_target &a = targets[t];
    a.kind = static_cast<uint8_t>(mt.kind);
    a.number = static_cast<uint8_t>(mt.number);
    a.flags = mt.normals ? AFM_TARGET_NORMALS : 0;
    a.reference = mt.reference;
    a.gate = static_cast<uint8_t>(mt.gate);
    a.gate_reference = mt.gate_reference;
    a.run_count = static_cast<uint32_t>(s.runs.size());
    a.runs = s.runs.data();
    a.delta_count = static_cast<uint32_t>(s.d[0].size());
    a.dx = s.d[0].data(), a.dy = s.d[1].data(), a.dz = s.d[2].data();
    if (mt.normals) a.nx = s.d[3].data(), a.ny = s.d[4].data(), a.nz = s.d[5].data();
  }

  // Rigid parts.
  std::vector<std::vector<uint16_t>> rigid_parts(content.rigids.size());
  std::vector<std::vector<afm_control>> rigid_controls(content.rigids.size());
  std::vector<afm_rigid> rigids(content.rigids.size());
  for (size_t i = 0; i < content.rigids.size(); ++i) {
    const RigidPart &g = content.rigids[i];
    afm_rigid &a = rigids[i];
    a.kind = static_cast<uint8_t>(g.kind);
    for (int k = 0; k < 3; ++k)
      a.pivot[k] = static_cast<int32_t>(
          std::lround((g.pivot[k] - static_cast<double>(grid.origin[k])) / static_cast<double>(grid.step)));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) a.axes[3 * r + c] = q14(g.axes(r, c));
    for (int p : g.parts) rigid_parts[i].push_back(static_cast<uint16_t>(p));
    for (const RigidPart::Control &c : g.controls) {
      double gain = c.dof >= AFM_DOF_TRANSLATE_X ? c.gain / static_cast<double>(grid.step) : c.gain;
      rigid_controls[i].push_back(
          {static_cast<uint8_t>(c.fap), static_cast<uint8_t>(c.dof),
           static_cast<int32_t>(std::lround(std::clamp(gain * 65536.0, -2147483647.0, 2147483647.0))),
           static_cast<int16_t>(std::clamp(c.knot, -32767, 32767))});
    }
    a.part_count = static_cast<uint16_t>(rigid_parts[i].size());
    a.parts = rigid_parts[i].data();
    a.control_count = static_cast<uint16_t>(rigid_controls[i].size());
    a.controls = rigid_controls[i].data();
  }

  afm_doc doc{};
  doc.meta.name = scene.name.c_str();
  doc.meta.units = scene.units.c_str();
  doc.meta.generator = content.generator.c_str();
  doc.meta.es0 = static_cast<float>(content.fapu.es0);
  doc.meta.irisd0 = static_cast<float>(content.fapu.irisd0);
  doc.meta.ens0 = static_cast<float>(content.fapu.ens0);
  doc.meta.mns0 = static_cast<float>(content.fapu.mns0);
  doc.meta.mw0 = static_cast<float>(content.fapu.mw0);
  doc.meta.fdp_count = static_cast<uint32_t>(fdps.size());
  doc.meta.fdps = fdps.data();
  afm_geometry &g = doc.geometry;
  g.vertex_count = static_cast<uint32_t>(R);
  g.triangle_count = static_cast<uint32_t>(tris.size() / 3);
  g.part_count = static_cast<uint32_t>(parts.size());
  g.attributes = AFM_ATTR_NORMALS | (any_tc ? AFM_ATTR_TEXCOORDS : 0u) | (any_color ? AFM_ATTR_COLORS : 0u);
  for (int k = 0; k < 3; ++k) g.origin[k] = grid.origin[k];
  g.step = grid.step;
  for (int k = 0; k < 2; ++k) g.uv_origin[k] = uv_origin[k], g.uv_step[k] = uv_step[k];
  g.parts = parts.data();
  g.px = px.data(), g.py = py.data(), g.pz = pz.data();
  g.nx = nx.data(), g.ny = ny.data(), g.nz = nz.data();
  if (any_tc) g.u = u.data(), g.v = v.data();
  if (any_color) g.rgba = rgba.data();
  g.triangles = tris.data();
  doc.target_count = static_cast<uint32_t>(targets.size());
  doc.targets = targets.data();
  doc.rigid_count = static_cast<uint32_t>(rigids.size());
  doc.rigids = rigids.data();
  if (lift.control_count > 0) doc.lift = &doc_lift;

  afm_write_options wo{};
  afm_diag diag{};
  wo.profile = profile;
  wo.draco = afm_draco_codec();
  wo.diag = &diag;
  uint8_t *out = nullptr;
  size_t size = 0;
  afm_result r = afm_doc_write(&doc, &wo, &out, &size);
  if (r != AFM_OK)
    return Status::error(std::string("AFM encoding failed: ") +
                         (diag.message[0] ? diag.message : afm_result_string(r)));
  std::vector<uint8_t> bytes(out, out + size);
  afm_free(nullptr, out);
  return bytes;
}

Status write_afm(const std::string &path, const AfmContent &content, afm_profile profile) {
  Expected<std::vector<uint8_t>> bytes = encode_afm(content, profile);
  if (!bytes) return bytes.status().wrap(path);
  return write_file_atomic(path, bytes->data(), bytes->size());
}

}  // namespace afmb
