// The anatomical face model: skin tissue, muscles and jaw put together from a
// scene and its FDPs, calibrated, and posed (method paper sections 2 and 3).
//
//   FaceModel model = *build_face_model(scene, fdps, options);
//   Activation a;  a.muscles = {{model.find("zygomaticus_major_left"), 60.0}};
//   Pose pose = *solve_pose(model, a, &cache);
//   Eigen::MatrixXd skin = pose_epidermis(model, pose);   // #V x 3
//
// Contraction is in percent of each muscle's calibrated range (section 3.3):
// +100 % moves its key node by MuscleDef::max_fraction of the fibre length
// (or semi-axis) in the direction of its action, -100 % by min_fraction the
// other way; in between, the tension is interpolated linearly (the motion is
// then close to linear, not exactly: the springs are biphasic).
//
// Calibration (section 3.3): each side is one equilibrium solve with the
// tension as an unknown (solver.h, load control), so the key node's action
// is exact to the solver tolerance. It runs a newton solver whatever
// FaceModelOptions::solver says (implicit-euler cannot solve for a
// tension), and so does the jaw's calibrated full opening
// (Jaw::open_response), which every pose that opens the jaw starts from:
// implicit-euler found no equilibrium for it on Song within its 2,000
// steps. On a mirror-symmetric skin (FaceModel::mirror) a right muscle
// whose left twin is calibrated too waits for it and starts from the twin's
// calibrated poses mirrored, at its tensions, on its set joined with the
// twin's V_d mirrored (Song: mostly 2 to 7 Newton iterations a side instead
// of 4 to 14; the calibrations' CPU 2.7 -> 2.2 s).
//
// Dynamic node sets (section 3.2.4): every solve runs on a set of skin
// vertices; the rest stay exactly where they are. A muscle's set V_d starts
// from the rest state's linear response (where the wave at the larger
// calibrated action exceeds half the wave threshold; the whole connected
// skin's response, from one rest factorisation shared by all muscles), and both
// calibration solves grow it by rings until no vertex on the set's border
// moves more than the wave threshold (by default kWaveQuanta AFM quanta):
// the elastic wave has died out. A pose solves on the union
// of its muscles' (and the jaw's) sets and grows it again if the combination
// reaches further. The jaw's set is its full opening's; a partial opening
// starts where that opening's calibrated response, scaled to it, exceeds
// half the wave threshold.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "anatomy/jaw.h"
#include "anatomy/mirror.h"
#include "anatomy/muscles.h"
#include "anatomy/skin_model.h"
#include "anatomy/solver.h"
#include "core/fapu.h"
#include "core/fdp.h"
#include "core/scene.h"

namespace afmb {

// The default wave threshold, in AFM position quanta. The vertices left out
// of a set would move less than that; the dynamic result stays within one
// quantum of the whole mesh's (0.40 of one on the 1k head's zygomaticus
// major, tests/anatomy; bench_builder up to 0.68 on Song; 0.08-0.20 at half
// a quantum), and the sets are 9-25 % smaller than at half a quantum (the
// three heads' whole AFMs: 14-26 % less CPU time; docs/anatomy.md).
constexpr double kWaveQuanta = 2;

struct FaceModelOptions {
  TissueParams tissue;
  SolverOptions solver;          // tolerance 0: half the AFM position quantum of the scene
  double wave_threshold = 0;     // model units; 0: kWaveQuanta AFM quanta
  bool estimate_missing_fdps = true;  // fdp_completion.h; off: skip (or fail on) their muscles
  bool calibrate = true;         // off: no calibration, no V_d (pictures of the placement only)
  // Calibrate only these muscles (names; empty: all) and the jaw only when
  // `calibrate_jaw`. Posing an uncalibrated muscle is an error. For tests and
  // tools that need a few muscles of a big model.
  std::vector<std::string> calibrate_only;
  bool calibrate_muscles = true;  // off: no muscle, whatever calibrate_only says
  bool calibrate_jaw = true;
  // Workers for the calibration (muscles and the jaw are independent); 0: one
  // per core. The model is the same whatever the number.
  int threads = 0;
  // Called after each step of the build: done of total, and what was done.
  // The placement steps come first (1..4 of 4), then the calibration tasks
  // (1..N of N, in the order they finish; from the worker threads, one call
  // at a time).
  std::function<void(int done, int total, const std::string &what)> progress;
};

struct FaceModel {
  int skin = -1;                 // scene part index
  FdpSet fdps;                   // the input's FDPs plus estimates
  Fapu fapu;
  SkinModel tissue;
  std::vector<Muscle> muscles;   // placed muscles, in table order
  Jaw jaw;
  double quantum = 0;            // AFM position step (afm_position_quantum)
  SolverOptions solver;          // tolerance filled in
  double wave_threshold = 0;
  // The skin's mirror symmetry (mirror.h), found between the pupils (FDPs
  // 3.5 and 3.6) to a thousandth of their separation; not symmetric without
  // them.
  SkinMirror mirror;
  std::vector<std::string> notes;     // FDP estimates
  std::vector<std::string> warnings;  // skipped muscles: the FDPs they lack, or why calibration failed

