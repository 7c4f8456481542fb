#include "afm/analytic_targets.h"

#include "afm/rigid_parts.h"
#include "core/fapu.h"
#include "refhead/refhead.h"

#include <afm/mpeg4.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <queue>

namespace afmb {

namespace {

// Edge graph of one part: Dijkstra distances give bumps that follow the
// surface, so a bump on the upper lip does not jump the mouth slit.
struct EdgeGraph {
  std::vector<std::vector<std::pair<int, double>>> adj;  // #V lists of (neighbour, length)

  explicit EdgeGraph(const Part &p) : adj(static_cast<size_t>(p.V.rows())) {
    for (Eigen::Index f = 0; f < p.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        int a = p.F(f, k), b = p.F(f, (k + 1) % 3);
        double len = (p.V.row(a) - p.V.row(b)).norm();
        adj[static_cast<size_t>(a)].push_back({b, len});
        adj[static_cast<size_t>(b)].push_back({a, len});
      }
  }

  // #V geodesic (edge-path) distances from `source`, infinite beyond `limit`.
  std::vector<double> distances(int source, double limit) const {
    std::vector<double> d(adj.size(), std::numeric_limits<double>::infinity());
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
    d[static_cast<size_t>(source)] = 0;
    q.push({0.0, source});
    while (!q.empty()) {
      auto [dist, v] = q.top();
      q.pop();
      if (dist > d[static_cast<size_t>(v)] || dist > limit) continue;
      for (auto [w, len] : adj[static_cast<size_t>(v)]) {
        double nd = dist + len;
        if (nd < d[static_cast<size_t>(w)] && nd <= limit) {
          d[static_cast<size_t>(w)] = nd;
          q.push({nd, w});
        }
      }
    }
    return d;
  }
};

// Reference value and bump radius (in FAPU distances) per FAP.
struct Shape {
  int reference;
  double radius;  // model units
};

// Radii are comparable to the skin a muscle drags along: about 3 cm around
// the lips and cheeks, 3 cm around the brows, the lid around the eyes.
Shape shape_for(int fap, const Fapu &f) {
  if ((fap >= 4 && fap <= 13) || fap == 16 || fap == 17 || (fap >= 51 && fap <= 60))
    return {256, 0.6 * f.mw0};
  if (fap == 18) return {256, 0.6 * f.mw0};
  if (fap >= 19 && fap <= 22) return {1024, 1.2 * f.irisd0};
  if (fap >= 31 && fap <= 38) return {256, 0.5 * f.es0};
  if (fap >= 39 && fap <= 42) return {256, 0.6 * f.es0};
  if (fap >= 43 && fap <= 46) return {256, 0.5 * f.mw0};
  if (fap >= 61 && fap <= 64) return {128, 0.3 * f.es0};
  if (fap >= 65 && fap <= 68) return {256, 0.3 * f.es0};
  return {0, 0};
}

// Rotation about the x axis through `pivot` by `angle` radians, applied to p.
Eigen::Vector3d rotate_x(const Eigen::Vector3d &p, const Eigen::Vector3d &pivot, double angle) {
  return pivot + Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()) * (p - pivot);
}

}  // namespace

