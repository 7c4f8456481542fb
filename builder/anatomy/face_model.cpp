#include "anatomy/face_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <mutex>

#include "afm/afm_export.h"
#include "anatomy/fdp_completion.h"
#include "core/orient.h"
#include "core/parallel.h"
#include "core/validate.h"

namespace afmb {

int FaceModel::find(const std::string &muscle) const {
  for (size_t i = 0; i < muscles.size(); ++i)
    if (muscles[i].name == muscle) return static_cast<int>(i);
  return -1;
}

int FaceModel::twin(int muscle) const {
  const std::string name = twin_name(muscles[static_cast<size_t>(muscle)].name);
  return name.empty() ? -1 : find(name);
}

Eigen::MatrixXd mirrored_nodes(const FaceModel &model, const Eigen::MatrixXd &X) {
  const SkinModel &skin = model.tissue;
  Eigen::MatrixXd out = skin.X0;
  for (int v = 0; v < skin.n; ++v) {
    const int u = model.mirror.image[static_cast<size_t>(v)];
    if (u < 0) continue;
    for (int l = 0; l < kTissueLayers; ++l) {
      Eigen::RowVector3d d = X.row(skin.node(l, u)) - skin.X0.row(skin.node(l, u));
      d.x() = -d.x();
      out.row(skin.node(l, v)) += d;
    }
  }
  return out;
}

std::vector<int> mirrored_vertices(const FaceModel &model, const std::vector<int> &set) {
  std::vector<int> out;
  for (int v : set)
    if (const int u = model.mirror.image[static_cast<size_t>(v)]; u >= 0) out.push_back(u);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
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

// Largest motion (any layer) of a vertex of `set` that has a neighbour outside
// it (and not `held`, when given: vertices placed by the pose, not solved).
double border_motion(const SkinModel &skin, const std::vector<int> &set, const Eigen::MatrixXd &X,
                     const std::vector<char> *held = nullptr) {
  std::vector<uint8_t> in(static_cast<size_t>(skin.n), 0);
  if (held)
    for (int v = 0; v < skin.n; ++v) in[static_cast<size_t>(v)] = (*held)[static_cast<size_t>(v)];
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
// `held` (when given, one flag per skin vertex): vertices that stay where X
// has them, never in the set.
Status solve_growing(const FaceModel &model, std::vector<int> &set, const ForceField &forces,
                     const Eigen::MatrixXd &reference, Eigen::MatrixXd &X, const SolverOptions &opts,
                     double threshold, FactorCache *cache, bool whole, SolveStats *stats, int *rounds,
                     LoadControl *control = nullptr, const std::vector<char> *held = nullptr) {
  const SkinModel &skin = model.tissue;
  if (whole) {
    set.clear();
    for (int v = 0; v < skin.n; ++v)
      if (skin.in_mesh[static_cast<size_t>(v)]) set.push_back(v);
  }
  auto unheld = [&] {
    if (held)
      set.erase(std::remove_if(set.begin(), set.end(), [&](int v) { return (*held)[static_cast<size_t>(v)] != 0; }),
                set.end());
  };
  unheld();
  SolveStats earlier;  // the earlier rounds' work
  for (int round = 0;; ++round) {
    SolveStats st = solve_equilibrium(skin, set, forces, reference, X, opts, cache, control);
    add_work(st, earlier);  // the last round's stats with every round's work
    earlier = st;
    if (stats) *stats = st;
    if (rounds) *rounds = round + 1;
    if (!st.converged) return Status::error(st.message);
    if (whole || border_motion(skin, set, X, held) <= threshold) return Status::ok();
    const size_t before = set.size();
    set = with_rings(skin, set, 2 << std::min(round, 4));
    unheld();
    if (set.size() == before) return Status::ok();  // the whole connected skin
  }
}

ForceField activation_forces(const FaceModel &model, const std::vector<std::pair<int, double>> &muscles) {
  return [&model, muscles](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
    double energy = 0;
    for (const auto &[i, pct] : muscles) {
      const Muscle &m = model.muscles[static_cast<size_t>(i)];
      energy += muscle_load(model.tissue, m, muscle_tension(m, pct), X, F, K);
    }
    return energy;
  };
}

// The muscle's load at unit tension, pulling (+1) or pushing (-1).
ForceField unit_load(const FaceModel &model, const Muscle &m, double sign) {
  return [&model, &m, sign](const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K) {
    return muscle_load(model.tissue, m, sign, X, F, K);
  };
}

// The first guess at V_d: where the muscle's elastic wave is above half the
// threshold at the larger of its two calibrated actions, by the rest state's
// linear response; plus one ring. The calibration solves grow it where the
// nonlinear wave reaches further. With `whole` (a cache holding the whole
// skin's rest factorisation, shared by every muscle), the response is the
// whole skin's: one triangular solve per muscle. Without it, on the
// influence area grown by rings until the response dies out at the set's
// border: one factorisation per round (Song: 113 rounds, 1.06 s of CPU,
// against 0.07 s on the whole skin).
Expected<std::vector<int>> wave_estimate(const FaceModel &model, const Muscle &m, FactorCache *whole) {
  const SkinModel &skin = model.tissue;
  Eigen::MatrixXd grad = Eigen::MatrixXd::Zero(skin.X0.rows(), 3);
  muscle_action(skin, m, skin.X0, &grad);
  const double reach = std::max(std::abs(muscle_action_target(m, true)), std::abs(muscle_action_target(m, false)));
  std::vector<int> seed = m.influence;  // and the key node's vertex
  for (Eigen::Index g = 0; g < grad.rows(); ++g)
    if (grad.row(g).squaredNorm() > 0) seed.push_back(skin.vertex_of(static_cast<int>(g)));
  std::sort(seed.begin(), seed.end());
  seed.erase(std::unique(seed.begin(), seed.end()), seed.end());
  std::vector<int> set = whole ? with_rings(skin, seed, skin.n) : with_rings(skin, seed, 2);
  for (int round = 0;; ++round) {
    Expected<Eigen::MatrixXd> w = linear_response(skin, set, unit_load(model, m, 1.0), whole);
    if (!w) return w.status();
    const double a1 = (grad.array() * w->array()).sum();
    if (!(std::abs(a1) > 0)) return Status::error(m.name + ": the muscle does not move its key node");
    const Eigen::MatrixXd scaled = *w * (reach / std::abs(a1));
    const size_t before = set.size();
    if (!whole && border_motion(skin, set, skin.X0 + scaled) > model.wave_threshold / 2) {
      set = with_rings(skin, set, 2 << std::min(round, 4));
      if (set.size() > before) continue;
    }
    std::vector<int> out = seed;
    for (int v : set)
      for (int l = 0; l < kSkull; ++l)
        if (scaled.row(skin.node(l, v)).norm() > model.wave_threshold / 2) {
          out.push_back(v);
          break;
        }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return with_rings(skin, out, 1);
  }
}

// set |= more (both sorted, unique).
void join(std::vector<int> &set, const std::vector<int> &more) {
  std::vector<int> u;
  std::set_union(set.begin(), set.end(), more.begin(), more.end(), std::back_inserter(u));
  set = std::move(u);
}

// X - reference on the nodes where they differ.
NodeDisplacement displacement(const Eigen::MatrixXd &X, const Eigen::MatrixXd &reference) {
  NodeDisplacement out;
  for (Eigen::Index g = 0; g < X.rows(); ++g)
    if (X.row(g) != reference.row(g)) out.nodes.push_back(static_cast<int>(g));
  out.displacement.resize(static_cast<Eigen::Index>(out.nodes.size()), 3);
  for (size_t i = 0; i < out.nodes.size(); ++i)
    out.displacement.row(static_cast<Eigen::Index>(i)) = X.row(out.nodes[i]) - reference.row(out.nodes[i]);
  return out;
}

// The rest state with the jaw's vertices (every layer) moved by `jaw`, and
// its followers by their shares of it (jaw.h).
Eigen::MatrixXd carried_rest(const FaceModel &model, const Eigen::Affine3d &jaw) {
  const SkinModel &skin = model.tissue;
  Eigen::MatrixXd X = skin.X0;
  auto carry = [&](int v, const Eigen::Affine3d &motion) {
    for (int l = 0; l < kTissueLayers; ++l) {
      const int g = skin.node(l, v);
      X.row(g) = (motion * Eigen::Vector3d(skin.X0.row(g))).transpose();
    }
  };
  for (int v : model.jaw.vertices) carry(v, jaw);
  for (const auto &[v, share] : model.jaw.followers) carry(v, jaw_share(model.jaw, jaw, share));
  return X;
}

// The model's solver options for the calibrations (the muscles' sides and
// the jaw's full opening): a newton solver whatever the model's, since
// implicit-euler cannot solve for a tension and, on Song, found no
// equilibrium for the jaw within its 2,000 steps (face_model.h).
SolverOptions calibration_solver(const FaceModel &model) {
  SolverOptions opts = model.solver;
  if (opts.kind == SolverKind::ImplicitEuler) opts.kind = SolverKind::Newton;
  return opts;
}

// Finds the tension giving the +100 % (maximum) or -100 % action (section
// 3.3): one equilibrium solve with the tension as an unknown (solver.h, load
// control), on `set`, grown while the wave reaches its border.
// *locked: it failed because the tissue locked before the key node got there.
// *torn (when given): the pose that gets there tears the skin
// (SkinFaults::tears); the tension is set all the same.
// With `twin` (the muscle's calibrated twin on a mirror-symmetric skin, at
// the same range; index into model.muscles, -1: none), the solve starts from
// the twin's pose mirrored, at its tension, on the set joined with the
// twin's V_d mirrored.
Status calibrate_side(const FaceModel &model, Muscle &m, bool maximum, FactorCache *cache, std::vector<int> &set,
                      bool *locked, bool *torn, int twin_index = -1) {
  const Muscle *twin = twin_index >= 0 ? &model.muscles[static_cast<size_t>(twin_index)] : nullptr;
  LoadControl control;
  control.unit_load = unit_load(model, m, maximum ? 1.0 : -1.0);
  control.action = [&](const Eigen::MatrixXd &X, Eigen::MatrixXd *g) { return muscle_action(model.tissue, m, X, g); };
  control.value = muscle_action_target(m, maximum);
  const SolverOptions opts = calibration_solver(model);
  Eigen::MatrixXd X = model.tissue.X0;
  if (twin && (maximum ? twin->range_max == m.range_max : twin->range_min == m.range_min)) {
    Activation a;
    a.muscles = {{twin_index, maximum ? 100.0 : -100.0}};
    const Pose t = superposed_pose(model, a);  // the twin's calibrated pose
    X = mirrored_nodes(model, t.X);
    control.tension = maximum ? twin->tension_max : twin->tension_min;
    join(set, mirrored_vertices(model, t.dynamic));
  }
  Status s = solve_growing(model, set, nullptr, model.tissue.X0, X, opts, model.wave_threshold, cache, false,
                           nullptr, nullptr, &control);
  if (locked) *locked = !s && control.unreachable;
  if (!s)
    return s.wrap("calibrating " + m.name + ": the " + (maximum ? "maximum" : "minimum") +
                  " contraction (moving its key node " + std::to_string(std::abs(control.value)) +
                  " model units) was not found");
  if (torn) *torn = skin_faults(model, X.topRows(model.tissue.n)).tears();
  (maximum ? m.tension_max : m.tension_min) = control.tension;
  (maximum ? m.response_max : m.response_min) = displacement(X, model.tissue.X0);
  return Status::ok();
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
  {
    const FdpPoint *l = model.fdps.find(FdpId{3, 5}), *r = model.fdps.find(FdpId{3, 6});
    if (l && r)
      model.mirror = skin_mirror(model.tissue.X0.topRows(model.tissue.n), model.tissue.in_mesh,
                                 0.5 * (l->pos.x() + r->pos.x()), kMirrorTolerance * (l->pos - r->pos).norm(),
                                 &model.tissue.neighbours);
  }
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
  // mentalis and upper lip areas, and out of each lip protrusion driver's.
  Expected<MouthLips> lips = mouth_lips(model.tissue, model.fdps);
  if (!lips) return lips.status();
  for (Muscle &m : model.muscles) {
    if (m.name.rfind("mentalis", 0) == 0) remove_from_influence(m, lips->upper);
    if (m.name.rfind("upper_lip", 0) == 0) remove_from_influence(m, lips->lower);
    if (m.name == "lip_protrusion_lower") remove_from_influence(m, lips->upper);
    if (m.name == "lip_protrusion_upper") remove_from_influence(m, lips->lower);
  }
  // The lips' contact pairs, from the same searches.
  if (model.tissue.params.lip_contact_modulus > 0)
    model.tissue.lip_pairs = lip_pairs(model.tissue, lips->upper, lips->lower, model.tissue.params.lip_contact_modulus,
                                       kLipBand * model.fapu.mns0, kLipMargin * model.fapu.mns0);
  for (const Muscle &m : model.muscles)
    if (table[static_cast<size_t>(m.def)].skull_free)
      for (int v : m.influence) model.tissue.skull_free[static_cast<size_t>(v)] = 1;
  // A lid turned far (Activation::lids) brings skin from above the eye,
  // beyond the band of SkinModel::eye_near, over the ball: the solver holds
  // the lid's skin outside its eyeball off it (not the skin turning into the
  // socket, inside the sphere at rest).
  for (const Muscle &m : model.muscles) {
    if (m.kind != MuscleKind::Lid || m.eye < 0) continue;
    const EyeSphere &ball = model.tissue.eyes[static_cast<size_t>(m.eye)];
    for (int v : m.influence)
      if (model.tissue.eye_near[static_cast<size_t>(v)] < 0 &&
          (model.tissue.X0.row(model.tissue.node(kEpidermis, v)).transpose() - ball.centre).norm() > ball.radius)
        hold_off_eyeball(model.tissue, v, m.eye);
  }
  progress(2, steps_fixed, "muscles placed");

  Expected<Jaw> jaw = build_jaw(model.tissue, model.fdps, model.fapu, *lips);
  if (!jaw) return jaw.status();
  model.jaw = std::move(*jaw);
  progress(3, steps_fixed, "jaw mapped");

  model.quantum = afm_position_quantum(scene);
  model.solver = options.solver;
  if (!(model.solver.tolerance > 0)) model.solver.tolerance = model.quantum / 2;
  model.wave_threshold = options.wave_threshold > 0 ? options.wave_threshold : kWaveQuanta * model.quantum;
  progress(4, steps_fixed, "solver ready");
  if (!options.calibrate) return model;

  // Every muscle's calibration, and the jaw's set, are independent tasks:
  // each reads the model and writes only its own muscle, so they run on
  // `threads` workers and give the same result on any number of them.
  std::vector<size_t> todo;
  for (size_t i = 0; options.calibrate_muscles && i < model.muscles.size(); ++i)
    if (options.calibrate_only.empty() ||
        std::find(options.calibrate_only.begin(), options.calibrate_only.end(), model.muscles[i].name) !=
            options.calibrate_only.end())
      todo.push_back(i);
  const size_t tasks = todo.size() + (options.calibrate_jaw ? 1 : 0);
  std::vector<Status> result(tasks);
  // Per muscle and side (-, +), why its range was cut: 0 its tissue locks,
  // 1 a pose tore the skin, 2 it still tears at the range kept, 3 the solver
  // found no equilibrium there.
  std::vector<std::array<int, 2>> cut(model.muscles.size(), {0, 0});
  Expected<Pose> jaw_pose = Status::error("jaw: not solved");
  model.jaw.dynamic = model.jaw.vertices;
  // The wave estimates first, then the muscles' calibrations, the largest
  // estimated set first: the 10k head's left mentalis takes a third of the
  // model's CPU, and taken in table order it came last and left the other
  // worker idle. The jaw's calibration needs no estimate: it runs beside
  // them (task 1), so that the estimates' rest factorisation of the whole
  // skin (Song: 0.14 s) no longer leaves the other worker idle.
  std::vector<Expected<std::vector<int>>> sets(todo.size(), Status::error("not estimated"));
  // On a mirror-symmetric skin, a right muscle whose left twin is
  // calibrated too starts from its poses mirrored (calibrate_side): a few
  // Newton iterations instead of a solve from rest. The right ones come
  // last, and one whose twin is still running waits for it.
  std::vector<int> twin_task(todo.size(), -1);
  if (model.mirror.symmetric())
    for (size_t k = 0; k < todo.size(); ++k) {
      const int t = model.twin(static_cast<int>(todo[k]));
      if (t < 0 || !right_side(model.muscles[todo[k]].name)) continue;
      for (size_t j = 0; j < todo.size(); ++j)
        if (todo[j] == static_cast<size_t>(t)) twin_task[k] = static_cast<int>(j);
    }
  std::vector<size_t> order(todo.size());  // the muscles' calibrations, in the order they are taken
  auto estimate = [&] {
    // One rest factorisation of the connected skin serves every muscle's
    // estimate; where it is singular (a skin piece that nothing holds),
    // each muscle grows its own set instead, in its own task (below).
    FactorCache whole;
    for (size_t k = 0; k < todo.size(); ++k) sets[k] = wave_estimate(model, model.muscles[todo[k]], &whole);
    for (size_t k = 0; k < todo.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      if ((twin_task[a] >= 0) != (twin_task[b] >= 0)) return twin_task[b] >= 0;
      return (sets[a] ? sets[a]->size() : 0) > (sets[b] ? sets[b]->size() : 0);
    });
  };
  // Tasks: 0 the estimates, then the jaw, then the muscles in `order`, each
  // after the estimates (and a right one after its twin, below).
  const size_t first_muscle = 1 + (options.calibrate_jaw ? 1 : 0);
  std::vector<int> after(first_muscle + todo.size(), 0);
  after[0] = -1;
  if (options.calibrate_jaw) after[1] = -1;
  std::mutex lock;
  std::condition_variable calibrated_one;
  std::vector<char> calibrated(todo.size(), 0);
  int finished = 0;
  const int total = static_cast<int>(tasks);
  for_each_task_after(after.size(), options.threads, after, [&](size_t j) {
    if (j == 0) {
      estimate();
      return;
    }
    FactorCache cache;
    std::string what = "jaw";
    if (j >= first_muscle) {
      const size_t k = order[j - first_muscle];
      Muscle &m = model.muscles[todo[k]];
      what = m.name;
      // Its twin's task comes earlier (the right ones last): running or done.
      const int t = twin_task[k];
      if (t >= 0) {
        std::unique_lock<std::mutex> g(lock);
        calibrated_one.wait(g, [&] { return calibrated[static_cast<size_t>(t)] != 0; });
      }
      Expected<std::vector<int>> &set = sets[k];
      if (!set) set = wave_estimate(model, m, nullptr);
      Status s = set ? Status::ok() : set.status().wrap("calibrating " + m.name);
      // A muscle whose tissue locks before its key node reaches the
      // table's range, whose pose there tears the skin, or where the solver
      // finds no equilibrium (a coarse lid turned 50 degrees), calibrates to
      // a half, a quarter or an eighth of it instead (not an essential one:
      // its range is what the FAPs rely on).
      const bool essential = table[static_cast<size_t>(m.def)].essential;
      const int twin = t >= 0 && result[static_cast<size_t>(t)] ? static_cast<int>(todo[static_cast<size_t>(t)]) : -1;
      auto side = [&](bool maximum) {
        bool locked = false, torn = false;
        int &why = cut[todo[k]][maximum ? 1 : 0];
        Status st = calibrate_side(model, m, maximum, &cache, *set, &locked, essential ? nullptr : &torn, twin);
        double &range = maximum ? m.range_max : m.range_min;
        while ((!st || torn) && range > 0.125 && !essential) {
          if (why != 1) why = torn ? 1 : locked ? 0 : 3;
          range /= 2;
          locked = torn = false;
          st = calibrate_side(model, m, maximum, &cache, *set, &locked, &torn, twin);
        }
        // Torn even at an eighth: kept there, so that the FAPs and
        // expressions have the muscle; their own checks bound its share.
        if (torn) why = 2;
        return st;
      };
      if (s) s = side(false);
      if (s) s = side(true);
      if (s) m.dynamic = std::move(*set);  // grown by both sides: V_d
      result[k] = s;
      std::lock_guard<std::mutex> g(lock);
      calibrated[k] = 1;
      calibrated_one.notify_all();
    } else {
      // The jaw's calibrated full opening, which every pose that opens the
      // jaw starts from.
      Activation open;
      open.jaw_open = 100;
      const SolverOptions newton = calibration_solver(model);
      PoseOptions po;
      po.solver = &newton;
      jaw_pose = solve_pose(model, open, &cache, po);
    }
    std::lock_guard<std::mutex> g(lock);
    progress(++finished, total, what);
  });

  // In table order: a muscle that cannot reach its range is skipped, as one
  // lacking FDPs; an essential one fails the build.
  std::vector<const Status *> failed(model.muscles.size(), nullptr);
  for (size_t k = 0; k < todo.size(); ++k)
    if (!result[k]) failed[todo[k]] = &result[k];
  for (size_t i = 0; i < model.muscles.size(); ++i)
    if (failed[i] && table[static_cast<size_t>(model.muscles[i].def)].essential)
      return failed[i]->wrap("essential muscle");
  std::vector<Muscle> kept;
  for (size_t i = 0; i < model.muscles.size(); ++i) {
    const Muscle &m = model.muscles[i];
    if (failed[i]) {
      model.warnings.push_back(failed[i]->message() + ": skipped");
      continue;
    }
    for (bool maximum : {true, false}) {
      const double range = maximum ? m.range_max : m.range_min;
      if (range == 1) continue;
      const std::string side = maximum ? "+100" : "-100";
      const char *part = range == 0.5 ? "a half" : range == 0.25 ? "a quarter" : "an eighth";
      const int why = cut[i][maximum ? 1 : 0];
      const char *cause = why == 0   ? ": its tissue locks before the key node reaches"
                          : why == 3 ? ": the solver finds no equilibrium with the key node at"
                                     : ": the skin tears before the key node reaches";
      model.warnings.push_back(m.name + cause + " the table's " + side + " % (" +
                               std::to_string(std::abs(muscle_action_target(m, maximum)) / range) +
                               " model units): " + side + " % stands for " + part + " of it" +
                               (why == 2 ? ", where it still tears the skin" : ""));
    }
    kept.push_back(std::move(model.muscles[i]));
  }
  model.muscles = std::move(kept);
  if (!options.calibrate_jaw) return model;
  if (!jaw_pose) return jaw_pose.status().wrap("jaw");
  model.jaw.dynamic = jaw_pose->dynamic;
  model.jaw.open_response = displacement(jaw_pose->X, carried_rest(model, jaw_pose->jaw));
  return model;
}

namespace {

// Checks the contractions and gathers the union of the muscles' dynamic sets.
Status muscle_set(const FaceModel &model, const std::vector<std::pair<int, double>> &muscles, std::vector<int> &set) {
  for (const auto &[i, pct] : muscles) {
    if (i < 0 || i >= static_cast<int>(model.muscles.size()))
      return Status::error("pose: muscle index " + std::to_string(i) + " out of range");
    if (pct < -100 || pct > 100 || !std::isfinite(pct))
      return Status::error("pose: " + model.muscles[static_cast<size_t>(i)].name + " at " +
                           std::to_string(pct) + " %: contraction must be within -100..100");
    const Muscle &m = model.muscles[static_cast<size_t>(i)];
    if (pct != 0 && !(pct > 0 ? m.tension_max > 0 : m.tension_min > 0))
      return Status::error("pose: muscle " + m.name + " is not calibrated");
    join(set, m.dynamic.empty() ? m.influence : m.dynamic);
  }
  return Status::ok();
}

}  // namespace

Expected<Pose> solve_pose_to(const FaceModel &model, const std::vector<std::pair<int, double>> &pattern,
                             const PoseAction &action, double value, FactorCache *cache, double *scale,
                             double max_scale, bool *capped, const SteerFrom *from) {
  Pose pose;
  pose.X = model.tissue.X0;
  std::vector<int> set;
  if (Status s = muscle_set(model, pattern, set); !s) return s;
  if (set.empty()) return Status::error("pose: no muscle to scale");
  LoadControl control;
  control.unit_load = activation_forces(model, pattern);
  control.action = action;
  control.value = value;
  control.max_tension = max_scale;
  SolverOptions opts = model.solver;
  if (from && from->pose) {
    pose.X = from->pose->X;
    join(set, from->pose->dynamic);
    control.tension = from->scale;
  }
  if (from && from->max_iterations > 0) opts.max_iterations = from->max_iterations;
  FactorCache local;
  Status s = solve_growing(model, set, nullptr, model.tissue.X0, pose.X, opts, model.wave_threshold,
                           cache ? cache : &local, false, &pose.stats, &pose.rounds, &control);
  if (!s) return s.wrap("pose");
  if (scale) *scale = control.tension;
  if (capped) *capped = control.capped;
  pose.dynamic = std::move(set);
  return pose;
}

Status place_turned_lid(const FaceModel &model, const LidTurn &lid, Eigen::MatrixXd &X, std::vector<char> *held) {
  const SkinModel &skin = model.tissue;
  const int muscle = lid.muscle;
  const double angle = lid.angle;
  if (muscle < 0 || muscle >= static_cast<int>(model.muscles.size()))
    return Status::error("pose: muscle index " + std::to_string(muscle) + " out of range");
  const Muscle &m = model.muscles[static_cast<size_t>(muscle)];
  if (m.kind != MuscleKind::Lid || m.turn_share.size() != m.influence.size() || m.tarsus.size() != m.influence.size() ||
      m.eye < 0 || m.eye >= static_cast<int>(skin.eyes.size()) || !std::isfinite(angle) ||
      !(lid.clearance >= 0 && std::isfinite(lid.clearance)))
    return Status::error("pose: " + m.name + " is not a lid that turns");
  if (held) held->resize(static_cast<size_t>(skin.n), 0);
  std::vector<char> tarsus(static_cast<size_t>(skin.n), 0);
  for (size_t k = 0; k < m.influence.size(); ++k) {
    const Eigen::AngleAxisd turn(angle * m.turn_share[k], m.axis);
    const int v = m.influence[k];
    for (int l = 0; l < kSkull; ++l) {
      const int g = skin.node(l, v);
      X.row(g) = (m.epicentre + turn * (Eigen::Vector3d(X.row(g)) - m.epicentre)).transpose();
    }
    tarsus[static_cast<size_t>(v)] = m.tarsus[k];
  }
  if (held)
    for (int v = 0; v < skin.n; ++v) (*held)[static_cast<size_t>(v)] |= tarsus[static_cast<size_t>(v)];
  // The tarsus's epidermis as far off the eyeball as the solver holds free
  // skin (eye_clearance_in, over the tarsus's own edges: the skin around it
  // is not placed yet): the chords between its nodes stay outside the ball,
  // else the eye part shows through the shut lid.
  const EyeSphere &ball = skin.eyes[static_cast<size_t>(m.eye)];
  const Eigen::MatrixXd turned = X;
  for (int v = 0; v < skin.n; ++v) {
    if (!tarsus[static_cast<size_t>(v)] || skin.eye_near[static_cast<size_t>(v)] != m.eye) continue;
    const int g = skin.node(kEpidermis, v);
    const Eigen::Vector3d d = Eigen::Vector3d(turned.row(g)) - ball.centre;
    const double least = ball.radius + eye_clearance_in(skin, v, turned, &tarsus) + lid.clearance;
    if (d.norm() < least) X.row(g) = (ball.centre + d.normalized() * least).transpose();
  }
  return Status::ok();
}

namespace {

// The skin a jaw motion starts its solve on. An opening short of the full
// one: where the full opening's calibrated response, scaled to this one,
// moves a node more than half the wave threshold (the muscles' first guess,
// wave_estimate), with the jaw's vertices and followers, and a ring; the
// solve grows it where the wave reaches further. Song's full opening moves
// the whole skin, a viseme's third of it much less. Thrust, shift and the
// full opening: the full opening's set.
std::vector<int> jaw_set(const FaceModel &model, const Activation &a) {
  const Jaw &jaw = model.jaw;
  if (jaw.dynamic.empty()) return jaw.vertices;
  const double share = a.jaw_open / 100;
  if (a.jaw_thrust != 0 || a.jaw_shift != 0 || !(share < 1) || jaw.open_response.nodes.empty()) return jaw.dynamic;
  const SkinModel &skin = model.tissue;
  std::vector<int> out = jaw.vertices;
  for (const auto &[v, w] : jaw.followers) out.push_back(v);
  const NodeDisplacement &r = jaw.open_response;
  for (size_t k = 0; k < r.nodes.size(); ++k)
    if (share * r.displacement.row(static_cast<Eigen::Index>(k)).norm() > model.wave_threshold / 2)
      out.push_back(skin.vertex_of(r.nodes[k]));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return with_rings(skin, out, 1);
}

}  // namespace

Expected<Pose> solve_pose(const FaceModel &model, const Activation &a, FactorCache *cache,
                          const PoseOptions &options) {
  const SkinModel &skin = model.tissue;
  Pose pose;
  pose.X = skin.X0;
  std::vector<int> set;
  if (Status s = muscle_set(model, a.muscles, set); !s) return s;
  const bool jaw_moves = a.jaw_open != 0 || a.jaw_thrust != 0 || a.jaw_shift != 0;
  if (jaw_moves) {
    if (a.jaw_open < 0) return Status::error("pose: the jaw does not open by a negative amount");
    pose.jaw = jaw_motion(model.jaw, a.jaw_open, a.jaw_thrust, a.jaw_shift);
    pose.X = carried_rest(model, pose.jaw);
    join(set, jaw_set(model, a));
  }
  const Eigen::MatrixXd reference = pose.X;  // the rest state, carried by the jaw
  // Turned lids: the whole area turned by its shares is the first guess (a
  // start given replaces it), the tarsus is placed and held.
  std::vector<char> held;
  std::vector<std::pair<int, Eigen::Vector3d>> placed;  // node, position
  for (const LidTurn &lid : a.lids) {
    Eigen::MatrixXd X = pose.X;
    if (Status st = place_turned_lid(model, lid, X, &held); !st) return st;
    const Muscle &m = model.muscles[static_cast<size_t>(lid.muscle)];
    join(set, m.dynamic.empty() ? m.influence : m.dynamic);
    for (int v : m.influence)
      for (int l = 0; l < kSkull; ++l) {
        const int g = skin.node(l, v);
        pose.X.row(g) = X.row(g);
        if (held[static_cast<size_t>(v)]) placed.emplace_back(g, X.row(g).transpose());
      }
  }
  if (const Pose *from = options.start) {
    // Its free nodes as the first guess; the skull nodes (fixed) stay this
    // pose's own, exactly.
    join(set, from->dynamic);
    // Carried from its jaw motion to this one's: the jaw's vertices whole,
    // the followers by their shares.
    const std::vector<double> share = jaw_shares(model.jaw, skin.n);
    for (int v : from->dynamic) {
      const double w = share[static_cast<size_t>(v)];
      const Eigen::Affine3d carry = w == 0 ? Eigen::Affine3d::Identity()
                                  : w == 1 ? pose.jaw * from->jaw.inverse()
                                           : jaw_share(model.jaw, pose.jaw, w) * jaw_share(model.jaw, from->jaw, w).inverse();
      for (int l = 0; l < kSkull; ++l) {
        const int g = skin.node(l, v);
        pose.X.row(g) = (carry * Eigen::Vector3d(from->X.row(g).transpose())).transpose();
      }
    }
  }
  for (const auto &[g, x] : placed) pose.X.row(g) = x.transpose();
  if (set.empty() && !options.whole_mesh) return pose;
  const SolverOptions &opts = options.solver ? *options.solver : model.solver;
  FactorCache local;
  Status s = solve_growing(model, set, activation_forces(model, a.muscles), reference, pose.X, opts,
                           model.wave_threshold, cache ? cache : &local,
                           options.whole_mesh, &pose.stats, &pose.rounds, nullptr, held.empty() ? nullptr : &held);
  if (!s) return s.wrap("pose");
  std::vector<int> moved;  // the held vertices moved too
  for (int v = 0; v < static_cast<int>(held.size()); ++v)
    if (held[static_cast<size_t>(v)]) moved.push_back(v);
  join(set, moved);
  pose.dynamic = std::move(set);
  return pose;
}

Eigen::MatrixXd pose_epidermis(const FaceModel &model, const Pose &pose) {
  return pose.X.topRows(model.tissue.n);
}

Pose superposed_pose(const FaceModel &model, const Activation &a) {
  Pose out;
  auto add = [&out](const NodeDisplacement &r, double share, const std::vector<int> &set) {
    for (size_t k = 0; k < r.nodes.size(); ++k)
      out.X.row(r.nodes[k]) += share * r.displacement.row(static_cast<Eigen::Index>(k));
    join(out.dynamic, set);
  };
  const bool jaw_moves = a.jaw_open != 0 || a.jaw_thrust != 0 || a.jaw_shift != 0;
  if (jaw_moves) out.jaw = jaw_motion(model.jaw, a.jaw_open, a.jaw_thrust, a.jaw_shift);
  out.X = jaw_moves ? carried_rest(model, out.jaw) : model.tissue.X0;
  if (jaw_moves) add(model.jaw.open_response, std::max(a.jaw_open, 0.0) / 100, jaw_set(model, a));
  for (const auto &[i, pct] : a.muscles) {
    if (i < 0 || i >= static_cast<int>(model.muscles.size()) || pct == 0) continue;
    const Muscle &m = model.muscles[static_cast<size_t>(i)];
    add(pct > 0 ? m.response_max : m.response_min, std::abs(pct) / 100, m.dynamic.empty() ? m.influence : m.dynamic);
  }
  return out;
}

namespace {

Eigen::Vector3d face_normal(const Eigen::MatrixXd &X, const Eigen::MatrixXi &F, Eigen::Index f) {
  const Eigen::Vector3d a = X.row(F(f, 0)), b = X.row(F(f, 1)), c = X.row(F(f, 2));
  return (b - a).cross(c - a);
}

}  // namespace

RestFaces rest_faces(const Eigen::MatrixXd &V0, const Eigen::MatrixXi &F) {
  RestFaces r;
  r.normal.resize(static_cast<size_t>(F.rows()));
  r.length.resize(F.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d n = face_normal(V0, F, f);
    r.normal[static_cast<size_t>(f)] = n;
    r.length(f) = n.norm();
    r.total += r.length(f);
  }
  return r;
}

std::vector<int> turned_faces(const RestFaces &rest, const Eigen::MatrixXi &F, const Eigen::MatrixXd &V,
                              double *share) {
  const double mean = rest.total / std::max<double>(1, static_cast<double>(F.rows()));
  std::vector<int> out;
  double turned = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    if (rest.length(f) > 1e-3 * mean && rest.normal[static_cast<size_t>(f)].dot(face_normal(V, F, f)) <= 0) {
      out.push_back(static_cast<int>(f));
      turned += rest.length(f);
    }
  }
  if (share) *share = rest.total > 0 ? turned / rest.total : 0;
  return out;
}

std::vector<int> turned_faces(const Eigen::MatrixXd &V0, const Eigen::MatrixXi &F, const Eigen::MatrixXd &V,
                              double *share) {
  return turned_faces(rest_faces(V0, F), F, V, share);
}

SkinFaults skin_faults(const FaceModel &model, const Eigen::MatrixXd &E) {
  const SkinModel &s = model.tissue;
  SkinFaults out;
  const Eigen::MatrixXd X0 = s.X0.topRows(s.n);
  out.turned_faces = turned_faces(X0, s.F, E, &out.turned_share);
  double total = 0, stretched = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const double a0 = face_normal(X0, s.F, f).norm();
    total += a0;
    if (face_normal(E, s.F, f).norm() > kTearStretch * a0) {
      out.stretched_faces.push_back(static_cast<int>(f));
      stretched += a0;
    }
  }
  out.stretched_share = total > 0 ? stretched / total : 0;
  // The jaw's bone moves under its vertices and, in part, its followers'.
  const std::vector<double> on_jaw = jaw_shares(model.jaw, s.n);
  for (int v = 0; v < s.n; ++v) {
    if (on_jaw[static_cast<size_t>(v)] > 0 || !s.in_mesh[static_cast<size_t>(v)] || !skull_rejects(s, v)) continue;
    const Eigen::Vector3d skull = s.X0.row(s.node(kSkull, v));
    if ((E.row(v).transpose() - skull).dot(s.normal.row(v).transpose()) < -model.quantum) out.sunk_vertices.push_back(v);
  }
  return out;
}

}  // namespace afmb
