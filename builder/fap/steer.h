// Steering a FAP's FDP back onto the FAP's direction with helper muscles
// (fap_mapping.h, FapMapping::helpers).
//
// Why: a FAP is the motion of its FDP along one axis (MPEG-4), but a muscle
// moves the skin along its own line of action and along the bone. Alone,
// zygomaticus major raises Song's mouth corner and pulls it out toward the
// cheekbone by a third of the rise; with risorius let back and orbicularis
// oris drawing the corner in, an eighth is left. The report's off-axis
// median on Song went from 25 to 14 % (docs/fap_mapping.md).
//
// The choice (steer_contractions): with r+ and r- a helper's calibrated
// pose's motion of the FDP at +100 % and -100 % (Muscle::response_max,
// _min), M the motion that counts (the projection off the FAP's direction
// where the group reaches its value, all of it where the group falls short)
// and e the FDP's counted distance from the wanted motion in a pose with
// the helpers at c0, the helpers' contractions c (signed fractions of
// their range, |c| <= kHelperBound) minimise
//
//     |e + sum_h M r_h (c_h - c0_h)|^2 + sum_h (k_h L_h^2 + b_h^2) c_h^2,
//
// r_h = r+ or r- by the sign of c_h (two variables per helper, each in
// [0, kHelperBound]), L_h the largest motion of any node in that calibrated
// pose (a helper that moves the FDP little and the face much costs much;
// k_h = kHelperCost, times kProtrusionCost for the lips' protrusion drivers),
// b_h its motion of the FDP back against the FAP's direction (a helper may
// not undo the group's work). Projected coordinate descent; the problem is
// convex and small. In the solve the helpers are part of the group's
// pattern, which the load control scales as a whole: where it scales the
// group up, a helper ends a little past its choice (52 % at most on Song
// and the generated 2k and 10k heads).
//
// The calibrated poses are single muscles from rest, the tissue is not
// linear, and the group's own scale shifts as the helpers join: the
// synthesis solves the group with the helpers at c, measures the FDP again,
// corrects the model by what it saw (steer_update) and chooses again from
// the best pose so far (kSteerRounds at most), keeping a round only where
// the off-axis motion falls (fap_synthesis.h).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "anatomy/face_model.h"