Expected<AnalyticModel> make_analytic_model(const Scene &scene, const FdpSet &fdps,
                                            const Fapu &fapu, const AnalyticOptions &options) {
  const int skin = scene.find_kind(PartKind::Skin);
  if (skin < 0) return Status::error(scene.source + ": no skin part for analytic targets");
  const Part &sk = scene.parts[static_cast<size_t>(skin)];
  const EdgeGraph graph(sk);
  auto fdp_on = [&](int g, int i, int part) { return fdps.find(FdpId{g, i}, part); };
  auto fdp_pos = [&](int g, int i) -> const FdpPoint * { return fdps.find(FdpId{g, i}); };

  AnalyticModel model;
  // Per-FAP displacement of the skin at its reference value (#V x 3).
  std::map<int, Eigen::MatrixXd> field;
  std::map<int, int> reference;

  // Bumps for every translation FAP with an FDP on the skin.
  for (int fap = 4; fap <= AFM_FAP_COUNT; ++fap) {
    const afm_fap_info *info = afm_fap(fap);
    if (fap == 14 || fap == 15 || info->motion != AFM_MOTION_TRANSLATE) continue;
    Shape sh = shape_for(fap, fapu);
    const FdpPoint *p = fdp_on(info->fdp_group, info->fdp_index, skin);
    if (!sh.reference || !p || p->part != skin || p->vertex < 0) continue;
    const double amplitude = sh.reference * fapu_distance(fapu, info->unit) / 1024.0;
    std::vector<double> d = graph.distances(p->vertex, sh.radius);
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(sk.V.rows(), 3);
    const Eigen::RowVector3d dir = fap_direction(info).transpose();
    const int eye = fap >= 19 && fap <= 22
                        ? scene.find_kind(fap % 2 ? PartKind::EyeLeft : PartKind::EyeRight)
                        : -1;
    if (eye >= 0) {
      // Eyelids slide over the eyeball: turn about its centre (x axis), by
      // the angle that moves the FDP vertically by exactly the amplitude.
      const Eigen::Vector3d centre = scene.parts[static_cast<size_t>(eye)].V.colwise().mean().transpose();
      const double sign = dir.y() < 0 ? 1.0 : -1.0;  // +x turns points in front downwards
      double lo = 0, hi = 1.5;
      for (int it = 0; it < 60; ++it) {
        double mid = 0.5 * (lo + hi);
        double moved = std::abs(rotate_x(p->pos, centre, sign * mid).y() - p->pos.y());
        (moved < amplitude ? lo : hi) = mid;
      }
      const double angle = sign * 0.5 * (lo + hi);
      for (Eigen::Index v = 0; v < sk.V.rows(); ++v) {
        double s = d[static_cast<size_t>(v)] / sh.radius;
        if (s >= 1) continue;
        Eigen::Vector3d x = sk.V.row(v).transpose();
        // The falloff scales the angle, so every vertex stays on its sphere.
        D.row(v) = (rotate_x(x, centre, angle * (1 - s * s) * (1 - s * s)) - x).transpose();
      }
    } else {
      for (Eigen::Index v = 0; v < sk.V.rows(); ++v) {
        double s = d[static_cast<size_t>(v)] / sh.radius;
        if (s < 1) D.row(v) = amplitude * (1 - s * s) * (1 - s * s) * dir;
      }
    }
    field[fap] = D;
    reference[fap] = sh.reference;
  }

  // The jaw: a hinge between the ears, level with the lower ear contacts.
  const FdpPoint *chin = fdp_on(2, 1, skin), *lower_lip = fdp_on(2, 3, skin);
  const FdpPoint *jl = fdp_pos(2, 13), *jr = fdp_pos(2, 14), *el = fdp_pos(10, 7), *er = fdp_pos(10, 8);
  const FdpPoint *eye_l = fdp_pos(3, 5), *eye_r = fdp_pos(3, 6);
  if (chin && lower_lip && ((jl && jr) || (eye_l && eye_r))) {
    Eigen::Vector3d pivot;
    if (jl && jr) {
      pivot = 0.5 * (jl->pos + jr->pos);
    } else {
      // No jaw corners (Song has none): a hinge one ENS below the eyes and
      // 1.2 mouth widths behind the chin, about where the condyles sit.
      pivot = Eigen::Vector3d(0, 0.5 * (eye_l->pos.y() + eye_r->pos.y()) - fapu.ens0,
                              chin->pos.z() - 1.2 * fapu.mw0);
    }
    pivot.x() = 0;
    if (el && er) pivot.y() = 0.5 * (el->pos.y() + er->pos.y());
    // Skin weight: 1 around the chin and lower lip, 0 past the mouth corners,
    // by surface distance from the chin.
    const double reach = 1.6 * (chin->pos - lower_lip->pos).norm();
    std::vector<double> d = graph.distances(chin->vertex, reach);
    auto jaw_weight = [&](Eigen::Index v) {
      double s = d[static_cast<size_t>(v)] / reach;
      if (s >= 1) return 0.0;
      return s < 0.6 ? 1.0 : 0.5 + 0.5 * std::cos(M_PI * (s - 0.6) / 0.4);
    };
    // open_jaw: the angle that lowers the chin by 1024 MNS units.
    const int ref3 = 1024;
    const double drop = ref3 * fapu.mns0 / 1024.0;
    double lo = 0, hi = 1.0;
    for (int it = 0; it < 60; ++it) {
      double mid = 0.5 * (lo + hi);
      (chin->pos.y() - rotate_x(chin->pos, pivot, mid).y() < drop ? lo : hi) = mid;
    }
    const double angle = 0.5 * (lo + hi);
    Eigen::MatrixXd D3 = Eigen::MatrixXd::Zero(sk.V.rows(), 3), D14 = D3, D15 = D3;
    const double thrust = 512 * fapu.mns0 / 1024.0, shift = 512 * fapu.mw0 / 1024.0;
    for (Eigen::Index v = 0; v < sk.V.rows(); ++v) {
      double w = jaw_weight(v);
      if (w == 0) continue;
      Eigen::Vector3d p = sk.V.row(v).transpose();
      D3.row(v) = w * (rotate_x(p, pivot, angle) - p).transpose();
      D14.row(v) = w * thrust * Eigen::RowVector3d(0, 0, 1);
      D15.row(v) = w * shift * Eigen::RowVector3d(-1, 0, 0);
    }
    field[3] = D3, reference[3] = ref3;
    field[14] = D14, reference[14] = 512;
    field[15] = D15, reference[15] = 512;
    RigidPart jaw;
    jaw.kind = AFM_RIGID_JAW;
    jaw.pivot = pivot;
    jaw.parts = scene.find_kinds({PartKind::TeethLower, PartKind::Tongue});
    jaw.controls.push_back({3, AFM_DOF_ROTATE_X, angle / ref3 / 1e-5});
    jaw.controls.push_back({14, AFM_DOF_TRANSLATE_Z, fapu.mns0 / 1024.0});
    jaw.controls.push_back({15, AFM_DOF_TRANSLATE_X, -fapu.mw0 / 1024.0});
    if (!jaw.parts.empty()) model.rigids.push_back(jaw);
  }

  // Morph targets for the FAP fields.
  for (auto &[fap, D] : field) {
    MorphTarget t;
    t.kind = AFM_TARGET_FAP;
    t.number = fap;
    t.reference = reference[fap];
    t.normals = options.normal_deltas;
    t.displacement.resize(scene.parts.size());
    t.displacement[static_cast<size_t>(skin)] = D;
    model.targets.push_back(std::move(t));
  }
  // Negative side of the inner brows: a narrower, lowering bump.
  if (options.negative_targets)
    for (int fap : {31, 32}) {
      const afm_fap_info *info = afm_fap(fap);
      const FdpPoint *p = fdp_on(info->fdp_group, info->fdp_index, skin);
      if (!p || p->vertex < 0 || !field.count(fap)) continue;
      const double r = 0.2 * fapu.es0, amplitude = 256 * fapu.ens0 / 1024.0;
      std::vector<double> d = graph.distances(p->vertex, r);
      Eigen::MatrixXd D = Eigen::MatrixXd::Zero(sk.V.rows(), 3);
      for (Eigen::Index v = 0; v < sk.V.rows(); ++v) {
        double s = d[static_cast<size_t>(v)] / r;
        // At value -256 the FDP moves 256 ENS units down: the target holds
        // the displacement at its (negative) reference value.
        if (s < 1) D.row(v) = -amplitude * (1 - s * s) * (1 - s * s) * fap_direction(info).transpose();
      }
      MorphTarget t;
      t.kind = AFM_TARGET_FAP;
      t.number = fap;
      t.reference = -256;
      t.normals = options.normal_deltas;
      t.displacement.resize(scene.parts.size());
      t.displacement[static_cast<size_t>(skin)] = D;
      model.targets.push_back(std::move(t));
    }

  // Visemes and expressions: fixed mixes of the FAP fields (value per FAP).
  using Mix = std::vector<std::pair<int, int>>;
  const Mix visemes[15] = {
      {},
      {{4, 60}, {5, 60}},                                         // p, b, m: lips pressed
      {{3, 100}, {5, 200}, {16, -100}},                           // f, v
      {{3, 250}, {4, -50}},                                       // T, D
      {{3, 200}},                                                 // t, d
      {{3, 300}},                                                 // k, g
      {{3, 150}, {16, 150}, {17, 150}, {53, -100}, {54, -100}},   // tS, dZ, S
      {{3, 100}, {6, 100}, {7, 100}},                             // s, z
      {{3, 200}},                                                 // n, l
      {{3, 150}, {16, 100}, {17, 100}, {53, -150}, {54, -150}},   // r
      {{3, 600}},                                                 // A:
      {{3, 300}, {6, 200}, {7, 200}},                             // e
      {{3, 200}, {6, 300}, {7, 300}},                             // I
      {{3, 400}, {53, -300}, {54, -300}, {16, 150}, {17, 150}},   // Q
      {{3, 200}, {53, -350}, {54, -350}, {16, 250}, {17, 250}}};  // U
  const Mix expressions[7] = {
      {},
      {{12, 200}, {13, 200}, {59, 200}, {60, 200}, {53, 150}, {54, 150}, {41, 200}, {42, 200}},
      {{31, 150}, {32, 150}, {33, -80}, {34, -80}, {12, -150}, {13, -150}, {59, -150}, {60, -150}},
      {{31, -200}, {32, -200}, {37, 150}, {38, 150}, {16, 80}, {17, 80}},
      {{3, 300}, {31, 250}, {32, 250}, {33, 200}, {34, 200}, {6, 150}, {7, 150}},
      {{4, -150}, {61, 80}, {62, 80}, {63, 100}, {12, -80}, {13, -80}},
      {{3, 500}, {31, 300}, {32, 300}, {33, 300}, {34, 300}, {35, 250}, {36, 250}, {19, -200}, {20, -200}}};
  auto mixed = [&](afm_target_kind kind, int number, const Mix &mix) {
    MorphTarget t;
    t.kind = kind;
    t.number = number;
    t.reference = 63;
    t.normals = options.normal_deltas;
    t.displacement.resize(scene.parts.size());
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(sk.V.rows(), 3);
    bool any = false;
    for (auto [fap, value] : mix)
      if (field.count(fap)) {
        D += (static_cast<double>(value) / reference[fap]) * field[fap];
        any = true;
      }
    if (!any) return;
    t.displacement[static_cast<size_t>(skin)] = D;
    model.targets.push_back(std::move(t));
  };
  for (int v = 1; v <= 14; ++v) mixed(AFM_TARGET_VISEME, v, visemes[v]);
  for (int e = 1; e <= 6; ++e) mixed(AFM_TARGET_EXPRESSION, e, expressions[e]);

  for (RigidPart &r : eye_and_head_rigids(scene, fdps, fapu, skin)) model.rigids.push_back(std::move(r));
  return model;
}

Expected<std::vector<uint8_t>> analytic_reference_afm(int skin_vertices, const AnalyticOptions &options,
                                                      afm_profile profile) {
  RefHeadOptions ro;
  ro.skin_vertices = skin_vertices;
  Expected<RefHead> head = make_reference_head(ro);
  if (!head) return head.status();
  Expected<Fapu> fapu = compute_fapu(head->fdps);
  if (!fapu) return fapu.status();
  Expected<AnalyticModel> model = make_analytic_model(head->scene, head->fdps, *fapu, options);
  if (!model) return model.status();
  AfmContent content;
  content.scene = &head->scene;
  content.fdps = &head->fdps;
  content.fapu = *fapu;
  content.targets = std::move(model->targets);
  content.rigids = std::move(model->rigids);
  content.generator = "analytic_reference_afm";
  return encode_afm(content, profile);
}

}  // namespace afmb
