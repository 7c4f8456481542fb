#include "anatomy/face_model.h"

#include <algorithm>
#include <cmath>

#include "afm/afm_export.h"
#include "anatomy/fdp_completion.h"
#include "core/orient.h"
#include "core/validate.h"

namespace afmb {

int FaceModel::find(const std::string &muscle) const {
  for (size_t i = 0; i < muscles.size(); ++i)
    if (muscles[i].name == muscle) return static_cast<int>(i);
  return -1;
}

double muscle_tension(const Muscle &m, double percent) {
  return percent >= 0 ? percent / 100.0 * m.tension_max : percent / 100.0 * m.tension_min;
}

namespace {

std::vector<int> with_rings(const SkinModel &skin, const std::vector<int> &set, int rings) {
  std::vector<uint8_t> in(static_cast<size_t>(skin.n), 0);
  std::vector<int> frontier;
  for (int v : set) in[static_cast<size_t>(v)] = 1, frontier.push_back(v);
  for (int r = 0; r < rings && !frontier.empty(); ++r) {
    std::vector<int> next;
    for (int v : frontier)
      for (int u : skin.neighbours[static_cast<size_t>(v)])
        if (!in[static_cast<size_t>(u)]) in[static_cast<size_t>(u)] = 1, next.push_back(u);
    frontier = std::move(next);
  }
  std::vector<int> out;
  for (int v = 0; v < skin.n; ++v)
    if (in[static_cast<size_t>(v)] && skin.in_mesh[static_cast<size_t>(v)]) out.push_back(v);
  return out;
}

// Largest motion (any layer) of a vertex of `set` that has a neighbour outside it.
double border_motion(const SkinModel &skin, const std::vector<int> &set, const Eigen::MatrixXd &X) {
  std::vector<uint8_t> in(static_cast<size_t>(skin.n), 0);
  for (int v : set) in[static_cast<size_t>(v)] = 1;
  double worst = 0;
  for (int v : set) {
    bool border = false;
    for (int u : skin.neighbours[static_cast<size_t>(v)]) border = border || !in[static_cast<size_t>(u)];
    if (!border) continue;
    for (int l = 0; l < kSkull; ++l) {
      const int g = skin.node(l, v);
      worst = std::max(worst, (X.row(g) - skin.X0.row(g)).norm());
    }
  }
  return worst;
}

// Solves on `set`, growing it until the wave dies out at its border.
Status solve_growing(const FaceModel &model, std::vector<int> &set, const ForceField &forces,
                     const Eigen::MatrixXd &reference, Eigen::MatrixXd &X, const SolverOptions &opts,
                     double threshold, FactorCache *cache, bool whole, SolveStats *stats, int *rounds) {
  const SkinModel &skin = model.tissue;
  if (whole) {
    set.clear();
    for (int v = 0; v < skin.n; ++v)
      if (skin.in_mesh[static_cast<size_t>(v)]) set.push_back(v);
  }
  int total_it = 0, total_cg = 0;
  for (int round = 0;; ++round) {
    SolveStats st = solve_equilibrium(skin, set, forces, reference, X, opts, cache);
    total_it += st.iterations;
    total_cg += st.cg_iterations;
    st.iterations = total_it;
    st.cg_iterations = total_cg;
    if (stats) *stats = st;
    if (rounds) *rounds = round + 1;
    if (!st.converged) return Status::error(st.message);
    if (whole || border_motion(skin, set, X) <= threshold) return Status::ok();
    const size_t before = set.size();
    set = with_rings(skin, set, 2 << std::min(round, 4));
    if (set.size() == before) return Status::ok();  // the whole connected skin
  }
}

ForceField activation_forces(const FaceModel &model, const std::vector<std::pair<int, double>> &muscles) {
  return [&model, muscles](const Eigen::MatrixXd &X, Eigen::MatrixXd *F) {
    double energy = 0;
    for (const auto &[i, pct] : muscles) {
      const Muscle &m = model.muscles[static_cast<size_t>(i)];
      energy += muscle_load(model.tissue, m, muscle_tension(m, pct), X, F);
    }
    return energy;
  };
}

// Finds the tension giving the +100 % (maximum) or -100 % action (section
// 3.3): probes, then safeguarded secant steps, warm-started.
Status calibrate_side(const FaceModel &model, Muscle &m, bool maximum, FactorCache *cache,
                      std::vector<int> &set) {
  const double target = muscle_action_target(m, maximum);
  const double sign = maximum ? 1.0 : -1.0;
  // The search needs the action to 2 %: solve to a tenth of that, and let
  // the wave die out to the same level (V_d is found by a strict solve later).
  SolverOptions coarse = model.solver;
  coarse.tolerance = std::max(model.solver.tolerance, 2e-3 * std::abs(target));
  Eigen::MatrixXd X = model.tissue.X0;
  // Probe: a tension small enough to stay in the linear range but moving
  // the key node well above the tolerance; then scale to the target and
  // take secant steps on the (stiffening) action-tension curve.
  double thickness = 0;
  for (int v : m.influence) thickness += model.tissue.thickness[v];
  thickness /= static_cast<double>(m.influence.size());
  double t = 1e-2 * model.tissue.params.slab[1].modulus * std::abs(target) / thickness;
  const ForceField f = [&](const Eigen::MatrixXd &P, Eigen::MatrixXd *F) {
    return muscle_load(model.tissue, m, sign * t, P, F);
  };
  for (int probe = 0; probe < 8; ++probe) {
    X = model.tissue.X0;
    Status s = solve_growing(model, set, f, model.tissue.X0, X, coarse, coarse.tolerance, cache, false, nullptr, nullptr);
    if (!s) return s.wrap("calibrating " + m.name);
    const double a = muscle_action(model.tissue, m, X);
    if (a * target > 0 && std::abs(a) > 0.02 * std::abs(target)) {
      t *= std::min(target / a, 1e4);
      break;
    }
    t *= 10;
  }
  // Safeguarded secant: [lo, hi] brackets the tension (hi: the action
  // overshot, or the solve failed: too much load); steps leaving the bracket
  // bisect it instead.
  double lo = 0, a_lo = 0, hi = 0;
  Eigen::MatrixXd X_lo = model.tissue.X0;
  std::string last_failure;
  for (int it = 0; it < 16; ++it) {
    X = X_lo;
    std::vector<int> trial_set = set;
    Status s = solve_growing(model, trial_set, f, model.tissue.X0, X, coarse, coarse.tolerance, cache, false,
                             nullptr, nullptr);
    double a = s ? muscle_action(model.tissue, m, X) : 0.0;
    if (s && std::abs(a - target) <= 0.02 * std::abs(target)) {
      (maximum ? m.tension_max : m.tension_min) = t;
      set = std::move(trial_set);
      return Status::ok();
    }
    double next;
    if (!s || std::abs(a) > std::abs(target)) {  // overshoot or failure: t is an upper bound
      if (!s) last_failure = s.message();
      hi = t;
      const double guess = s && a * target > 0 && lo > 0 ? lo + (target - a_lo) * (t - lo) / (a - a_lo) : 0.0;
      next = guess > lo && guess < hi ? guess : 0.5 * (lo + hi);
    } else {
      const double prev = lo, a_prev = a_lo;
      lo = t, a_lo = a, X_lo = X, set = trial_set;
      double guess = prev > 0 && a != a_prev ? t + (target - a) * (t - prev) / (a - a_prev)
                                              : (a * target > 0 ? t * target / a : t * 4);
      if (!(guess > lo) || !std::isfinite(guess)) guess = 2 * lo;
      guess = std::min(guess, 3 * lo);
      next = hi > 0 && guess >= hi ? 0.5 * (lo + hi) : guess;
    }
    t = next;
  }
  if (!last_failure.empty()) return Status::error("calibrating " + m.name + ": " + last_failure);
  return Status::error("calibrating " + m.name + ": the " + (maximum ? "maximum" : "minimum") +
                       " contraction was not found (the muscle cannot move its key node " +
                       std::to_string(std::abs(target)) + " model units)");
}

}  // namespace

Expected<FaceModel> build_face_model(const Scene &scene, const FdpSet &input, const FaceModelOptions &options) {
  FaceModel model;
  const int steps_fixed = 4;
  auto progress = [&](int done, int total, const std::string &what) {
    if (options.progress) options.progress(done, total, what);
  };
  model.skin = scene.find_kind(PartKind::Skin);
  if (model.skin < 0) return Status::error("no skin part: no part holds FDP 2.1 (chin)");
  if (Status s = check_skin(scene, model.skin); !s) return s;
  if (Status s = check_orientation(input); !s) return s;

  model.fdps = input;
  if (options.estimate_missing_fdps) {
    Expected<std::vector<FdpId>> added = complete_fdps(scene, model.skin, model.fdps, anatomy_fdps(), &model.notes);
    if (!added) return added.status();
  }
  Expected<Fapu> fapu = compute_fapu(input);
  if (!fapu) fapu = compute_fapu(model.fdps);
  if (!fapu) return fapu.status();
  model.fapu = *fapu;

  Expected<SkinModel> tissue = build_skin_model(scene, model.skin, options.tissue);
  if (!tissue) return tissue.status();
  model.tissue = std::move(*tissue);
  progress(1, steps_fixed, "skin tissue");

  const std::vector<MuscleDef> &table = muscle_table();
  for (size_t d = 0; d < table.size(); ++d) {
    Expected<Muscle> m = place_muscle(model.tissue, model.fdps, static_cast<int>(d));
    if (!m) {
      if (table[d].essential) return m.status().wrap("essential muscle");
      model.warnings.push_back(m.status().message() + ": skipped");
      continue;
    }
    model.muscles.push_back(std::move(*m));
  }
  // Section 3.2.1: the mouth-window searches take the other lip out of the
  // mentalis and upper lip areas.
  Expected<MouthLips> lips = mouth_lips(model.tissue, model.fdps);
  if (!lips) return lips.status();
  for (Muscle &m : model.muscles) {
    if (m.name.rfind("mentalis", 0) == 0) remove_from_influence(m, lips->upper);
    if (m.name.rfind("upper_lip", 0) == 0) remove_from_influence(m, lips->lower);
  }
  for (const Muscle &m : model.muscles)
    if (table[static_cast<size_t>(m.def)].lips_or_cheeks)
      for (int v : m.influence) model.tissue.skull_free[static_cast<size_t>(v)] = 1;
  progress(2, steps_fixed, "muscles placed");

  Expected<Jaw> jaw = build_jaw(model.tissue, model.fdps, model.fapu, *lips);
  if (!jaw) return jaw.status();
  model.jaw = std::move(*jaw);
  progress(3, steps_fixed, "jaw mapped");

  model.quantum = afm_position_quantum(scene);
  model.solver = options.solver;
  if (!(model.solver.tolerance > 0)) model.solver.tolerance = model.quantum / 2;
  model.wave_threshold = options.wave_threshold > 0 ? options.wave_threshold : model.solver.tolerance;
  progress(4, steps_fixed, "solver ready");
  if (!options.calibrate) return model;

  FactorCache cache;
  const int total = static_cast<int>(model.muscles.size()) + 1;
  for (size_t i = 0; i < model.muscles.size(); ++i) {
    Muscle &m = model.muscles[i];
    if (!options.calibrate_only.empty() &&
        std::find(options.calibrate_only.begin(), options.calibrate_only.end(), m.name) ==
            options.calibrate_only.end())
      continue;
    std::vector<int> set = with_rings(model.tissue, m.influence, 1);
    if (Status s = calibrate_side(model, m, false, &cache, set); !s) return s;
    if (Status s = calibrate_side(model, m, true, &cache, set); !s) return s;
    // V_d: the strict solve at +100 %, grown until the wave is below the threshold.
    Activation full;
    full.muscles = {{static_cast<int>(i), 100.0}};
    m.dynamic = set;
    Expected<Pose> p = solve_pose(model, full, &cache);
    if (!p) return p.status().wrap("dynamic set of " + m.name);
    m.dynamic = p->dynamic;
    cache.clear();
    progress(static_cast<int>(i) + 1, total, m.name);
  }
  if (!options.calibrate_jaw) return model;
  Activation open;
  open.jaw_open = 100;
  model.jaw.dynamic = model.jaw.vertices;
  Expected<Pose> p = solve_pose(model, open, &cache);
  if (!p) return p.status().wrap("jaw");
  model.jaw.dynamic = p->dynamic;
  progress(total, total, "jaw");
  return model;
}

Expected<Pose> solve_pose(const FaceModel &model, const Activation &a, FactorCache *cache,
                          const PoseOptions &options) {
  const SkinModel &skin = model.tissue;
  Pose pose;
  pose.X = skin.X0;
  std::vector<int> set;
  for (const auto &[i, pct] : a.muscles) {
    if (i < 0 || i >= static_cast<int>(model.muscles.size()))
      return Status::error("pose: muscle index " + std::to_string(i) + " out of range");
    if (pct < -100 || pct > 100 || !std::isfinite(pct))
      return Status::error("pose: " + model.muscles[static_cast<size_t>(i)].name + " at " +
                           std::to_string(pct) + " %: contraction must be within -100..100");
    const Muscle &m = model.muscles[static_cast<size_t>(i)];
    if (pct != 0 && !(pct > 0 ? m.tension_max > 0 : m.tension_min > 0))
      return Status::error("pose: muscle " + m.name + " is not calibrated");
    const std::vector<int> &own = m.dynamic.empty() ? m.influence : m.dynamic;
    std::vector<int> u;
    std::set_union(set.begin(), set.end(), own.begin(), own.end(), std::back_inserter(u));
    set = std::move(u);
  }
  const bool jaw_moves = a.jaw_open != 0 || a.jaw_thrust != 0 || a.jaw_shift != 0;
  if (jaw_moves) {
    if (a.jaw_open < 0) return Status::error("pose: the jaw does not open by a negative amount");
    const Eigen::Affine3d t = jaw_motion(model.jaw, a.jaw_open, a.jaw_thrust, a.jaw_shift);
    for (int v : model.jaw.vertices)
      for (int l = 0; l < kTissueLayers; ++l) {
        const int g = skin.node(l, v);
        pose.X.row(g) = (t * Eigen::Vector3d(skin.X0.row(g))).transpose();
      }
    const std::vector<int> &own = model.jaw.dynamic.empty() ? model.jaw.vertices : model.jaw.dynamic;
    std::vector<int> u;
    std::set_union(set.begin(), set.end(), own.begin(), own.end(), std::back_inserter(u));
    set = std::move(u);
  }
  if (set.empty() && !options.whole_mesh) return pose;
  const SolverOptions &opts = options.solver ? *options.solver : model.solver;
  FactorCache local;
  const Eigen::MatrixXd reference = pose.X;  // the rest state, carried by the jaw
  Status s = solve_growing(model, set, activation_forces(model, a.muscles), reference, pose.X, opts,
                           model.wave_threshold, cache ? cache : &local,
                           options.whole_mesh, &pose.stats, &pose.rounds);
  if (!s) return s.wrap("pose");
  pose.dynamic = std::move(set);
  return pose;
}

Eigen::MatrixXd pose_epidermis(const FaceModel &model, const Pose &pose) {
  return pose.X.topRows(model.tissue.n);
}

}  // namespace afmb