namespace afmb {

// The most a helper contracts, as a fraction of its range either way.
constexpr double kHelperBound = 0.5;
// The weight of a helper's largest motion against the FDP's off-axis motion.
constexpr double kHelperCost = 0.05;
// The lips' protrusion drivers (lip_protrusion_upper, _lower) pay this
// share of it: the one helper that moves a lip in depth (fap_mapping.cpp),
// their largest motion is the lip's own middle, beside the lip FDPs they
// steer, so that at the full cost they stopped at a third of their range
// while the upper lip's sides went 25-30 % of their motion off in depth
// (the generated 10k head). At a fifth, off-axis medians of the three
// heads' reports 11.5 / 13.4 / 12.6 % (Song, 10k, 2k) against 11.5 / 18.2 /
// 11.7 %, and the real streams' summed distance from their prescription
// (afm-play --fdp-motion) 1,640 / 2,128 / 2,074 against 1,682 / 2,184 /
// 2,085 (docs/fap_mapping.md, "Second groups").
constexpr double kProtrusionCost = 0.2;
// A helper chosen at less than this (a fraction of its range) is left out.
constexpr double kHelperLeast = 0.01;
// The off-axis share (of the prescribed motion) above which a group is
// steered, the most solves spent on it (a third round was never kept on
// Song or the generated 2k and 10k heads), and the least gain (the same
// share) for which the steering goes on.
constexpr double kSteerAbove = 0.1;
constexpr int kSteerRounds = 2;
constexpr double kSteerGain = 0.02;

struct HelperColumn {
  int muscle = -1;  // index into FaceModel::muscles
  // The FDP's motion in the calibrated poses at +100 % and -100 %, model
  // units (zero on a side that is not calibrated), and the largest motion
  // of any node in them.
  Eigen::Vector3d plus = Eigen::Vector3d::Zero(), minus = Eigen::Vector3d::Zero();
  double largest_plus = 0, largest_minus = 0;
  double cost = kHelperCost;  // the weight of its largest motion (kHelperCost, kProtrusionCost)
};

// The helpers named in `names` that the model has, that are not in `group`
// (indices into FaceModel::muscles) and that move skin vertex `vertex` in a
// calibrated pose.
std::vector<HelperColumn> helper_columns(const FaceModel &model, const std::vector<std::string> &names,
                                         const std::vector<std::pair<int, double>> &group, int vertex);

// The linear model the choice works on: two variables per helper, its
// positive and its negative contraction (each in [0, kHelperBound]), each
// with the counted motion of the FDP at a full contraction and a cost.
// `measured` (3 x 3) says which motion counts: the projection off the FAP's
// direction where the group reaches its value (the load control keeps the
// motion along it), the identity where it does not (the helpers may then
// also take the FDP further along). `along`: the FAP's unit direction on
// the side made. A variable that moves the FDP back against it pays for
// that loss as for an error, on top of kHelperCost: a helper may not undo
// the group's work.
struct SteerModel {
  std::vector<Eigen::Vector3d> column;  // 2 per helper: + then -, model units
  std::vector<double> cost;             // 2 per helper
};
SteerModel steer_model(const std::vector<HelperColumn> &helpers, const Eigen::Matrix3d &measured,
                       const Eigen::Vector3d &along);

// The contractions (one per helper, signed fractions of the range) that
// minimise the cost above, from `current` (the same). `error`: the counted
// distance from the wanted motion in the pose at `current`, measured x
// (FDP motion - wanted), model units. *predicted, when given, gets the
// model's |error| at the contractions returned.
std::vector<double> steer_contractions(const SteerModel &model, const Eigen::Vector3d &error,
                                       const std::vector<double> &current, double *predicted = nullptr);

// Re-linearises the model on a solved pose (a secant, Broyden's update):
// going from contractions `from` to `to` changed the counted error by
// `change`, with the group's own scale found again by the solve.
void steer_update(SteerModel &model, const std::vector<double> &from, const std::vector<double> &to,
                  const Eigen::Vector3d &change);

// Steers a group's pose with the helpers `names` (FapMapping::helpers), as
// the synthesis does (fap_synthesis.h). In: `pose`, the group `pattern`
// (indices into FaceModel::muscles, percent) at scale `scale`, found under
// load control (face_model.h, solve_pose_to) so that `action`, the motion
// of skin vertex `vertex` along `along` (the FAP's unit direction on the
// side made), reaches `value` (model units), the scale at most `cap`;
// `capped`: the solve stopped at the cap, short of the value. `faults`:
// what is wrong with an epidermis (#V x 3) as a face. Each round chooses
// the helpers' contractions (steer_contractions) from the best pose so far
// and solves the group with them from it, under the same load control; a
// round is kept only where the FDP's off-axis motion falls, the group
// reaches no less than before (a capped group no less far along), and the
// skin sinks and tears no more. Folds are allowed, past the calibrated
// range too: the few a steered pose turns there (Song: 2-8 triangles, in
// all under 5e-5 of the skin's area) the split of shared skin and the
// untangling take out (fap_synthesis.h), and requiring none cost Song 2
// points of its off-axis median. After a round not kept the model is
// corrected and the choice made again; the steering stops after a round
// that gains less than kSteerGain of `value`, a choice the model says
// gains less, a failed solve, or kSteerRounds rounds. Out: the pose,
// scale and capped of the last round kept (as they were when none is), and
// *steered_pattern (when given) the pattern it was solved with: `pattern`
// and the helpers, in percent before the scale (`pattern` when none is).
// Returns "steered by NAME +C %, ... (off-axis A % -> B %)", contractions
// in percent of each helper's range and off-axis shares of `value` (with
// ", along A % -> B %" where a group short of its value got further), or
// "" when no round was kept.
std::string steer_group(const FaceModel &model, const std::vector<std::string> &names,
                        const std::vector<std::pair<int, double>> &pattern, int vertex, const Eigen::Vector3d &along,
                        const PoseAction &action, double value, double cap, FactorCache *cache,
                        const std::function<SkinFaults(const Eigen::MatrixXd &)> &faults, Pose &pose, double &scale,
                        bool &capped, std::vector<std::pair<int, double>> *steered_pattern = nullptr);

}  // namespace afmb
