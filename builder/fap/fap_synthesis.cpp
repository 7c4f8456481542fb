#include "fap/fap_synthesis.h"

#include <afm/mpeg4.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <tuple>

#include "afm/rigid_parts.h"
#include "anatomy/pupil.h"
#include "anatomy/skin_binding.h"
#include "anatomy/tongue.h"
#include "core/fapu.h"
#include "core/parallel.h"
#include "core/part_kind.h"
#include "fap/fap_mapping.h"
#include "fap/fap_partition.h"
#include "fap/jaw_lips.h"
#include "fap/steer.h"
#include "fap/teeth_clearance.h"
#include "fap/untangle.h"

namespace afmb {

namespace {

// Newton iterations allowed to a solve beyond the calibrated range: where
// the tissue locks it would take hundreds (Song's lower eyelids).
constexpr int kBeyondIterations = 40;
// Steps along the chord from the pose at the calibrated range to one beyond
// it that folds the skin, to guess where the poses between start to fold,
// and the share of the unfolded part of the chord that the solve short of
// the fold goes to.
constexpr int kChordSteps = 16;
constexpr double kChordShare = 0.75;
// Where the solve short of the fold is still short of the FAP's value, the
// solves that halve the gap between it and the fold, each from the last
// pose that stays a face (seventy-fifth session: the 2k head's brows
// squeezed 82 -> 95 % of their reference, drawn apart 72 -> 80 %; the 10k
// head's outer lower lip raised 75 -> 87 %, its lower lids lowered 74 -> 86 %;
// Song's middle brow lowered 97 -> 99 %; Newton iterations after the model
// +1.2 % on Song, +2.7 % and +12 % on the 2k and 10k heads).
constexpr int kFoldBisections = 2;
// Bisection steps on the share of a viseme's or expression's pose that
// keeps the skin a face: to a sixteenth.
constexpr int kShareSteps = 4;
// "reaches N % of the prescribed motion: why", reached a share (0..1).
std::string reaches_message(double reached, const std::string &why) {
  char pct[32];
  std::snprintf(pct, sizeof pct, "%.0f %%", 100 * reached);
  return std::string("reaches ") + pct + " of the prescribed motion: " + why;
}

// The left twin's name of a right FAP ("raise_r_cornerlip",
// "lower_t_lip_rm"), else "".
std::string left_fap_name(const std::string &name) {
  for (const char *right : {"_r_", "_rm"})
    if (const size_t at = name.find(right); at != std::string::npos)
      return name.substr(0, at) + (right[2] == 'm' ? "_lm" : "_l_") + name.substr(at + 3);
  return std::string();
}

// The muscles of activation `a` to blame for `faults` (one flag per
// a.muscles entry, then one for the jaw): those whose influence area holds a
// sunk vertex or a corner of the largest turned or stretched triangles, as
// many as leave the rest of each under kTornShare (the slivers a smile turns
// at the mouth corners blame nothing), with their other side's twin, so
// that a reduced expression stays symmetric. A turned triangle of the lifted
// skin stands for the coarse vertices its corners are bound to (`sim`).
std::vector<char> blame(const FaceModel &model, const Activation &a, const SkinFaults &faults, const SimMesh *sim) {
  const SkinModel &skin = model.tissue;
  std::vector<char> hit(static_cast<size_t>(skin.n), 0);
  // `faces` of (V, F), largest first, until the rest is under kTornShare;
  // `mark` takes each one's corners.
  auto take = [](const std::vector<int> &faces, const Eigen::MatrixXd &V, const Eigen::MatrixXi &F,
                 const std::function<void(int)> &mark) {
    auto area = [&](int f) {
      const Eigen::Vector3d p = V.row(F(f, 0)), q = V.row(F(f, 1)), r = V.row(F(f, 2));
      return (q - p).cross(r - p).norm();
    };
    double total = 0;
    for (Eigen::Index f = 0; f < F.rows(); ++f) total += area(static_cast<int>(f));
    std::vector<int> order = faces;
    std::stable_sort(order.begin(), order.end(), [&area](int f, int g) { return area(f) > area(g); });
    double rest = 0;  // twice the area left unblamed
    for (int f : order) rest += area(f);
    for (int f : order) {
      if (rest <= kTornShare * total) break;
      for (int k = 0; k < 3; ++k) mark(F(f, k));
      rest -= area(f);
    }
  };
  const Eigen::MatrixXd X0 = skin.X0.topRows(skin.n);
  auto mark = [&hit](int v) { hit[static_cast<size_t>(v)] = 1; };
  take(faults.turned_faces, X0, skin.F, mark);
  take(faults.stretched_faces, X0, skin.F, mark);
  for (int v : faults.sunk_vertices) mark(v);
  if (sim)
    take(faults.lifted_turned_faces, sim->skin_V, sim->skin_F, [&](int v) {
      for (int j = 0; j < 3; ++j) mark(sim->binding.corner(v, j));
    });
  std::vector<char> out(a.muscles.size() + 1, 0);
  auto any_hit = [&hit](const std::vector<int> &vertices) {
    for (int v : vertices)
      if (hit[static_cast<size_t>(v)]) return true;
    return false;
  };
  for (size_t k = 0; k < a.muscles.size(); ++k)
    out[k] = any_hit(model.muscles[static_cast<size_t>(a.muscles[k].first)].influence);
  out.back() = a.jaw_open != 0 && any_hit(model.jaw.vertices);
  const std::vector<char> direct = out;
  for (size_t k = 0; k < a.muscles.size(); ++k) {
    if (!direct[k]) continue;
    const std::string other = twin_name(model.muscles[static_cast<size_t>(a.muscles[k].first)].name);
    for (size_t j = 0; j < a.muscles.size(); ++j)
      if (model.muscles[static_cast<size_t>(a.muscles[j].first)].name == other) out[j] = 1;
  }
  return out;
}

// The muscles `reduced` marks, for a message: "orbicularis_oculi" for both
// sides of one, "jaw" for the jaw.
std::string muscle_list(const FaceModel &model, const Activation &a, const std::vector<char> &reduced) {
  std::vector<std::string> names;
  for (size_t k = 0; k < a.muscles.size(); ++k) {
    if (!reduced[k]) continue;
    std::string n = model.muscles[static_cast<size_t>(a.muscles[k].first)].name;
    const std::string other = twin_name(n);
    bool both = false;
    for (size_t j = 0; j < a.muscles.size() && !other.empty(); ++j)
      both |= reduced[j] && model.muscles[static_cast<size_t>(a.muscles[j].first)].name == other;
    if (both) n.erase(n.rfind('_'));
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  }
  if (reduced.back()) names.push_back("jaw");
  std::string out;
  for (const std::string &n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

bool is_jaw(FapDriver d) { return d == FapDriver::JawOpen || d == FapDriver::JawThrust || d == FapDriver::JawShift; }

// The jaw percentage that moves point p by `value` along `dir` (model units),
// by bisection on the rigid motion: the chin is carried by the jaw.
double jaw_percent(const Jaw &jaw, FapDriver d, const Eigen::Vector3d &p, const Eigen::Vector3d &dir, double value) {
  auto along = [&](double pct) {
    const Eigen::Affine3d t = jaw_motion(jaw, d == FapDriver::JawOpen ? pct : 0, d == FapDriver::JawThrust ? pct : 0,
                                         d == FapDriver::JawShift ? pct : 0);
    return (t * p - p).dot(dir);
  };
  // Translations are linear in the percentage, and may run either way.
  const double sign = d == FapDriver::JawOpen || along(1) >= 0 ? 1.0 : -1.0;
  double lo = 0, hi = 100;
  while (along(sign * hi) < value && hi < 1e4) hi *= 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (along(sign * mid) < value ? lo : hi) = mid;
  }
  return sign * 0.5 * (lo + hi);
}

std::string fap_label(int fap, int side) {
  const afm_fap_info *info = afm_fap(fap);
  return std::string(info ? info->name : "fap") + (side < 0 ? " (negative)" : "");
}

// Whether the model has every muscle of group g.
bool complete_group(const FaceModel &model, const std::vector<FapContraction> &g) {
  for (const FapContraction &c : g)
    if (model.find(c.muscle) < 0) return false;
  return true;
}

// A FAP side's second group (fap_mapping.h), where the model has it: else
// empty.
const std::vector<FapContraction> &second_group(const FaceModel &model, const FapMapping &map, int side) {
  static const std::vector<FapContraction> none;
  const std::vector<FapContraction> &g = side > 0 ? map.second_positive : map.second_negative;
  return complete_group(model, g) ? g : none;
}

// The group a FAP's side acts through: its own, or its fallback when the
// model lacks one of its own muscles and has every fallback muscle
// (fap_mapping.h). *fallback tells which. With `second`, its second group.
const std::vector<FapContraction> &fap_group(const FaceModel &model, const FapMapping &map, int side,
                                             bool *fallback = nullptr, bool second = false) {
  if (fallback) *fallback = false;
  if (second) return second_group(model, map, side);
  const std::vector<FapContraction> &own = side > 0 ? map.positive : map.negative;
  const std::vector<FapContraction> &alt = side > 0 ? map.fallback_positive : map.fallback_negative;
  const bool use_alt = !complete_group(model, own) && !alt.empty() && complete_group(model, alt);
  if (fallback) *fallback = use_alt;
  return use_alt ? alt : own;
}

// An eyelid FAP's closing side can be made by turning its lid as a whole
// (Activation::lids): the lid driver of the FAP's own group, where the model
// has it with the FDP's vertex on its tarsus; muscle -1: not so.
struct LidFap {
  int muscle = -1;
  double share = 0;  // the FDP vertex's Muscle::turn_share
};
LidFap lid_fap(const FaceModel &model, const FapMapping &map, int side, int vertex) {
  LidFap out;
  if (!map.lid || side < 0 || map.positive.size() != 1) return out;
  const int i = model.find(map.positive[0].muscle);
  if (i < 0) return out;
  const Muscle &m = model.muscles[static_cast<size_t>(i)];
  if (m.kind != MuscleKind::Lid || m.turn_share.size() != m.influence.size()) return out;
  const auto at = std::lower_bound(m.influence.begin(), m.influence.end(), vertex);
  if (at == m.influence.end() || *at != vertex) return out;
  const size_t k = static_cast<size_t>(at - m.influence.begin());
  if (!m.tarsus[k] || !(m.turn_share[k] > 0)) return out;
  out.muscle = i;
  out.share = m.turn_share[k];
  return out;
}

// Eyelid FAPs: weights the rows of D (#V x 3) by the lid's half (fap_mapping.h):
// a smooth step in height across the lids' opening, 1 at the lid's centre.
void keep_lid_half(const FaceModel &model, int fap, int lid, Eigen::MatrixXd &D) {
  const bool left = fap == 19 || fap == 21;
  const FdpPoint *up = model.fdps.find(FdpId{3, left ? 1 : 2}, model.skin);
  const FdpPoint *down = model.fdps.find(FdpId{3, left ? 3 : 4}, model.skin);
  if (!up || !down || up->vertex < 0 || down->vertex < 0) return;
  const double y_up = model.tissue.X0(up->vertex, 1), y_down = model.tissue.X0(down->vertex, 1);
  const double mid = 0.5 * (y_up + y_down), open = std::max(std::abs(y_up - y_down), 1e-12);
  for (Eigen::Index v = 0; v < D.rows(); ++v) {
    const double s = std::clamp(lid * (model.tissue.X0(v, 1) - mid) / open + 0.5, 0.0, 1.0);
    D.row(v) *= s * s * (3 - 2 * s);
  }
}

// The errors of achieved FDP motion against o.prescribed, along the FAP's
// direction `dir` and off it.
// The skin vertex of FAP `info`'s FDP, or -1 when the FDP is not on the skin.
int fdp_vertex(const FaceModel &model, const afm_fap_info *info) {
  const FdpPoint *p = model.fdps.find(FdpId{info->fdp_group, info->fdp_index}, model.skin);
  return p && p->part == model.skin && p->vertex >= 0 ? p->vertex : -1;
}

// The lower lip's FAPs: its middle and mid-left/right, inner and outer.
bool lower_lip_fap(int fap) {
  return fap == 5 || fap == 10 || fap == 11 || fap == 52 || fap == 57 || fap == 58;
}

// The lip corners, inner (2.4, 2.5) and outer (8.3, 8.4).
bool lip_corner_fdp(const afm_fap_info *info) {
  return (info->fdp_group == 2 && (info->fdp_index == 4 || info->fdp_index == 5)) ||
         (info->fdp_group == 8 && (info->fdp_index == 3 || info->fdp_index == 4));
}

void measure(FapOutcome &o, const Eigen::Vector3d &achieved, const Eigen::Vector3d &dir) {
  o.achieved = achieved;
  const double len = o.prescribed.norm();
  const double a = o.achieved.dot(dir);
  o.along_error = std::abs(a - o.prescribed.dot(dir)) / len;
  const Eigen::Vector3d off = o.achieved - a * dir;
  o.off_axis = off.norm() / len;
  o.off_face = off.head<2>().norm() / len;
  o.off_depth = std::abs(off.z()) / len;
}

std::string high_level_label(const HighLevelMapping &h) {
  return h.expression ? std::string(afm_expression_name(h.number))
                      : "viseme " + std::string(afm_viseme_phonemes(h.number));
}

bool listed(const std::vector<int> &list, int n) { return std::find(list.begin(), list.end(), n) != list.end(); }

// Nothing listed in `options`: every FAP, viseme and expression is made.
bool lists_nothing(const FapSynthesisOptions &options) {
  return options.only.empty() && options.only_visemes.empty() && options.only_expressions.empty();
}

// Whether FAP `fap` is not listed in `options` but is the left twin of a
// listed one.
bool twin_of_listed(const FapSynthesisOptions &options, int fap) {
  if (listed(options.only, fap)) return false;
  for (int f : options.only)
    if (left_fap_name(afm_fap(f)->name) == afm_fap(fap)->name) return true;
  return false;
}

}  // namespace

CalibrationNeeds calibration_needs(const FapSynthesisOptions &options) {
  CalibrationNeeds need;
  need.all = lists_nothing(options);
  if (need.all) return need;
  need.jaw = false;
  auto add = [&need](const std::vector<FapContraction> &group) {
    for (const FapContraction &c : group)
      if (std::find(need.muscles.begin(), need.muscles.end(), c.muscle) == need.muscles.end())
        need.muscles.push_back(c.muscle);
  };
  for (const FapMapping &m : fap_mappings()) {
    if (!listed(options.only, m.fap) && !(m.driver == FapDriver::Muscles && twin_of_listed(options, m.fap))) continue;
    need.jaw |= m.driver == FapDriver::JawOpen || m.driver == FapDriver::JawThrust || m.driver == FapDriver::JawShift;
    if (m.driver != FapDriver::Muscles) continue;
    for (const auto *g : {&m.positive, &m.negative, &m.fallback_positive, &m.fallback_negative, &m.second_positive,
                          &m.second_negative})
      add(*g);
    for (const std::string &h : m.helpers)
      if (std::find(need.muscles.begin(), need.muscles.end(), h) == need.muscles.end()) need.muscles.push_back(h);
  }
  for (const HighLevelMapping &h : high_level_mappings()) {
    if (!listed(h.expression ? options.only_expressions : options.only_visemes, h.number)) continue;
    add(h.muscles);
    need.jaw |= h.jaw_open > 0;
  }
  // A right muscle calibrates from its left twin's poses (face_model.h).
  for (size_t i = 0, n = need.muscles.size(); i < n; ++i)
    if (right_side(need.muscles[i])) add({FapContraction{twin_name(need.muscles[i]), 0}});
  return need;
}

bool solved_fap_target(const FapOutcome &o) {
  return o.made && o.kind == AFM_TARGET_FAP && !kinematic_fap(o.number) && !o.from_jaw && !o.past_reference;
}

bool solved_own_pose(const FapOutcome &o) {
  return o.made && !o.holds && (o.kind == AFM_TARGET_VISEME || o.kind == AFM_TARGET_EXPRESSION || solved_fap_target(o));
}

Expected<FapSynthesis> synthesize_faps(const Scene &scene, const FaceModel &model, const FapSynthesisOptions &options) {
  if (model.skin < 0 || model.tissue.n == 0) return Status::error("FAP synthesis: the model has no skin");
  const SkinModel &skin = model.tissue;
  FapSynthesis out;
  // What is wrong with an epidermis as a face: on the model's skin, and on
  // the input's once lifted.
  const SimMesh *sim = options.sim && options.sim->decimated ? options.sim : nullptr;
  auto face_faults = [&model, &skin, sim](const Eigen::MatrixXd &E) {
    SkinFaults f = skin_faults(model, E);
    if (sim) f.lifted_turned_faces = lifted_turned_faces(*sim, E - skin.X0.topRows(skin.n), &f.lifted_turned_share);
    return f;
  };
  // A FAP's target is stored with its slivers untangled (untangle.h; below,
  // after the solves): the FAP's FDP keeps the motion it was measured by, and
  // the skin the solver holds off an eyeball is held (a patch of Song's
  // closing upper lid, moved affinely, left a hole in it; only a sliver's
  // corner there may move).
  const Eigen::MatrixXd rest = skin.X0.topRows(skin.n);
  std::vector<char> held(static_cast<size_t>(skin.n), kUntangleFree);
  for (int v = 0; v < skin.n; ++v)
    if (skin.eye_near[static_cast<size_t>(v)] >= 0) held[static_cast<size_t>(v)] = kUntangleHeld;
  auto target_hold = [&held](int fdp) {
    std::vector<char> hold = held;
    if (fdp >= 0) hold[static_cast<size_t>(fdp)] = kUntangleFixed;
    return hold;
  };
  // What is wrong with epidermis E as the target of the FAP whose FDP is
  // skin vertex `fdp`: its faults once untangled, as it would be stored. The
  // searches past a group's range judge a pose by it: judged by its raw
  // slivers, Song's nose wings narrowed stopped at 49 % of the reference and
  // its outer lower lip lowered at 88 %, each for a triangle or two the
  // untangling straightens. Not at the lip corners, which streams send
  // together with the jaw and every lip FAP: Song's corners stretched then
  // reached the reference (65 % before), and joy.fap, which sends them to
  // 1.6 times it with the corners raised, turned up to 3 triangles at them
  // in 31 of its 108 frames, none of the targets alone. Nor where the skin
  // sinks into the skull or stretches past a tear (SkinFaults::breaks):
  // that is no fold. Whole triangles turned are untangled too, however
  // much of the skin they cover: judged torn past kTornShare (as visemes
  // and expressions are, SkinFaults::tears), 1-6 triangles of the 2k head's
  // skin near the brow buckling stopped its brows drawn apart at 80 % of the
  // reference, and 2-21 below the 10k head's lower lip its outer lower lip
  // lowered at 64 %; poses further on, steered, turn none and reach it.
  std::vector<char> corner(static_cast<size_t>(skin.n), 0);
  for (int fap = 3; fap <= AFM_FAP_COUNT; ++fap)
    if (const afm_fap_info *info = afm_fap(fap); info && lip_corner_fdp(info))
      if (const int v = fdp_vertex(model, info); v >= 0) corner[static_cast<size_t>(v)] = 1;
  // (untangled_faults: the same with E's raw faults `f` at hand.)
  auto untangled_faults = [&](const Eigen::MatrixXd &E, int fdp, SkinFaults f) {
    if ((f.turned_faces.empty() && f.lifted_turned_faces.empty()) || f.breaks() ||
        (fdp >= 0 && corner[static_cast<size_t>(fdp)]))
      return f;
    Eigen::MatrixXd D = E - rest;
    untangle(rest, skin.F, target_hold(fdp), options.sim, D);
    return face_faults(rest + D);
  };
  auto target_faults = [&](const Eigen::MatrixXd &E, int fdp) { return untangled_faults(E, fdp, face_faults(E)); };

  // How far the input's skin, lifted from a coarse displacement Dc (#Vc x
  // 3), sinks below the clearance the solver would hold it at off the
  // eyeball of lid driver `muscle` (skin_model.h, rest_eye_clearance), among
  // its vertices bound to that lid's tarsus; model units, 0 when none does.
  // Empty without a simulation mesh.
  std::function<double(const Eigen::MatrixXd &, int)> lifted_eye;
  if (sim) {
    std::vector<uint8_t> used(static_cast<size_t>(sim->skin_V.rows()), 0);
    for (Eigen::Index f = 0; f < sim->skin_F.rows(); ++f)
      for (int j = 0; j < 3; ++j) used[static_cast<size_t>(sim->skin_F(f, j))] = 1;
    const std::vector<int8_t> near = near_eyeballs(sim->skin_V, used, skin.eyes);
    std::vector<double> longest(static_cast<size_t>(sim->skin_V.rows()), 0.0);
    for (Eigen::Index f = 0; f < sim->skin_F.rows(); ++f)
      for (int j = 0; j < 3; ++j) {
        const int u = sim->skin_F(f, j), w = sim->skin_F(f, (j + 1) % 3);
        const double l = (sim->skin_V.row(u) - sim->skin_V.row(w)).norm();
        longest[static_cast<size_t>(u)] = std::max(longest[static_cast<size_t>(u)], l);
        longest[static_cast<size_t>(w)] = std::max(longest[static_cast<size_t>(w)], l);
      }
    lifted_eye = [&model, &skin, sim, near, longest](const Eigen::MatrixXd &Dc, int muscle) {
      const Muscle &m = model.muscles[static_cast<size_t>(muscle)];
      std::vector<char> tarsus(static_cast<size_t>(skin.n), 0);
      for (size_t k = 0; k < m.influence.size(); ++k) tarsus[static_cast<size_t>(m.influence[k])] = m.tarsus[k];
      const EyeSphere &ball = skin.eyes[static_cast<size_t>(m.eye)];
      const Eigen::MatrixXd E = sim->skin_V + lift_displacement(*sim, Dc);
      double worst = 0;
      for (Eigen::Index v = 0; v < E.rows(); ++v) {
        if (near[static_cast<size_t>(v)] != m.eye) continue;
        bool bound = false;
        for (int j = 0; j < 3; ++j)
          bound = bound || (sim->binding.weight(v, j) > 0 && tarsus[static_cast<size_t>(sim->binding.corner(v, j))]);
        if (!bound) continue;
        const double gap = (sim->skin_V.row(v).transpose() - ball.centre).norm() - ball.radius;
        const double longest_v = longest[static_cast<size_t>(v)];
        const double clearance = rest_eye_clearance(gap, longest_v * longest_v, ball.radius);
        worst = std::max(worst, ball.radius + clearance - (E.row(v).transpose() - ball.centre).norm());
      }
      return worst;
    };
  }

  // The work list: a FAP's mapping and side, or a viseme's or an
  // expression's.
  struct Work {
    const FapMapping *fap = nullptr;
    const HighLevelMapping *high = nullptr;
    int side = +1;
    int reference = 0;        // FAP units along `side` (> 0)
    bool in_between = false;  // one of the mapping's `farther`
    bool hidden = false;      // made only as a listed right FAP's mirror twin, not kept
    bool second = false;      // made with the side's second group (fap_mapping.h)
  };
  const bool everything = lists_nothing(options);
  std::vector<Work> work;
  // A listed right FAP's left twin is made too where it is not listed, and
  // dropped after: the right one's target is then the one the whole AFM has
  // (see twin_of below).
  auto twin_listed = [&](const FapMapping &m) {
    return !everything && model.mirror.symmetric() && m.driver == FapDriver::Muscles && twin_of_listed(options, m.fap);
  };
  for (const FapMapping &m : fap_mappings()) {
    if (m.driver == FapDriver::Rigid || m.driver == FapDriver::None) continue;
    const bool hidden = twin_listed(m);
    if (!everything && !listed(options.only, m.fap) && !hidden) continue;
    work.push_back({&m, nullptr, +1, m.reference, false, hidden});
    for (int r : m.farther)
      if (!hidden) work.push_back({&m, nullptr, +1, r, true});
    const bool own_negative =
        !m.negative.empty() || (m.driver == FapDriver::Tongue && tongue_negative_target(m.fap));
    if (options.negative_sides && own_negative) work.push_back({&m, nullptr, -1, m.reference, false, hidden});
  }
  for (const HighLevelMapping &h : high_level_mappings())
    if (everything || listed(h.expression ? options.only_expressions : options.only_visemes, h.number))
      work.push_back({nullptr, &h, +1, 63});

  out.jaw.kind = AFM_RIGID_JAW;
  out.jaw.pivot = model.jaw.pivot;
  out.jaw.parts = scene.find_kinds({PartKind::TeethLower, PartKind::Tongue});
  // Lashes and lid strips ride on the skin (skin_binding.h).
  out.carried = bind_to_skin(scene, model.skin, PartKind::Eyelid);
  const std::vector<SkinBinding> &carried = out.carried;
  auto carry = [&carried](const Eigen::MatrixXd &D, MorphTarget &t) {
    for (const SkinBinding &b : carried) {
      Eigen::MatrixXd d = carried_displacement(b, D);
      if (d.size() > 0 && d.cwiseAbs().maxCoeff() > 0) t.displacement[static_cast<size_t>(b.part)] = std::move(d);
    }
  };

  // Each target is its own solve: workers take them in turn, and the results
  // are put together in the work list's order, so the output does not depend
  // on the number of workers.
  struct Result {
    FapOutcome outcome;
    std::optional<MorphTarget> target;
    std::vector<RigidSample> jaw;  // a jaw FAP's bone motion at its value (piecewise_controls)
  };
  std::vector<Result> results(work.size());
  // The tongue (anatomy/tongue.h), where the face has one with FDPs
  // 6.1-6.4: the tongue FAPs' own motion, exact at the FDP, and the visemes'.
  const Expected<Tongue> tongue = find_tongue(scene, model.fdps);
  // A viseme or an expression: the table's pose, once.
  auto make_high_level = [&](const HighLevelMapping &h, Result &res) {
    const auto start = std::chrono::steady_clock::now();
    FapOutcome o;
    o.kind = h.expression ? AFM_TARGET_EXPRESSION : AFM_TARGET_VISEME;
    o.number = h.number;
    o.reference = 63;
    Activation a;
    std::string missing;
    for (const FapContraction &c : h.muscles) {
      const int i = model.find(c.muscle);
      const Muscle *mu = i < 0 ? nullptr : &model.muscles[static_cast<size_t>(i)];
      if (!mu || !(c.percent > 0 ? mu->tension_max > 0 : mu->tension_min > 0))
        missing += (missing.empty() ? "" : ", ") + c.muscle;
      else
        a.muscles.push_back({i, c.percent});
    }
    if (!missing.empty()) o.message = "without " + missing + ": not in the model or not calibrated";
    // The tongue's and the pupils' own motions (HighLevelMapping::parts).
    std::vector<std::pair<int, int>> shape_tongue;
    std::vector<std::pair<Pupil, int>> pupils;
    for (const auto &[fap, value] : h.parts) {
      std::string without;
      if (is_tongue_fap(fap)) {
        if (tongue) shape_tongue.push_back({fap, value});
        else without = "the tongue: " + tongue.status().message();
      } else if (Expected<Pupil> p = find_pupil(scene, model.fdps, model.tissue.eyes, fap); !p) {
        without = "the pupil: " + p.status().message();
      } else if (!pupil_value_fits(*p, model.fapu, value)) {
        without = "the pupil: it would grow past its iris";
      } else {
        pupils.push_back({*p, value});
      }
      without = "without " + without;  // once per part: a viseme may send the tongue several FAPs
      if (without != "without " && o.message.find(without) == std::string::npos)
        o.message += std::string(o.message.empty() ? "" : "; ") + without;
    }
    Eigen::Affine3d jaw = Eigen::Affine3d::Identity();
    if (h.jaw_open > 0) {
      // The chin (2.1) drops by jaw_open FAP 3 units, as the bone carries it.
      const afm_fap_info *info = afm_fap(3);
      const FdpPoint *chin = model.fdps.find(FdpId{info->fdp_group, info->fdp_index}, model.skin);
      if (model.jaw.vertices.empty() || !chin || chin->vertex < 0) {
        o.message += std::string(o.message.empty() ? "" : "; ") + "without the jaw: the model has none";
      } else {
        const double unit = fapu_distance(model.fapu, info->unit) / 1024.0;
        a.jaw_open = jaw_percent(model.jaw, FapDriver::JawOpen, skin.X0.row(chin->vertex).transpose(),
                                 fap_direction(info), h.jaw_open * unit);
      }
    }
    if (a.muscles.empty() && a.jaw_open == 0) {
      o.message = "nothing to pose: " + o.message;
    } else {
      FactorCache cache;
      // Muscles of both lips act together here: the lips meet, not pass
      // into each other (SolverOptions::lip_contact).
      SolverOptions together = model.solver;
      together.lip_contact = true;
      // `reduced` marks the muscles (one per a.muscles entry, then the jaw)
      // that `share` scales; the others keep the table's contraction.
      // Each solve starts from `from` (a pose of a smaller share of the same
      // muscles), else from the muscles' and the jaw's calibrated poses added
      // (superposed_pose): half the Newton iterations of a start from rest.
      auto solve_share = [&](const std::vector<char> &reduced, double share, const Pose *from = nullptr) {
        Activation b = a;
        for (size_t k = 0; k < b.muscles.size(); ++k)
          if (reduced[k]) b.muscles[k].second *= share;
        if (reduced.back()) b.jaw_open *= share;
        const Pose guess = from ? Pose() : superposed_pose(model, b);
        PoseOptions po;
        po.start = from ? from : &guess;
        po.solver = &together;
        return solve_pose(model, b, &cache, po);
      };
      // The table's pose. Where it tears the skin (joy turned the crease at
      // Song's left eye's outer corner over), or turns triangles over that
      // the target, untangled as it is stored, would keep turned, the
      // largest share of the muscles to blame that does neither, by
      // bisection; of every muscle and the jaw when that fails. (Judged by
      // the tear alone, the 10k head's joy and fear were made at 94 and 88 %
      // and stored 2 triangles turned each, under the tear's share of the
      // skin: a crease below each eye's outer corner, and beside each inner
      // one.)
      auto torn = [&](const Pose &p, SkinFaults *faults = nullptr) {
        const Eigen::MatrixXd E = pose_epidermis(model, p);
        SkinFaults f = face_faults(E);
        const bool bad = f.tears() || (f.any() && untangled_faults(E, -1, f).any());
        if (faults) *faults = std::move(f);
        return bad;
      };
      const std::vector<char> all(a.muscles.size() + 1, 1);
      std::vector<char> reduced = all;
      double share = 1;
      Expected<Pose> pose = solve_share(all, 1);
      SkinFaults faults;
      if (pose && torn(*pose, &faults)) {
        auto bisect = [&](const std::vector<char> &which) -> std::optional<std::pair<double, Pose>> {
          double lo = 0, hi = 1;
          std::optional<Pose> kept;
          for (int step = 0; step < kShareSteps; ++step) {
            const double mid = 0.5 * (lo + hi);
            Expected<Pose> p = solve_share(which, mid, kept ? &*kept : nullptr);
            if (p && !torn(*p)) {
              lo = mid;
              kept = std::move(*p);
            } else {
              hi = mid;
            }
          }
          if (!kept) return std::nullopt;
          return std::make_pair(lo, std::move(*kept));
        };
        const std::vector<char> blamed = blame(model, a, faults, sim);
        std::optional<std::pair<double, Pose>> found;
        if (blamed != all && std::count(blamed.begin(), blamed.end(), 1) > 0) {
          found = bisect(blamed);
          if (found) reduced = blamed;
        }
        if (!found) found = bisect(all);
        char what[256];
        std::snprintf(what, sizeof what,
                      "the table's pose turns %.2g %% of the skin's area over, stretches %.2g %% beyond %g times "
                      "its area and sinks %d vertices into the skull",
                      100 * std::max(faults.turned_share, faults.lifted_turned_share), 100 * faults.stretched_share,
                      kTearStretch,
                      static_cast<int>(faults.sunk_vertices.size()));
        if (found) {
          share = found->first;
          pose = std::move(found->second);
          o.message += std::string(o.message.empty() ? "" : "; ") + std::string(what) + ": " +
                       (reduced == all ? std::string("made at") : muscle_list(model, a, reduced) + " at") + " " +
                       std::to_string(static_cast<int>(std::lround(100 * share))) + " % of it";
        } else {
          pose = Status::error(std::string(what) + ", and so does " +
                               std::to_string(static_cast<int>(std::lround(100 * std::ldexp(1.0, -kShareSteps)))) +
                               " % of it");
        }
      }
      if (!pose) {
        o.message = pose.status().message();
      } else {
        const Eigen::MatrixXd D = pose_epidermis(model, *pose) - skin.X0.topRows(skin.n);
        if (a.jaw_open != 0) jaw = jaw_motion(model.jaw, (reduced.back() ? share : 1) * a.jaw_open, 0, 0);
        o.made = true;
        o.largest = D.rowwise().norm().maxCoeff();
        o.dynamic = static_cast<int>(pose->dynamic.size());
        o.slabs = static_cast<int>(turned_slabs(model.tissue, pose->X).size());
        o.scale = share;
        MorphTarget t;
        t.kind = o.kind;
        t.number = h.number;
        t.reference = 63;
        t.displacement.assign(scene.parts.size(), Eigen::MatrixXd());
        t.displacement[static_cast<size_t>(model.skin)] = D;
        carry(D, t);
        // No rigid control serves FAP 1 or 2: the jaw's parts move in the
        // target itself, the tongue in its own shape first.
        Eigen::MatrixXd shaped;  // the tongue's displacement before the jaw's
        if (!shape_tongue.empty()) {
          const Eigen::MatrixXd &V = scene.parts[static_cast<size_t>(tongue->part)].V;
          shaped = Eigen::MatrixXd::Zero(V.rows(), 3);
          for (const auto &[fap, value] : shape_tongue)
            shaped += tongue_displacement(*tongue, V, model.fapu, fap, value);
          t.displacement[static_cast<size_t>(tongue->part)] = shaped;
        }
        for (const auto &[pupil, value] : pupils)
          t.displacement[static_cast<size_t>(pupil.part)] =
              pupil_displacement(pupil, scene.parts[static_cast<size_t>(pupil.part)].V, model.fapu, value);
        if (!jaw.matrix().isIdentity(0))
          for (int p : out.jaw.parts) {
            const Eigen::MatrixXd &V = scene.parts[static_cast<size_t>(p)].V;
            const bool own = shaped.size() > 0 && p == tongue->part;
            t.displacement[static_cast<size_t>(p)] = moved_points(jaw, own ? Eigen::MatrixXd(V + shaped) : V) - V;
          }
        res.target = std::move(t);
      }
    }
    o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    res.outcome = std::move(o);
  };
  // A tongue FAP: its own motion (anatomy/tongue.h), no solve.
  auto make_tongue = [&](const FapMapping &map, int side, int reference, Result &res) {
    FapOutcome &o = res.outcome;
    o.number = map.fap;
    o.side = side;
    o.reference = side * reference;
    if (!tongue) {
      o.message = tongue.status().message();
      return;
    }
    const afm_fap_info *info = afm_fap(map.fap);
    const double value = side * reference;
    if (map.fap == 45 && !(value * fapu_distance(model.fapu, info->unit) / 1024.0 > -0.5 * tongue->length)) {
      o.message = "the tongue would shorten by half or more";
      return;
    }
    const FdpPoint *fdp = model.fdps.find(FdpId{info->fdp_group, info->fdp_index}, tongue->part);
    const Eigen::MatrixXd &V = scene.parts[static_cast<size_t>(tongue->part)].V;
    const Eigen::MatrixXd D = tongue_displacement(*tongue, V, model.fapu, map.fap, value);
    o.prescribed = tongue_fdp_motion(*tongue, model.fapu, map.fap, value);
    // The roll's FDP turns: measured along the chord MPEG-4's angle gives it.
    const Eigen::Vector3d dir = map.fap == 47 ? o.prescribed.normalized() : Eigen::Vector3d(side * fap_direction(info));
    measure(o, D.row(fdp->vertex).transpose(), dir);
    o.largest = D.rowwise().norm().maxCoeff();
    o.made = true;
    MorphTarget t;
    t.kind = AFM_TARGET_FAP;
    t.number = map.fap;
    t.reference = o.reference;
    t.displacement.assign(scene.parts.size(), Eigen::MatrixXd());
    t.displacement[static_cast<size_t>(tongue->part)] = D;
    res.target = std::move(t);
  };
  // A pupil FAP: the eye part's pupil dilates (anatomy/pupil.h), no solve.
  // The FDP (the pupil's centre) stays: the outcome's prescribed and
  // achieved motions are the growth of the pupil's diameter, along x.
  auto make_pupil = [&](const FapMapping &map, int reference, Result &res) {
    FapOutcome &o = res.outcome;
    o.number = map.fap;
    o.reference = reference;
    const Expected<Pupil> pupil = find_pupil(scene, model.fdps, model.tissue.eyes, map.fap);
    if (!pupil) {
      o.message = pupil.status().message();
      return;
    }
    if (!pupil_value_fits(*pupil, model.fapu, reference)) {
      o.message = "the pupil would grow past its iris";
      return;
    }
    const Eigen::MatrixXd &V = scene.parts[static_cast<size_t>(pupil->part)].V;
    const Eigen::MatrixXd D = pupil_displacement(*pupil, V, model.fapu, reference);
    o.prescribed = reference * model.fapu.irisd0 / 1024 * Eigen::Vector3d::UnitX();
    const double grown = pupil_diameter(*pupil, V, V + D) - pupil_diameter(*pupil, V, V);
    measure(o, grown * Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX());
    o.largest = D.rowwise().norm().maxCoeff();
    o.made = true;
    MorphTarget t;
    t.kind = AFM_TARGET_FAP;
    t.number = map.fap;
    t.reference = reference;
    t.displacement.assign(scene.parts.size(), Eigen::MatrixXd());
    t.displacement[static_cast<size_t>(pupil->part)] = D;
    res.target = std::move(t);
  };
  // Mirror twins (anatomy/mirror.h). On a mirror-symmetric skin a right
  // FAP's target waits for its left twin's (same side, reference, driver
  // group mirrored) and, where the twin reached its value or stopped at its
  // cap short of it, starts from the twin's recipe: its group with the
  // helpers the steering kept, its scale and cap, and its pose mirrored. One
  // solve of a few Newton iterations instead of the search and the steering
  // rounds.
  struct Recipe {
    std::vector<std::pair<int, double>> pattern;  // the group and its helpers, percent before the scale
    double scale = 0, cap = 0;
    Pose pose;
    // The FDP's distance from the prescribed motion that counts, model
    // units: off the FAP's direction where the group reached its value, all
    // of it where it stopped at its cap short of the value (`capped`, with
    // `why` it stopped there).
    double miss = 0;
    bool faults = false;  // face_faults(...).any() of the pose
    bool capped = false;
    std::string why;
  };
  std::vector<int> twin_of(work.size(), -1);  // the left twin's work index (a first solve, see same_as)
  std::vector<char> has_twin(work.size(), 0);
  // The recipes of the own groups' solves and of the second groups'
  // (work[k].second): a right twin's second group starts from its left
  // twin's second recipe where the left one was made again too.
  std::vector<std::optional<Recipe>> recipes(work.size()), second_recipes(work.size());
  // Where a side is made again with its second group: its own group's result.
  std::vector<std::optional<Result>> own_group(work.size());
  auto miss_of = [&skin](const Pose &p, int vertex, const Eigen::Vector3d &along, double value, bool capped) {
    const int node = skin.node(kEpidermis, vertex);
    const Eigen::Vector3d m = (p.X.row(node) - skin.X0.row(node)).transpose();
    return capped ? (m - value * along).norm() : (m - m.dot(along) * along).norm();
  };
  // The recipe mirrored onto `pattern` (this side's group, which must be the
  // recipe's group mirrored), solved under the load control at the recipe's
  // cap. Kept (into `pose` and `o`; true) where it ends as the twin's did
  // (reaching the value, or at the cap short of it), turns no skin the
  // twin's did not, and misses the prescribed motion by at most kSteerGain
  // of the value more than the twin's (Recipe::miss).
  auto from_twin = [&](const Recipe &r, const std::vector<std::pair<int, double>> &pattern, const PoseAction &action,
                       double value, double unit_of, const Eigen::Vector3d &along, int vertex, FactorCache *cache,
                       Pose &pose, FapOutcome &o) {
    std::vector<std::pair<int, double>> with;
    for (const auto &[i, pct] : r.pattern) {
      const bool sided = !twin_name(model.muscles[static_cast<size_t>(i)].name).empty();
      const int j = sided ? model.twin(i) : i;
      if (j < 0) return false;
      with.push_back({j, pct});
    }
    if (with.size() < pattern.size() || !std::equal(pattern.begin(), pattern.end(), with.begin())) return false;
    Pose start;
    start.X = mirrored_nodes(model, r.pose.X);
    start.dynamic = mirrored_vertices(model, r.pose.dynamic);
    SteerFrom from;
    from.pose = &start;
    from.scale = r.scale;
    from.max_iterations = kBeyondIterations;
    double scale = 0;
    bool capped = false;
    Expected<Pose> q = solve_pose_to(model, with, action, value, cache, &scale, r.cap, &capped, &from);
    if (!q || capped != r.capped || miss_of(*q, vertex, along, value, r.capped) > r.miss + kSteerGain * value)
      return false;
    const double reach = action(q->X, nullptr);
    if (r.capped && !(reach >= unit_of && reach < value)) return false;
    if (!r.faults && target_faults(pose_epidermis(model, *q), vertex).any()) return false;
    pose = std::move(*q);
    o.scale = scale;
    o.mirrored = true;
    if (r.capped) {
      o.reached = reach / value;
      o.message = reaches_message(o.reached, r.why + " (its mirror twin's finding)");
    }
    std::string helpers;
    for (size_t h = pattern.size(); h < with.size(); ++h) {
      char b[96];
      std::snprintf(b, sizeof b, "%s%s %+.0f %%", helpers.empty() ? "" : ", ",
                    model.muscles[static_cast<size_t>(with[h].first)].name.c_str(), scale * with[h].second);
      helpers += b;
    }
    if (!helpers.empty()) {
      char b[64];
      std::snprintf(b, sizeof b, " (off-axis %.0f %%)", 100 * miss_of(pose, vertex, along, value, false) / value);
      o.message += (o.message.empty() ? "" : "; ") + ("steered as its mirror twin by " + helpers + b);
    }
    return true;
  };
  auto make = [&](size_t k) {
    Result &res = results[k];
    if (work[k].high) return make_high_level(*work[k].high, res);
    const FapMapping *map = work[k].fap;
    if (map->driver == FapDriver::Tongue) return make_tongue(*map, work[k].side, work[k].reference, res);
    if (map->driver == FapDriver::Pupil) return make_pupil(*map, work[k].reference, res);
    const int side = work[k].side, reference = work[k].reference;
    const auto start = std::chrono::steady_clock::now();
    const afm_fap_info *info = afm_fap(map->fap);
    FapOutcome o;
    o.number = map->fap;
    o.side = side;
    o.reference = side * reference;
    o.in_between = work[k].in_between;
    const Eigen::Vector3d dir = fap_direction(info);
    const double unit = fapu_distance(model.fapu, info->unit) / 1024.0;
    const double value = reference * unit;  // along side x dir
    bool fallback = false;  // the FAP acts through its fallback group
    o.prescribed = side * value * dir;
    const FdpPoint *fdp = model.fdps.find(FdpId{info->fdp_group, info->fdp_index}, model.skin);
    Pose pose;
    bool ok = false;
    double shrink = 1;  // on the target, when a capped pose lies just beyond the value
    // A closing lid turned as a whole (lid_fap). Where the driver could not
    // be calibrated to the table's range (its load turns the lid only so
    // far: the generated heads' lids open as wide as the iris, and Newton
    // found no equilibrium at their 50-degree turn), for every closing
    // target; elsewhere for an in-between the driver's load does not reach,
    // kept only where the skin stays a face.
    const LidFap lid = fdp && fdp->part == model.skin && fdp->vertex >= 0 ? lid_fap(model, *map, side, fdp->vertex)
                                                                           : LidFap();
    const bool lid_cut = lid.muscle >= 0 && model.muscles[static_cast<size_t>(lid.muscle)].range_max < 1;
    // The tarsus turned about the eyeball's centre until the FDP (on the
    // margin, held with the tarsus) has come down by the value; the lid
    // above follows through the tissue. The FDP's drop grows with the turn
    // until the FDP passes under the centre; the turn is found by bisection
    // on the placement itself. Whether a pose was made (into `pose`, with
    // `o` and `shrink`).
    auto turn_lid = [&](const LidFap &lf) -> bool {
      const int node = skin.node(kEpidermis, fdp->vertex);
      const Eigen::Vector3d along = side * dir;
      LidTurn turn;
      turn.muscle = lf.muscle;
      auto moved = [&](double angle) {
        Eigen::MatrixXd X = skin.X0;
        turn.angle = angle;
        if (!place_turned_lid(model, turn, X, nullptr)) return 0.0;
        return (X.row(node) - skin.X0.row(node)).dot(along.transpose());
      };
      // The first of 180 steps of the turn, up to where the lids meet, at
      // which the FDP has come down by the value, refined by bisection;
      // else the step that takes it furthest (`most`).
      double most = 0;
      const Muscle &driver = model.muscles[static_cast<size_t>(lf.muscle)];
      const double last = driver.closing_turn > 0 ? driver.closing_turn : M_PI / lf.share;
      auto find_turn = [&] {
        double lo = 0, best = 0;
        most = -std::numeric_limits<double>::infinity();
        for (int step = 1; step <= 180; ++step) {
          const double t = step * last / 180;
          const double d = moved(t);
          if (d >= value) {
            double hi = t;
            for (int halving = 0; halving < 60; ++halving) {
              const double mid = 0.5 * (lo + hi);
              (moved(mid) < value ? lo : hi) = mid;
            }
            most = value;
            return 0.5 * (lo + hi);
          }
          if (d > most) most = d, best = t;
          lo = t;
        }
        return best;
      };
      FactorCache cache;
      Expected<Pose> pz = Status::error("no pose");
      // On a simulation mesh, the input's skin over the eyeball is lifted by
      // blending its coarse triangle's corners' displacements: its offset
      // from the coarse triangle does not turn with the lid, and where the
      // lid has turned far, the lifted skin sinks toward the ball. One more
      // round holds the tarsus further off by what it sank.
      for (int round = 0; round < 2; ++round) {
        turn.angle = find_turn();
        Activation a;
        a.lids.push_back(turn);
        pz = solve_pose(model, a, &cache);
        if (!pz || !lifted_eye) break;
        const double sunk = lifted_eye(pose_epidermis(model, *pz) - skin.X0.topRows(skin.n), lf.muscle);
        if (!(sunk > 0)) break;
        turn.clearance += sunk;
      }
      o.scale = turn.angle;
      const int met = static_cast<int>(std::floor(most / unit));  // FAP units where the lids meet
      if (!pz) {
        o.message = pz.status().message();
        return false;
      }
      pose = std::move(*pz);
      o.reached = 1;
      o.message.clear();
      if (most < value && o.in_between && driver.closing_turn > 0 && met >= 1) {
        // The lids meet short of the in-between's value: the target is the
        // shut lid, at the value that shuts it (formats/afm.md: any
        // references will do), so that a stream reaching it shows the lid
        // shut and not a chord of the arc past it.
        shrink = met * unit / most;
        o.reference = side * met;
        o.prescribed = side * met * unit * dir;
        o.message = "the lids meet at " + std::to_string(met) + " (" +
                    std::to_string(static_cast<int>(std::lround(100.0 * met / reference))) + " % of " +
                    std::to_string(reference) + "): made there";
      } else if (most < value) {
        o.reached = std::max(most, 0.0) / value;
        o.message = "reaches " + std::to_string(static_cast<int>(std::lround(100 * o.reached))) +
                    " % of the prescribed motion: " +
                    (driver.closing_turn > 0 ? "there the lids meet" : "the margin's arc over the eyeball goes no further");
      }
      return true;
    };
    if (!fdp || fdp->part != model.skin || fdp->vertex < 0) {
      o.message = "its FDP " + std::to_string(info->fdp_group) + "." + std::to_string(info->fdp_index) +
                  " is not on the skin";
    } else if (is_jaw(map->driver)) {
      if (model.jaw.vertices.empty()) {
        o.message = "the model has no jaw";
      } else {
        const Eigen::Vector3d p = skin.X0.row(fdp->vertex).transpose();
        // The jaw moves the bone; the skin over it follows through the
        // tissue, a few percent short or beyond. So: the bone's motion at
        // the FDP first, then secant steps on the solved pose. Each round
        // starts from the pose of the largest motion solved so far that does
        // not pass its own, as the jaw loads the tissue (the first from the
        // calibrated opening scaled, superposed_pose): a few Newton
        // iterations instead of a solve from rest, and the rounds stay on one
        // branch where the tissue snaps through (at Song's chin the midline
        // buckles at 20 % open; rounds from rest landed on either side and the
        // secant did not converge).
        double pct = jaw_percent(model.jaw, map->driver, p, side * dir, value);
        FactorCache cache;
        Expected<Pose> pz = Status::error("no pose");
        std::vector<std::pair<double, Pose>> solved;  // |pct| and its pose
        double prev_pct = 0, prev_along = 0, posed = pct;
        for (int round = 0; round < 6; ++round) {
          posed = pct;
          Activation a;
          (map->driver == FapDriver::JawOpen    ? a.jaw_open
           : map->driver == FapDriver::JawThrust ? a.jaw_thrust
                                                 : a.jaw_shift) = pct;
          PoseOptions po;
          double from = -1;
          for (const auto &[at, q] : solved)
            if (at <= std::abs(pct) && at > from) po.start = &q, from = at;
          const Pose guess = po.start ? Pose() : superposed_pose(model, a);
          if (!po.start) po.start = &guess;
          pz = solve_pose(model, a, &cache, po);
          if (!pz) break;
          const double along = (pz->X.row(fdp->vertex) - skin.X0.row(fdp->vertex)).dot(side * dir.transpose());
          if (std::abs(along - value) <= model.solver.tolerance) break;
          solved.emplace_back(std::abs(pct), *pz);
          const double next = prev_along != along ? pct + (value - along) * (pct - prev_pct) / (along - prev_along)
                                                  : pct * value / along;
          prev_pct = pct, prev_along = along;
          pct = next;
        }
        pct = posed;  // the pose's own
        o.scale = pct / 100.0;
        if (!pz) {
          o.message = pz.status().message();
        } else {
          pose = std::move(*pz);
          ok = true;
          // The bone's motion at this value (an in-between's too: the
          // controls bend there, piecewise_controls below), for the jaw's
          // rigid parts.
          const double s = pct / 100.0;
          if (side > 0 && map->driver == FapDriver::JawOpen) {
            res.jaw.push_back({map->fap, AFM_DOF_ROTATE_X, reference, s * model.jaw.max_open / 1e-5});  // AU
            // The condyles' glide (jaw.h): a second control on the same FAP.
            if (s * model.jaw.open_glide > 0)
              res.jaw.push_back({map->fap, AFM_DOF_TRANSLATE_Z, reference, s * model.jaw.open_glide});
          } else if (side > 0) {
            const bool thrust = map->driver == FapDriver::JawThrust;
            res.jaw.push_back({map->fap, thrust ? AFM_DOF_TRANSLATE_Z : AFM_DOF_TRANSLATE_X, reference,
                               s * (thrust ? model.jaw.max_thrust : model.jaw.max_shift)});
          }
        }
      }
    } else if (lid_cut) {
      ok = turn_lid(lid);
    } else {
      std::vector<std::pair<int, double>> pattern;
      std::string missing;
      for (const FapContraction &c : fap_group(model, *map, side, &fallback, work[k].second)) {
        const int i = model.find(c.muscle);
        if (i < 0) missing += (missing.empty() ? "" : ", ") + c.muscle;
        else pattern.push_back({i, c.percent});
      }
      if (!missing.empty()) {
        o.message = "the model lacks " + missing + " (skipped when the model was built)";
      } else {
        const int node = skin.node(kEpidermis, fdp->vertex);
        const Eigen::Vector3d along = side * dir;
        PoseAction action = [&skin, node, along](const Eigen::MatrixXd &X, Eigen::MatrixXd *g) {
          if (g) g->row(node) += along.transpose();
          return (X.row(node) - skin.X0.row(node)).dot(along.transpose());
        };
        FactorCache cache;
        // A right FAP whose left twin left a recipe: that mirrored first
        // (from_twin). Else, or where that pose is worse than the twin's, the
        // target is made as any other.
        // (Read only for a right FAP: its left twin's task has finished.)
        if (const int tw = twin_of[k]; tw >= 0) {
          const size_t t = static_cast<size_t>(tw);
          const std::optional<Recipe> &twin_recipe = work[k].second && own_group[t] ? second_recipes[t] : recipes[t];
          if (twin_recipe)
            ok = from_twin(*twin_recipe, pattern, action, value, unit, along, fdp->vertex, &cache, pose, o);
        }
        if (!ok) {
          double scale = 0;
          bool capped = false;
          // Within the calibrated range first (s <= 1). A group that falls
          // short there may pass it, its tensions extrapolated up to
          // kMaxFapScale, in one more solve from the pose at s = 1 with a
          // budget of Newton iterations; that pose is kept only if the skin
          // stays a face. Where the skin already folds at s = 1, no more solve:
          // on Song all 12 such groups folded beyond too, at about 18 Newton
          // iterations each.
          double cap = 1;
          // The first guess: the muscles' calibrated poses added, scaled by the
          // share that would bring the FDP to the value if the tissue were
          // linear (within the range).
          Activation group;
          group.muscles = pattern;
          const Pose sum = superposed_pose(model, group);
          const double sum_action = action(sum.X, nullptr);
          Pose guess = sum;
          SteerFrom first;
          if (sum_action > 0) {
            first.scale = std::clamp(value / sum_action, 1.0 / 16, cap);
            guess.X = skin.X0 + first.scale * (sum.X - skin.X0);
            first.pose = &guess;
          }
          Expected<Pose> pz = solve_pose_to(model, pattern, action, value, &cache, &scale, cap, &capped,
                                            first.pose ? &first : nullptr);
          std::string beyond_why;  // why the group stayed within its range
          if (pz && capped && target_faults(pose_epidermis(model, *pz), fdp->vertex).any()) {
            beyond_why = "the skin folds or sinks into the skull already at them";
          } else if (pz && capped && action(pz->X, nullptr) <= 0) {
            // The load control steers an action that grows with the load; one
            // that fell at the range cannot be steered past it (Song's FAP 17:
            // 40 Newton iterations, then a failed solve, 2.4 s of 34 s on one
            // worker).
            beyond_why = "beyond them nothing is tried: at them the FDP moves the wrong way";
          } else if (pz && capped && action(pz->X, nullptr) < unit) {
            // A group that moves its FDP less than a FAP unit at its range
            // makes no target past it either (Song's FAP 64: 2 % of the
            // reference at the range, then 0.7 s of CPU in two failed solves).
            beyond_why = "beyond them nothing is tried: at them the FDP moves less than a FAP unit";
          } else if (pz && capped) {
            // From the pose at s = 1, within kBeyondIterations, s up to `up_to`.
            auto past_range = [&](double up_to, double *s_out, bool *capped_out) {
              SteerFrom from;
              from.pose = &*pz;
              from.scale = scale;
              from.max_iterations = kBeyondIterations;
              return solve_pose_to(model, pattern, action, value, &cache, s_out, up_to, capped_out, &from);
            };
            double s2 = 0;
            bool capped2 = false;
            Expected<Pose> beyond = past_range(kMaxFapScale, &s2, &capped2);
            if (!beyond) {
              beyond_why = "beyond it the solve fails";
            } else if (target_faults(pose_epidermis(model, *beyond), fdp->vertex).any()) {
              // Short of the fold there may be a face. Where the chord from
              // the pose at s = 1 to the folding one first folds guesses where
              // the poses between do; one solve goes to 3/4 of that share of
              // the way (s capped there, from the pose at s = 1). On Song, 9 %
              // more Newton iterations for the whole AFM; to the whole share,
              // then half of it where that folded, 17 % and less found; three
              // bisection steps from the middle, a third more time. Not for a
              // group that moves its FDP less than a FAP unit at s = 1:
              // beyond, such a group moved Song's upper lip 6 times as far off
              // the FAP's direction as along it.
              beyond_why = "beyond it the skin folds or sinks into the skull";
              if (action(pz->X, nullptr) >= unit) {
                const Eigen::MatrixXd E1 = pose_epidermis(model, *pz), E2 = pose_epidermis(model, *beyond);
                int steps = kChordSteps;  // of the chord that stay a face, at most
                while (steps > 1 && target_faults(E1 + (steps * 1.0 / kChordSteps) * (E2 - E1), fdp->vertex).any())
                  --steps;
                const double share = kChordShare * steps / kChordSteps;
                double s3 = 0;
                bool capped3 = false;
                Expected<Pose> p = past_range(scale + share * (s2 - scale), &s3, &capped3);
                if (p && !target_faults(pose_epidermis(model, *p), fdp->vertex).any()) {
                  pz = std::move(p);
                  scale = cap = s3;
                  double fold = s2;  // the least scale known to fold (kFoldBisections)
                  for (int b = 0; b < kFoldBisections && capped3; ++b) {
                    double s5 = 0;
                    bool capped5 = false;
                    Expected<Pose> q = past_range(0.5 * (scale + fold), &s5, &capped5);
                    if (q && !target_faults(pose_epidermis(model, *q), fdp->vertex).any()) {
                      pz = std::move(q);
                      scale = cap = s5;
                      capped3 = capped5;
                    } else {
                      fold = 0.5 * (scale + fold);
                    }
                  }
                  char why[96];
                  std::snprintf(why, sizeof why, "at %.2g times them the skin folds or sinks into the skull", fold);
                  beyond_why = why;
                }
              }
            } else {
              pz = std::move(beyond);
              scale = s2, capped = capped2, cap = kMaxFapScale;
              if (capped) {
                // Still short at the cap, the skin a face: once more from
                // there, up to kFurtherFapScale.
                double s4 = 0;
                bool capped4 = false;
                Expected<Pose> further = past_range(kFurtherFapScale, &s4, &capped4);
                if (further && !target_faults(pose_epidermis(model, *further), fdp->vertex).any()) {
                  pz = std::move(further);
                  scale = s4, capped = capped4, cap = kFurtherFapScale;
                }
              }
            }
          }
          // Where the group's pose drifts off the FAP's direction, helpers
          // steer the FDP back (steer.h). Not on a fallback group.
          std::string steered;
          std::vector<std::pair<int, double>> steered_pattern = pattern;
          // Judged by their raw skin (target_faults above): steered into
          // slivers the untangling straightens, Song's upper lip sides
          // summed in joy.fap's frames to a turned triangle at the corner.
          if (pz && !fallback && !map->helpers.empty() && options.steer)
            steered = steer_group(model, map->helpers, pattern, fdp->vertex, side * dir, action, value, cap, &cache,
                                  face_faults, *pz, scale, capped, &steered_pattern);
          if (pz && !capped) {
            pose = std::move(*pz);
            o.scale = scale;
            ok = true;
            if (has_twin[k] && !fallback)
              (work[k].second ? second_recipes : recipes)[k] =
                  Recipe{steered_pattern, scale, cap, pose, miss_of(pose, fdp->vertex, along, value, false),
                         target_faults(pose_epidermis(model, pose), fdp->vertex).any(), false, std::string()};
          } else {
            // The target is then the most the group does at the cap. Where
            // the load control failed (the FDP moves the wrong way), a plain
            // pose says how far and which way.
            const std::string why = !pz                 ? pz.status().message()
                                    : !beyond_why.empty() ? "the table's contractions reach less, and " + beyond_why
                                                          : "the group reaches less at " +
                                                                std::to_string(static_cast<int>(cap)) +
                                                                " times the table's contractions";
            const bool at_cap = static_cast<bool>(pz);
            Expected<Pose> full = std::move(pz);
            if (!full) {
              Activation a;
              a.muscles = pattern;
              PoseOptions po;
              po.start = &sum;
              full = solve_pose(model, a, &cache, po);
            }
            if (!full) {
              o.message = full.status().message();
            } else {
              const double reach = action(full->X, nullptr);
              const int r = static_cast<int>(std::floor(reach / unit));
              if (r < 1) {
                o.message = reach <= 0 ? "the group moves the FDP the wrong way"
                                       : "the group moves the FDP less than a FAP unit";
                o.message += " (reference " + std::to_string(reference) + ": " + why + ")";
              } else {
                // Kept at the table's reference: the target is the most the
                // group does, so streams at the reference see the muscles at
                // their range instead of a small target extrapolated many times.
                pose = std::move(*full);
                o.scale = at_cap ? cap : 1;
                if (reach >= value) {
                  // The load control stopped at the cap just short of the value,
                  // and the equilibrium there lies beyond it: scale the few
                  // percent back.
                  shrink = value / reach;
                } else {
                  o.reached = reach / value;
                  o.message = reaches_message(o.reached, why);
                  if (has_twin[k] && !fallback && at_cap)
                    (work[k].second ? second_recipes : recipes)[k] =
                        Recipe{steered_pattern, scale, cap, pose, miss_of(pose, fdp->vertex, along, value, true),
                               target_faults(pose_epidermis(model, pose), fdp->vertex).any(), true, why};
                }
                ok = true;
              }
            }
          }
          if (ok && !steered.empty()) o.message += (o.message.empty() ? "" : "; ") + steered;
        }
      }
    }
    if (ok && o.in_between && o.reached < 1) {
      // Only where the group reaches it in full. Made at what it reaches
      // instead, the generated 2k head's upper lid (449 of 600) took its
      // pose's chord past 449 2.7 mm into the eyeball at 1024, against
      // 0.4 mm with the reference target alone extrapolated.
      ok = false;
      // A closing lid's driver short of an in-between: the lid turned as a
      // whole, where the skin stays a face (the 2k head's lower lids at 600;
      // Song's upper lids at 1024 folded where they meet, and kept none, until
      // target_faults: their driver's load reaches 1024 since).
      if (lid.muscle >= 0 && !lid_cut) {
        const FapOutcome driven = o;
        const double driven_shrink = shrink;
        if (turn_lid(lid) && o.reached == 1 && !target_faults(pose_epidermis(model, pose), fdp->vertex).any()) {
          ok = true;
          o.message += std::string(o.message.empty() ? "" : "; ") +
                       "the lid turned as a whole (its driver's load reaches " +
                       std::to_string(static_cast<int>(std::lround(100 * driven.reached))) + " %)";
        } else {
          o = driven;
          shrink = driven_shrink;
        }
      }
    }
    if (ok) {
      Eigen::MatrixXd D = shrink * (pose_epidermis(model, pose) - skin.X0.topRows(skin.n));
      if (map->lid && fallback) keep_lid_half(model, map->fap, map->lid, D);
      measure(o, D.row(fdp->vertex).transpose(), dir);
      o.dynamic = static_cast<int>(pose.dynamic.size());
      o.slabs = static_cast<int>(turned_slabs(model.tissue, pose.X).size());
      o.made = true;
      MorphTarget t;
      t.kind = AFM_TARGET_FAP;
      t.number = map->fap;
      t.reference = o.reference;
      t.displacement.assign(scene.parts.size(), Eigen::MatrixXd());
      t.displacement[static_cast<size_t>(model.skin)] = D;
      carry(D, t);
      res.target = std::move(t);
    }
    o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    res.outcome = std::move(o);
  };
  // FAPs whose muscle group, FDP vertex, direction and value coincide are
  // one solve: Song's inner and outer lip corners (FAPs 6/53, 7/54, 12/59,
  // 13/60) share their vertices. The later ones copy the first's result.
  using SolveKey = std::tuple<std::vector<std::pair<std::string, double>>, int, double, double, double, double, int>;
  std::vector<std::optional<SolveKey>> keys(work.size());
  for (size_t k = 0; k < work.size(); ++k) {
    const FapMapping *f = work[k].fap;
    if (!f || f->driver != FapDriver::Muscles) continue;
    const afm_fap_info *info = afm_fap(f->fap);
    const int fdp = fdp_vertex(model, info);
    if (fdp < 0) continue;  // not made: no copy
    std::vector<std::pair<std::string, double>> group;
    for (const FapContraction &c : fap_group(model, *f, work[k].side)) group.push_back({c.muscle, c.percent});
    for (const std::string &h : f->helpers) group.push_back({"helper " + h, 0});
    const Eigen::Vector3d along = work[k].side * fap_direction(info);
    keys[k] = SolveKey{group, fdp, along.x(), along.y(), along.z(),
                       work[k].reference * fapu_distance(model.fapu, info->unit), f->lid};
  }
  std::vector<size_t> same_as(work.size());
  for (size_t k = 0; k < work.size(); ++k) {
    same_as[k] = k;
    for (size_t j = 0; keys[k] && j < k && same_as[k] == k; ++j)
      if (same_as[j] == j && keys[j] == keys[k]) same_as[k] = j;
  }
  if (model.mirror.symmetric())
    for (size_t k = 0; k < work.size(); ++k) {
      if (same_as[k] != k || !work[k].fap || work[k].fap->driver != FapDriver::Muscles || work[k].in_between) continue;
      const std::string left = left_fap_name(afm_fap(work[k].fap->fap)->name);
      if (left.empty()) continue;
      for (size_t j = 0; j < work.size(); ++j)
        if (work[j].fap && !work[j].in_between && work[j].side == work[k].side &&
            work[j].reference == work[k].reference && left == afm_fap(work[j].fap->fap)->name) {
          twin_of[k] = static_cast<int>(same_as[j]);
          has_twin[same_as[j]] = 1;
        }
    }
  // The twins' targets first, in the work list's order; a right one that
  // finds its twin still running waits for it.
  std::vector<size_t> order;
  for (size_t k = 0; k < work.size(); ++k)
    if (twin_of[k] < 0) order.push_back(k);
  for (size_t k = 0; k < work.size(); ++k)
    if (twin_of[k] >= 0) order.push_back(k);
  std::vector<int> position(work.size()), after(order.size(), -1);  // in `order`
  for (size_t j = 0; j < order.size(); ++j) position[order[j]] = static_cast<int>(j);
  for (size_t j = 0; j < order.size(); ++j)
    if (const int t = twin_of[order[j]]; t >= 0) after[j] = position[static_cast<size_t>(t)];
  std::mutex lock;
  int done = 0;
  // Second groups (fap_mapping.h): a side its own group left short of the
  // reference is made again with its second group in the same task, at
  // once (a right twin's after its left twin's, as its own group's), and
  // the target nearer the prescribed motion is kept (below). A pass after
  // the others left a worker idle for part of its 0.3 s on Song.
  auto retry = [&](size_t k) {
    const FapOutcome &o = results[k].outcome;
    return options.second_groups && same_as[k] == k && work[k].fap && work[k].fap->driver == FapDriver::Muscles &&
           !work[k].in_between && o.made && o.reached < 1 && o.prescribed.norm() > 0 &&
           !second_group(model, *work[k].fap, work[k].side).empty();
  };
  for_each_task_after(order.size(), options.threads, after, [&](size_t j) {
    const size_t k = order[j];
    const std::string label = work[k].high ? high_level_label(*work[k].high) : fap_label(work[k].fap->fap, work[k].side);
    if (same_as[k] == k) make(k);
    if (retry(k)) {
      {
        std::lock_guard<std::mutex> g(lock);
        if (options.progress) options.progress(done, static_cast<int>(work.size()), label + " (second group)");
      }
      own_group[k] = std::move(results[k]);
      results[k] = Result();
      work[k].second = true;
      make(k);
      work[k].second = false;
    }
    std::lock_guard<std::mutex> g(lock);
    if (options.progress) options.progress(++done, static_cast<int>(work.size()), label);
  });
  {
    auto miss = [](const FapOutcome &o) { return (o.achieved - o.prescribed).norm() / o.prescribed.norm(); };
    for (size_t k : order) {
      if (!own_group[k]) continue;
      FapOutcome &first = own_group[k]->outcome, &second = results[k].outcome;
      std::string group;
      for (const FapContraction &c : second_group(model, *work[k].fap, work[k].side)) {
        char b[96];
        std::snprintf(b, sizeof b, "%s%s %+.0f %%", group.empty() ? "" : ", ", c.muscle.c_str(), c.percent);
        group += b;
      }
      if (second.made && miss(second) < miss(first)) {
        char b[96];
        std::snprintf(b, sizeof b, "): its own reached %.0f %% of the prescribed motion", 100 * first.reached);
        second.message = "made with its second group (" + group + b +
                         (second.message.empty() ? "" : "; " + second.message);
        second.seconds += first.seconds;
      } else {
        // What it reached, so that a reader can judge the group.
        char b[96] = "made no target";
        if (second.made)
          std::snprintf(b, sizeof b, "reached %.0f %% of the prescribed motion, %.0f %% off-axis",
                        100 * second.reached, 100 * second.off_axis);
        first.message += "; its second group (" + group + ") came no nearer: " + b;
        first.seconds += second.seconds;
        results[k] = std::move(*own_group[k]);
      }
    }
  }
  for (size_t k = 0; k < work.size(); ++k) {
    if (same_as[k] == k) continue;
    const Result &first = results[same_as[k]];
    Result &r = results[k];
    r.outcome = first.outcome;
    r.outcome.number = work[k].fap->fap;
    r.outcome.side = work[k].side;
    r.outcome.reference = work[k].side * work[k].reference;
    r.outcome.seconds = 0;
    if (first.target) {
      r.target = first.target;
      r.target->number = work[k].fap->fap;
      r.target->reference = r.outcome.reference;
    }
  }
  for (size_t k = work.size(); k-- > 0;)
    if (work[k].hidden) {
      work.erase(work.begin() + static_cast<std::ptrdiff_t>(k));
      results.erase(results.begin() + static_cast<std::ptrdiff_t>(k));
    }
  // A FAP side's in-betweens go on past its nearer targets: one made at
  // the value where the lids meet is dropped when that value is not past
  // them (an eye opened less than a 600 in-between).
  for (size_t k = 0; k < work.size(); ++k) {
    if (!work[k].in_between || !results[k].target) continue;
    int nearer = 0;
    for (size_t j = 0; j < work.size(); ++j)
      if (j != k && work[j].fap == work[k].fap && work[j].side == work[k].side && results[j].target &&
          std::abs(results[j].outcome.reference) < work[k].reference)
        nearer = std::max(nearer, std::abs(results[j].outcome.reference));
    FapOutcome &o = results[k].outcome;
    if (std::abs(o.reference) > nearer) continue;
    results[k].target.reset();
    o.made = false;
    o.message += "; not kept: not past the side's target at " + std::to_string(nearer);
  }
  // The mouth corner moves as one (the modiolus: "The modiolus" in
  // fap_synthesis.h).
  for (size_t k = 0; k < work.size(); ++k) {
    const FapMapping *f = work[k].fap;
    if (!f || f->driver != FapDriver::Muscles || !results[k].target) continue;
    const afm_fap_info *info = afm_fap(f->fap);
    if (!lip_corner_fdp(info)) continue;
    const int c = fdp_vertex(model, info);
    if (c < 0) continue;
    MorphTarget &t = *results[k].target;
    Eigen::MatrixXd &D = t.displacement[static_cast<size_t>(model.skin)];
    if (D.rows() != skin.n) continue;
    move_modiolus(skin.X0.topRows(skin.n), c, kModiolusRadius * model.fapu.mw0, D);
    for (const SkinBinding &b : carried) t.displacement[static_cast<size_t>(b.part)] = Eigen::MatrixXd();
    carry(D, t);
  }
  // FAP targets that move the same skin split it (fap_partition.h).
  std::vector<Eigen::VectorXd> skin_share(work.size());  // per target: its share, empty when whole
  // Per target: the other FAPs' targets that move its FDP the same way, on
  // the same side (the lip corners': the inner and outer lip's).
  std::vector<std::vector<size_t>> fdp_partners(work.size());
  {
    std::vector<SharingTarget> sharing(work.size());
    for (size_t k = 0; k < work.size(); ++k) {
      const FapMapping *f = work[k].fap;
      // Lids and the cheek puffs share no skin. An in-between is a FAP's own
      // target past its reference: it takes no share apart from the FAP's.
      if (!f || f->driver != FapDriver::Muscles || f->lid || f->own_skin || work[k].in_between || !results[k].target)
        continue;
      const afm_fap_info *info = afm_fap(f->fap);
      const int fdp = fdp_vertex(model, info);
      if (fdp < 0) continue;
      sharing[k].fap = f->fap;
      sharing[k].vertex = fdp;
      for (const FapContraction &c : fap_group(model, *f, work[k].side))
        sharing[k].muscles.push_back({c.muscle, c.percent > 0 ? +1 : -1});
      sharing[k].direction = fap_direction(info);
      sharing[k].side = work[k].side;
      sharing[k].displacement = &results[k].target->displacement[static_cast<size_t>(model.skin)];
    }
    FapPartition part = partition_shared_targets(skin.X0.topRows(skin.n), skin.F, sharing);
    // Where a share would turn skin over, the weights are evened out
    // (fap_partition.h), judged as the target is stored: untangled (below).
    const UnfoldedShares unfolded =
        unfold_shared_weights(rest, skin.F, sharing, part, [&](size_t k, const Eigen::VectorXd &w) {
          Eigen::MatrixXd D = results[k].target->displacement[static_cast<size_t>(model.skin)];
          D.array().colwise() *= w.array();
          untangle(rest, skin.F, target_hold(sharing[k].vertex), options.sim, D);
          const SkinFaults f = face_faults(rest + D);
          return static_cast<int>(f.turned_faces.size() + f.lifted_turned_faces.size());
        }, options.threads);
    for (size_t k = 0; k < work.size(); ++k)
      if (unfolded.turned_after[k] < unfolded.turned_before[k]) {
        char what[240];
        std::snprintf(what, sizeof what,
                      "its share of the skin it shares turned %d triangles (the lifted skin's counted too), %d "
                      "once the shares were evened out (weights changed by up to %.2g at %d vertices: "
                      "fap_partition.h)",
                      unfolded.turned_before[k], unfolded.turned_after[k], unfolded.largest_change,
                      unfolded.vertices);
        FapOutcome &o = results[k].outcome;
        o.message += std::string(o.message.empty() ? "" : "; ") + what;
      }
    skin_share = part.weight;
    const size_t sk = static_cast<size_t>(model.skin);
    for (size_t k = 0; k < work.size(); ++k) {
      if (part.weight[k].size() == 0) continue;
      MorphTarget &t = *results[k].target;
      Eigen::MatrixXd D = t.displacement[sk];
      D.array().colwise() *= part.weight[k].array();
      for (const SkinBinding &b : carried) t.displacement[static_cast<size_t>(b.part)] = Eigen::MatrixXd();
      t.displacement[sk] = D;
      carry(D, t);
    }
    // A target whose FDP is another FAP's too, in the same direction (the
    // lip corners), moves it by a share: it is measured with those FAPs at
    // the same value.
    for (size_t k = 0; k < work.size(); ++k) {
      if (part.weight[k].size() == 0) continue;
      FapOutcome &o = results[k].outcome;
      const int v = sharing[k].vertex;
      Eigen::Vector3d achieved = results[k].target->displacement[sk].row(v).transpose();
      std::string with;
      for (size_t j = 0; j < work.size(); ++j) {
        if (j == k || part.component[j] != part.component[k] || sharing[j].vertex != v ||
            work[j].side != work[k].side || sharing[j].fap == sharing[k].fap ||
            sharing[j].direction != sharing[k].direction ||
            part.weight[j].size() == 0)
          continue;
        fdp_partners[k].push_back(j);
        achieved += static_cast<double>(work[k].reference) / work[j].reference *
                    results[j].target->displacement[sk].row(v).transpose();
        with += (with.empty() ? "" : ", ") + std::to_string(sharing[j].fap);
      }
      measure(o, achieved, sharing[k].direction);
      if (!with.empty())
        o.message += std::string(o.message.empty() ? "" : "; ") + "its FDP is FAP " + with +
                     "'s too: each moves it by a share, measured together at the same value";
    }
  }
  // The jaw's opening leaves the lower lip's height to the lip's FAPs
  // (jaw_lips.h). What FAP 3's farthest target gives up (#n, y), the push
  // that keeps its skin in front of the lower teeth (#n, z:
  // teeth_clearance.h) and its reference are kept: past their reach the
  // lower lip's FAPs go on with it.
  Eigen::VectorXd lip_given_up, lip_pushed, lip_kept;
  int given_up_at = 0;
  size_t given_up_by = results.size();  // the work item of FAP 3's target at given_up_at
  std::optional<TeethClearance> teeth;
  {
    const JawLipHold hold = jaw_lip_hold(model);
    for (size_t k = 0; k < work.size(); ++k) {
      const FapMapping *f = work[k].fap;
      if (!f || f->driver != FapDriver::JawOpen || !results[k].target || hold.lip.empty()) continue;
      MorphTarget &t = *results[k].target;
      Eigen::MatrixXd &D = t.displacement[static_cast<size_t>(model.skin)];
      if (D.rows() != skin.n) continue;
      if (work[k].reference > given_up_at) {
        given_up_at = work[k].reference;
        given_up_by = k;
        lip_given_up = D.col(1).cwiseProduct((1 - hold.share.array()).matrix());
        lip_kept = hold.share;
      }
      keep_lip_height(hold, D);
      // The teeth turn down behind the held lip (teeth_clearance.h).
      if (!teeth) teeth = teeth_clearance(scene, model, options.sim);
      const TeethPush push = keep_before_teeth(*teeth, jaw_motion(model.jaw, 100 * results[k].outcome.scale, 0, 0), D);
      if (work[k].reference == given_up_at) lip_pushed = push.push;
      if (push.pushed > 0) {
        char what[200];
        std::snprintf(what, sizeof what,
                      "the skin over the lower teeth pushed forward at %d vertices, by up to %.2g MNS0%s",
                      push.pushed, push.deepest / model.fapu.mns0,
                      push.left > 0 ? " (some still short of the clearance)" : "");
        FapOutcome &o = results[k].outcome;
        o.message += std::string(o.message.empty() ? "" : "; ") + what;
        // The push may reach the chin's FDP: measured as stored.
        const afm_fap_info *info = afm_fap(f->fap);
        if (const int v = fdp_vertex(model, info); v >= 0) measure(o, D.row(v).transpose(), fap_direction(info));
      }
      for (const SkinBinding &b : carried) t.displacement[static_cast<size_t>(b.part)] = Eigen::MatrixXd();
      carry(D, t);
    }
  }
  // The slivers a target turns over are untangled (untangle.h; target_hold
  // above).
  std::vector<RigidSample> jaw_samples;
  // Reach, then hold (fap_synthesis.h): the sides that store an
  // under-reaching pose twice.
  std::vector<char> negative_made(AFM_FAP_COUNT + 1, 0);
  for (size_t k = 0; k < work.size(); ++k)
    if (work[k].fap && work[k].side < 0 && results[k].target) negative_made[static_cast<size_t>(work[k].fap->fap)] = 1;
  auto holds_reach = [&](size_t k) {
    const Work &w = work[k];
    const FapOutcome &o = results[k].outcome;
    if (!options.hold_reach || !w.fap || w.in_between || w.fap->driver != FapDriver::Muscles || w.fap->lid ||
        !results[k].target || !o.made || o.reached >= 1)
      return false;
    // Negative values would extrapolate the positive side's first segment.
    if (w.side > 0 && afm_fap(w.fap->fap)->bidirectional && !negative_made[static_cast<size_t>(w.fap->fap)])
      return false;
    for (size_t j = 0; j < work.size(); ++j)
      if (j != k && work[j].fap == w.fap && work[j].side == w.side && results[j].target) return false;
    return true;
  };
  // The held side's target at its reach: pose t scaled to the whole FAP
  // units it reaches along the FAP's direction, r = floor(a), stored at r
  // (returned, to go before the hold); outcome o becomes the hold's.
  // Nothing where it reaches under one unit.
  auto split_hold = [&](size_t k, const MorphTarget &t,
                        FapOutcome &o) -> std::optional<std::pair<MorphTarget, FapOutcome>> {
    const Eigen::Vector3d dir = fap_direction(afm_fap(o.number));
    const int table = work[k].reference;
    const double a = table * o.achieved.dot(dir) / o.prescribed.dot(dir);
    const int reach = static_cast<int>(std::floor(a));
    if (reach < 1 || a >= table) return std::nullopt;
    const double c = reach / a;
    MorphTarget base = t;
    for (Eigen::MatrixXd &d : base.displacement) d *= c;
    base.reference = o.side * reach;
    FapOutcome b = o;
    b.reference = base.reference;
    b.prescribed = o.prescribed * (static_cast<double>(reach) / table);
    measure(b, c * o.achieved, dir);
    b.reached = 1;
    b.at_reach = true;
    const SkinFaults bf = skin_faults(model, rest + base.displacement[static_cast<size_t>(model.skin)]);
    b.turned = static_cast<int>(bf.turned_faces.size());
    b.sunk = static_cast<int>(bf.sunk_vertices.size());
    b.message = "its group's reach, " + std::to_string(reach) + " of the table's " + std::to_string(table) +
                "; held to " + std::to_string(o.side * table) + " (the in-between there)";
    // The pose as it is, at the table's reference.
    o.in_between = true;
    o.holds = true;
    o.seconds = 0;
    o.message = "holds the reach of " + std::to_string(o.side * reach) + "; " + o.message;
    return std::make_pair(std::move(base), std::move(b));
  };
  // A lower lip FAP's negative side past its target (jaw_lips.h, "Past
  // the lip's reach"): at FAP 3's farthest reference, an in-between holding
  // the side's pose, and a combination gated by FAP 3 (formats/afm.md): the
  // height FAP 3's target gave up there, times the side's share of the
  // split skin, scaled so that with the in-between the FDP reaches that
  // value. Alone the lip holds; with the jaw it goes on as far as the jaw
  // opens.
  using Made = std::pair<MorphTarget, FapOutcome>;
  auto lip_past_reach = [&](size_t k, const MorphTarget &t, const FapOutcome &o,
                            const std::vector<char> &hold) -> std::vector<Made> {
    const FapMapping *f = work[k].fap;
    if (!f || f->driver != FapDriver::Muscles || work[k].side > 0 || work[k].in_between || !o.made ||
        !lower_lip_fap(f->fap) || lip_given_up.size() != skin.n || std::abs(o.reference) >= given_up_at)
      return {};
    const afm_fap_info *info = afm_fap(f->fap);
    const int v = fdp_vertex(model, info);
    const Eigen::MatrixXd &D = t.displacement[static_cast<size_t>(model.skin)];
    if (v < 0 || D.rows() != skin.n) return {};
    const Eigen::Vector3d along = work[k].side * fap_direction(info);
    const double unit = o.prescribed.dot(along) / std::abs(o.reference);
    Eigen::VectorXd G = lip_given_up;
    if (skin_share[k].size() == skin.n) G.array() *= skin_share[k].array();
    const double own = D.row(v).dot(along.transpose()), more = G(v) * along.y();
    const double alpha = (given_up_at * unit - own) / more;
    if (!(more > 0) || !(alpha > 0)) return {};
    // E: the side's pose with the jaw's height, what the hold and the
    // combination add up to with the jaw open as far. Below the lip the
    // side's own motion gives way to the jaw's as the share FAP 3 keeps
    // there (s) grows: taken down by both, the skin above Song's chin went
    // past the chin (4 triangles turned, played with the jaw at 1024; 2
    // with this, none once the played pose is untangled, below).
    Eigen::MatrixXd E = D.array().colwise() * (1 - lip_kept.array());
    E.col(1) += alpha * G;
    // The push over the teeth that FAP 3's target made goes with the hold;
    // in front of the closed teeth the skin keeps its clearance.
    if (lip_pushed.size() == skin.n) {
      Eigen::VectorXd Z = lip_pushed;
      if (skin_share[k].size() == skin.n) Z.array() *= skin_share[k].array();
      E.col(2) -= alpha * Z;
      if (teeth) keep_before_teeth(*teeth, Eigen::Affine3d::Identity(), E);
    }
    std::vector<char> h = hold;
    h[static_cast<size_t>(v)] = kUntangleFixed;
    untangle(rest, skin.F, h, options.sim, E);
    std::vector<Made> made(2, Made{t, o});
    // The hold: the side's pose to FAP 3's farthest reference.
    MorphTarget &ht = made[0].first;
    FapOutcome &ho = made[0].second;
    ht.reference = work[k].side * given_up_at;
    ho.reference = ht.reference;
    ho.in_between = ho.from_jaw = true;
    ho.holds = ho.at_reach = false;
    ho.seconds = 0;
    ho.slabs = 0;  // the side's pose, counted once
    ho.prescribed = given_up_at * unit * along;
    measure(ho, D.row(v).transpose(), fap_direction(info));
    ho.reached = D.row(v).dot(along.transpose()) / (given_up_at * unit);
    ho.message = "holds the side's pose to " + std::to_string(ht.reference) +
                 "; with the jaw open the combination below goes on";
    // The combination: E less the hold, gated by FAP 3.
    MorphTarget &ct = made[1].first;
    FapOutcome &co = made[1].second;
    ct.kind = co.kind = AFM_TARGET_COMBINATION;
    ct.reference = ht.reference;
    ct.gate = 3;
    ct.gate_reference = given_up_at;
    for (Eigen::MatrixXd &d : ct.displacement) d = Eigen::MatrixXd();
    ct.displacement[static_cast<size_t>(model.skin)] = E - D;
    carry(ct.displacement[static_cast<size_t>(model.skin)], ct);
    co.reference = ct.reference;
    co.in_between = co.from_jaw = true;
    co.holds = co.at_reach = false;
    co.reached = 1;
    co.seconds = 0;
    co.slabs = 0;  // not solved: FAP 3's skin carried
    co.prescribed = given_up_at * unit * along;
    measure(co, E.row(v).transpose(), fap_direction(info));
    // Judged as played below, with the other lip sides and the jaw.
    co.sunk = static_cast<int>(skin_faults(model, rest + E).sunk_vertices.size());
    co.message = "with FAP 3 at " + std::to_string(given_up_at) + " the lip goes on as the jaw would carry it, by " +
                 "this FAP's share (jaw_lips.h); gated by FAP 3's value";
    return made;
  };
  // Each target's untangling, checks, reach and lip past its reach are its
  // own (on workers: a serial 0.2 s of Song's AFM); they join `out` in the
  // work list's order.
  struct Finished {
    std::optional<std::pair<MorphTarget, FapOutcome>> reach, past;  // before and after the target
    std::vector<std::pair<MorphTarget, FapOutcome>> far;  // after the target
  };
  std::vector<Finished> finished(results.size());
  for_each_task(results.size(), options.threads, [&](size_t k) {
    Result &r = results[k];
    if (r.target && r.target->displacement[static_cast<size_t>(model.skin)].rows() > 0) {
      MorphTarget &t = *r.target;
      Eigen::MatrixXd &D = t.displacement[static_cast<size_t>(model.skin)];
      const FapMapping *f = work[k].fap;
      const std::vector<char> hold = target_hold(f ? fdp_vertex(model, afm_fap(f->fap)) : -1);
      const Untangled u = untangle(rest, skin.F, hold, options.sim, D);
      if (u.moved > 0) {
        for (const SkinBinding &b : carried) t.displacement[static_cast<size_t>(b.part)] = Eigen::MatrixXd();
        carry(D, t);
        char what[288], near[64] = "";
        if (u.near_before > 0) std::snprintf(near, sizeof near, " and %d slivers nearly turned", u.near_before);
        std::snprintf(what, sizeof what,
                      "untangled %d of %d turned triangles%s: %d vertices move (in patches, each affinely "
                      "or as one piece, or as a sliver's corner), changed by %.2g at most",
                      u.turned_before - u.turned_after, u.turned_before, near, u.moved, u.largest_change);
        r.outcome.message += std::string(r.outcome.message.empty() ? "" : "; ") + what;
      }
      const SkinFaults faults = skin_faults(model, rest + D);
      r.outcome.turned = static_cast<int>(faults.turned_faces.size());
      r.outcome.sunk = static_cast<int>(faults.sunk_vertices.size());
      if (holds_reach(k)) finished[k].reach = split_hold(k, t, r.outcome);
      finished[k].far = lip_past_reach(k, t, r.outcome, hold);
    }
  });
  // The lower lip's combinations as streams play them: FAP 3 at its
  // farthest reference with every lower lip side there. Where that pose
  // turns triangles, it is untangled once (the sides' FDPs and the chin's
  // fixed) and the change shared among the combinations by the sides'
  // shares of the split skin (Song: 2 triangles above the chin; none on the
  // generated heads).
  {
    const size_t s0 = static_cast<size_t>(model.skin);
    std::vector<size_t> lips;
    for (size_t k = 0; k < results.size(); ++k)
      if (finished[k].far.size() == 2) lips.push_back(k);
    // FAP 3's target at given_up_at, untangled as stored (there are lips
    // only where it gave up some height).
    const MorphTarget *jaw = lips.empty() ? nullptr : &*results[given_up_by].target;
    if (jaw) {
      auto share = [&](size_t k) -> Eigen::VectorXd {
        return skin_share[k].size() == skin.n ? skin_share[k] : Eigen::VectorXd::Ones(skin.n);
      };
      Eigen::MatrixXd J = jaw->displacement[s0];
      Eigen::VectorXd total = Eigen::VectorXd::Zero(skin.n);
      std::vector<char> h = target_hold(fdp_vertex(model, afm_fap(3)));  // the chin keeps FAP 3's motion
      for (size_t k : lips) {
        J += finished[k].far[0].first.displacement[s0] + finished[k].far[1].first.displacement[s0];
        total += share(k);
        const int v = fdp_vertex(model, afm_fap(work[k].fap->fap));
        if (v >= 0) h[static_cast<size_t>(v)] = kUntangleFixed;
      }
      Eigen::MatrixXd U = J;
      const Untangled u = untangle(rest, skin.F, h, options.sim, U);
      const int turned = static_cast<int>(skin_faults(model, rest + U).turned_faces.size());
      for (size_t k : lips) {
        MorphTarget &ct = finished[k].far[1].first;
        FapOutcome &co = finished[k].far[1].second;
        if (u.moved > 0) {
          Eigen::VectorXd w = share(k);
          for (Eigen::Index i = 0; i < w.size(); ++i)
            w(i) = total(i) > 0 ? w(i) / total(i) : 1.0 / static_cast<double>(lips.size());
          Eigen::MatrixXd &K = ct.displacement[s0];
          K.array() += (U - J).array().colwise() * w.array();
          for (const SkinBinding &b : carried) ct.displacement[static_cast<size_t>(b.part)] = Eigen::MatrixXd();
          carry(K, ct);
          char what[200];
          std::snprintf(what, sizeof what,
                        "; played with the other lip sides and FAP 3, %d turned triangles untangled, its share of "
                        "the change by up to %.2g",
                        u.turned_before - u.turned_after, u.largest_change);
          co.message += what;
        }
        co.turned = turned;
      }
    }
  }
  // Held past the reference (fap_synthesis.h): a lip corner's side whose
  // target, summed with its partners' at the same value (the FAPs that move
  // its FDP the same way) and taken kCornerStreamReach times as far, turns
  // the skin over. Judged once every target is untangled.
  const size_t sk = static_cast<size_t>(model.skin);
  for (size_t k = 0; k < results.size(); ++k) {
    const FapMapping *f = work[k].fap;
    const Result &r = results[k];
    if (!options.hold_past_reference || !f || f->driver != FapDriver::Muscles || work[k].in_between ||
        !r.target || !r.outcome.made || finished[k].reach)
      continue;
    const afm_fap_info *info = afm_fap(f->fap);
    const Eigen::MatrixXd &D = r.target->displacement[sk];
    if (!lip_corner_fdp(info) || D.rows() != skin.n) continue;
    const Eigen::Vector3d dir = fap_direction(info);
    Eigen::MatrixXd sum = D;
    std::string with;
    for (size_t j : fdp_partners[k]) {
      sum += static_cast<double>(work[k].reference) / work[j].reference *
             results[j].target->displacement[sk];
      with += (with.empty() ? "" : ", ") + std::to_string(work[j].fap->fap);
    }
    const SkinFaults folds = face_faults(rest + kCornerStreamReach * sum);
    if (folds.turned_faces.empty() && folds.lifted_turned_faces.empty()) continue;
    const int past = static_cast<int>(std::lround(kCornerStreamReach * work[k].reference));
    std::pair<MorphTarget, FapOutcome> past_hold{*r.target, r.outcome};
    MorphTarget &ht = past_hold.first;
    FapOutcome &ho = past_hold.second;
    ht.reference = work[k].side * past;
    ho.reference = ht.reference;
    ho.in_between = ho.past_reference = true;
    ho.holds = ho.at_reach = false;
    ho.seconds = 0;
    ho.prescribed = r.outcome.prescribed * (static_cast<double>(past) / work[k].reference);
    measure(ho, r.outcome.achieved, dir);
    ho.reached = r.outcome.reached * work[k].reference / past;
    const std::string whose = with.empty() ? "its target" : "with FAP " + with + "'s at the same value, its target";
    char what[288];
    std::snprintf(what, sizeof what,
                  "holds the pose of %d past it: %s, taken %.2g times as far, turns %zu skin triangles over "
                  "(%zu of the input's)",
                  work[k].side * work[k].reference, whose.c_str(), kCornerStreamReach, folds.turned_faces.size(),
                  folds.lifted_turned_faces.size());
    ho.message = what;
    finished[k].past = std::move(past_hold);
  }
  for (size_t k = 0; k < results.size(); ++k) {
    Result &r = results[k];
    Finished &f = finished[k];
    if (f.reach) {
      out.targets.push_back(std::move(f.reach->first));
      out.outcomes.push_back(std::move(f.reach->second));
    }
    if (r.target) out.targets.push_back(std::move(*r.target));
    if (r.outcome.made) jaw_samples.insert(jaw_samples.end(), r.jaw.begin(), r.jaw.end());
    out.outcomes.push_back(std::move(r.outcome));
    for (auto &m : f.far) {
      out.targets.push_back(std::move(m.first));
      out.outcomes.push_back(std::move(m.second));
    }
    if (f.past) {
      out.targets.push_back(std::move(f.past->first));
      out.outcomes.push_back(std::move(f.past->second));
    }
  }
  // The jaw's controls bend at FAP 3's in-betweens, so the teeth are where
  // each target's bone is (formats/afm.md, RIGD knots).
  out.jaw.controls = piecewise_controls(jaw_samples);
  if (out.jaw.controls.empty()) out.jaw.parts.clear();
  if (options.sim) lift_synthesis(out, *options.sim);
  return out;
}

void move_modiolus(const Eigen::MatrixXd &V0, int corner, double radius, Eigen::MatrixXd &D) {
  if (!(radius > 0) || corner < 0 || corner >= D.rows()) return;
  const Eigen::RowVector3d c = V0.row(corner), dc = D.row(corner);
  for (Eigen::Index v = 0; v < D.rows(); ++v) {
    const double t2 = (V0.row(v) - c).squaredNorm() / (radius * radius);
    if (t2 >= 1) continue;
    const double w = (1 - t2) * (1 - t2);
    D.row(v) += w * (dc - D.row(v));
  }
}

void lift_synthesis(FapSynthesis &synthesis, const SimMesh &sim) {
  if (!sim.decimated || synthesis.lift.control_count > 0) return;
  const size_t skin = static_cast<size_t>(sim.skin);
  synthesis.lift.control_count = static_cast<int>(sim.V.rows());
  synthesis.lift.parts = {sim.binding};
  synthesis.lift.parts[0].part = sim.skin;
  for (const SkinBinding &b : synthesis.carried) synthesis.lift.parts.push_back(b);
  size_t next = 0;  // targets are the made outcomes, in order
  std::vector<std::pair<FapOutcome *, size_t>> combinations;
  for (FapOutcome &o : synthesis.outcomes) {
    if (!o.made) continue;
    MorphTarget &t = synthesis.targets[next++];
    if (skin >= t.displacement.size() || t.displacement[skin].rows() == 0) continue;
    t.controls = t.displacement[skin];
    t.displacement[skin] = lift_displacement(sim, t.controls);
    if (t.kind == AFM_TARGET_COMBINATION)
      combinations.emplace_back(&o, next - 1);  // judged below, once every target is lifted
    else
      o.turned = static_cast<int>(turned_faces(sim.skin_V, sim.skin_F, sim.skin_V + t.displacement[skin]).size());
    if (o.kind == AFM_TARGET_VISEME || o.kind == AFM_TARGET_EXPRESSION)
      o.largest = t.displacement[skin].rowwise().norm().maxCoeff();
  }
  // A combination is judged as played.
  for (auto [o, c] : combinations) {
    Eigen::MatrixXd played = sim.skin_V;
    for (size_t i : played_with(synthesis.targets, c))
      if (skin < synthesis.targets[i].displacement.size() &&
          synthesis.targets[i].displacement[skin].rows() == played.rows())
        played += synthesis.targets[i].displacement[skin];
    o->turned = static_cast<int>(turned_faces(sim.skin_V, sim.skin_F, played).size());
  }
}

std::vector<size_t> played_with(const std::vector<MorphTarget> &targets, size_t c) {
  std::vector<size_t> with;
  if (c >= targets.size() || targets[c].kind != AFM_TARGET_COMBINATION) return with;
  const MorphTarget &ct = targets[c];
  auto partner = [&ct](const MorphTarget &u) {
    return u.kind == AFM_TARGET_COMBINATION && u.gate == ct.gate && u.gate_reference == ct.gate_reference &&
           u.reference == ct.reference;
  };
  for (size_t i = 0; i < targets.size(); ++i) {
    const MorphTarget &t = targets[i];
    bool in = partner(t) || (t.kind == AFM_TARGET_FAP && t.number == ct.gate && t.reference == ct.gate_reference);
    for (const MorphTarget &u : targets)
      in |= partner(u) && t.kind == AFM_TARGET_FAP && t.number == u.number && t.reference == u.reference;
    if (in) with.push_back(i);
  }
  return with;
}

AfmContent fap_afm_content(const Scene &scene, const FdpSet &fdps, const FaceModel &model, FapSynthesis synthesis) {
  AfmContent c;
  c.scene = &scene;
  c.fdps = &fdps;
  c.fapu = model.fapu;
  c.targets = std::move(synthesis.targets);
  c.rigids = eye_and_head_rigids(scene, fdps, model.fapu, model.skin);
  if (!synthesis.jaw.parts.empty()) c.rigids.push_back(std::move(synthesis.jaw));
  c.lift = std::move(synthesis.lift);
  return c;
}

}  // namespace afmb