  int find(const std::string &muscle) const;  // index into muscles, or -1
  // The muscle's twin on the other side (..._left and ..._right), or -1.
  int twin(int muscle) const;
};

// Fails on: no skin part (FDP 2.1), a skin that check_skin() refuses
// (non-manifold, degenerate), FDPs not in the MPEG-4 frame
// (check_orientation), a skin facing inward or not wrapping its centre (not
// a face), a missing FDP of an essential muscle or of the jaw, and a
// calibration of an essential muscle or of the jaw that does not converge.
// A muscle that is not essential and lacks FDPs or cannot be calibrated is
// left out of `muscles`, with a line in `warnings` saying why.
Expected<FaceModel> build_face_model(const Scene &scene, const FdpSet &fdps,
                                     const FaceModelOptions &options);

// A lid turned as a whole, about its driver's axis through the eyeball's
// centre (the palpebral part of orbicularis oculi closing the lid's tarsal
// plate, or levator palpebrae opening it).
struct LidTurn {
  int muscle = -1;       // a lid driver, index into FaceModel::muscles
  double angle = 0;      // radians; positive closes
  double clearance = 0;  // model units the tarsus's epidermis is held further off the eyeball (>= 0)
};

struct Activation {
  std::vector<std::pair<int, double>> muscles;  // (index into FaceModel::muscles, percent -100..100)
  double jaw_open = 0, jaw_thrust = 0, jaw_shift = 0;  // percent (open >= 0)
  // Lids turned as a whole (place_turned_lid): the tarsus is placed and
  // held there, the rest of the skin follows through the tissue. The lid
  // driver's own load is not applied.
  std::vector<LidTurn> lids;
};

struct Pose;

struct PoseOptions {
  bool whole_mesh = false;  // solve on every skin vertex instead of the dynamic set
  const SolverOptions *solver = nullptr;  // override the model's
  // Start from this pose (a solve_pose result of the same model, or a
  // superposed_pose) instead of the rest state: its nodes are the first
  // guess, the jaw's vertices carried from its jaw motion to this one's, and
  // its dynamic set joins this one's.
  // A nearby activation then takes a few Newton iterations instead of a solve
  // from rest, and follows the same branch where the tissue has two
  // equilibria (Song's chin snaps through as the jaw opens). Null: from rest.
  const Pose *start = nullptr;
};

struct Pose {
  Eigen::MatrixXd X;          // 4n x 3 node positions
  std::vector<int> dynamic;   // the vertices solved, sorted
  SolveStats stats;           // of the last solve (summed iterations over the growth rounds)
  int rounds = 0;             // solves (1 + growth rounds)
  Eigen::Affine3d jaw = Eigen::Affine3d::Identity();  // the jaw's motion in it
};

// Fails when the solver fails (the message says why); never returns an
// unconverged pose.
Expected<Pose> solve_pose(const FaceModel &model, const Activation &activation, FactorCache *cache,
                          const PoseOptions &options = {});

// Where a lid turned as a whole (Activation::lids) puts the skin. X (4n x 3)
// in: the unloaded state (the rest, or the rest carried by the jaw); out:
// the lid's influence area turned about its axis, each vertex by the angle
// times its Muscle::turn_share, and the tarsus's epidermis held off the
// eyeball as the solver holds free skin (eye_clearance_in over the tarsus's
// own edges) plus lid.clearance. Turning about the eyeball's centre keeps
// the lid as far off the ball as at rest. *held (when given; sized to the
// skin's vertices) gets the tarsus's vertices flagged. Fails for a muscle
// that is not a lid driver with its eyeball.
Status place_turned_lid(const FaceModel &model, const LidTurn &lid, Eigen::MatrixXd &X, std::vector<char> *held);

// A quantity of a pose to steer (model units), adding its gradient (4n x 3)
// to `gradient` when given; it must grow with the load.
using PoseAction = std::function<double(const Eigen::MatrixXd &X, Eigen::MatrixXd *gradient)>;

// The pose in which `action` reaches `value`: the muscles of `pattern`
// (percent, -100..100 each) scaled together by one factor s > 0, found with
// the pose (solver.h, load control). s above 1 extrapolates the calibrated
// tensions linearly. *scale gets s. With max_scale > 0, s stops there: the
// pose is then the equilibrium at s = max_scale, its action short of
// `value`, and *capped (when given) is set. Fails as solve_pose does, and when
// the group cannot take the action to `value` (the message says how far it
// got).
//
// With `from`, the solve starts from from->pose (found before for the same
// pattern and action, at scale from->scale) instead of the rest state, on
// its set, and may take from->max_iterations Newton iterations (0: the
// model's solver's) before it fails.
struct SteerFrom {
  const Pose *pose = nullptr;
  double scale = 0;
  int max_iterations = 0;
};
Expected<Pose> solve_pose_to(const FaceModel &model, const std::vector<std::pair<int, double>> &pattern,
                             const PoseAction &action, double value, FactorCache *cache, double *scale,
                             double max_scale = 0, bool *capped = nullptr, const SteerFrom *from = nullptr);

// X (4n x 3) mirrored: each node takes its image's displacement from the
// rest, reflected in the mid-plane (FaceModel::mirror); nodes whose vertex
// has no image stay at rest. A first guess for the other side's pose. The
// model must be mirror-symmetric.
Eigen::MatrixXd mirrored_nodes(const FaceModel &model, const Eigen::MatrixXd &X);

// The images of a sorted set of skin vertices (those with one), sorted.
std::vector<int> mirrored_vertices(const FaceModel &model, const std::vector<int> &set);

// The epidermis of a pose, #V x 3 (the skin part's vertex positions).
Eigen::MatrixXd pose_epidermis(const FaceModel &model, const Pose &pose);

// A first guess, not an equilibrium: the rest carried by the jaw's motion,
// plus its calibrated full opening (Jaw::open_response) scaled by the
// opening / 100, plus the muscles' calibrated poses (Muscle::response_max or
// _min) scaled by |percent| / 100, on the union of their dynamic sets. (Thrust
// and shift have no calibrated pose: the carried rest.) As PoseOptions::start or
// SteerFrom::pose it halves the Newton iterations of a pose that combines
// muscles (Song's visemes and expressions: 54 iterations against 109 from
// rest, the same equilibria within the tolerance for 10 of 12). The tissue is
// not linear, so the guess is not the pose: two mouth muscles together move
// the 1k head's mouth corner up to a fifth more or less than the sum.
Pose superposed_pose(const FaceModel &model, const Activation &activation);

// What is wrong with an epidermis E (#V x 3, model units) as a face: skin
// triangles whose normal turned against its rest one (slivers under a
// thousandth of the mean area left out); vertices tied to the skull that
// went more than one AFM quantum below their skull node's rest plane (the
// jaw's vertices left out: the jaw moves their bone; within a quantum, the
// stored target cannot tell them from resting on the bone); and triangles
// stretched to more than kTearStretch times their rest area, which skin does
// not survive (Song's left upper lid pulled off the eyeball by the brows).
// `any` is the strict test of a FAP target. `tears` weighs the shares, for
// visemes, expressions and the muscles' calibration: a fold turns a few
// triangles over (slivers at Song's mouth corners, 6e-6 of the skin's area,
// in every smile; the crease at its left eye's outer corner in joy, 2.7e-4,
// where the eyeball shows through), a tear far more (surprise pulled Song's
// left upper lid off the eyeball: 3.4e-3 stretched, 5.7e-3 turned).
constexpr double kTearStretch = 3;
constexpr double kTornShare = 1e-4;
//
// A model built on a simulation mesh (sim_mesh.h) stores its targets on the
// input's own skin, lifted from the coarse one; that skin can fold where the
// coarse one does not (a fine triangle steeper than the coarse one it is
// bound to, as the coarse one turns). skin_faults leaves `lifted_*` empty;
// fap_synthesis fills them (lifted_turned_faces).
struct SkinFaults {
  std::vector<int> turned_faces;      // skin triangles, ascending
  std::vector<int> stretched_faces;   // skin triangles, ascending
  std::vector<int> sunk_vertices;     // skin vertices, ascending
  std::vector<int> lifted_turned_faces;  // the input skin's triangles, ascending
  double turned_share = 0;            // rest area of turned_faces over the skin's, 0..1
  double stretched_share = 0;         // rest area of stretched_faces over the skin's, 0..1
  double lifted_turned_share = 0;     // the same of lifted_turned_faces on the input skin
  bool any() const { return !turned_faces.empty() || !sunk_vertices.empty() || !lifted_turned_faces.empty(); }
  bool tears() const {
    return !sunk_vertices.empty() || turned_share > kTornShare || stretched_share > kTornShare ||
           lifted_turned_share > kTornShare;
  }
  // What no untangling mends (untangle.h), whatever turns over: vertices
  // sunk into the skull, or triangles stretched beyond kTearStretch over
  // more than kTornShare of the skin. How a FAP's pose is judged
  // (fap_synthesis.cpp, target_faults).
  bool breaks() const { return !sunk_vertices.empty() || stretched_share > kTornShare; }
};
SkinFaults skin_faults(const FaceModel &model, const Eigen::MatrixXd &E);

// The triangles F (#F x 3) that turn over from V0 to V (#V x 3 each): their
// normal at V points against the one at V0. Triangles under a thousandth of
// the mean rest area are left out (slivers whose rest normal is noise).
// Ascending; *share, when given, gets their rest area over the total, 0..1.
std::vector<int> turned_faces(const Eigen::MatrixXd &V0, const Eigen::MatrixXi &F, const Eigen::MatrixXd &V,
                              double *share = nullptr);

// The same with the rest triangles' normals computed once (rest_faces), for
// a mesh checked many times: the same result.
struct RestFaces {
  std::vector<Eigen::Vector3d> normal;  // #F: each rest triangle's normal, twice its area long
  Eigen::VectorXd length;  // #F: those lengths
  double total = 0;        // their sum
};
RestFaces rest_faces(const Eigen::MatrixXd &V0, const Eigen::MatrixXi &F);
std::vector<int> turned_faces(const RestFaces &rest, const Eigen::MatrixXi &F, const Eigen::MatrixXd &V,
                              double *share = nullptr);

// The signed tension of muscle i at `percent` contraction.
double muscle_tension(const Muscle &m, double percent);

}  // namespace afmb
