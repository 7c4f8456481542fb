// FAP synthesis (method paper section 4): one morph target per low-level FAP
// (and per side of a bidirectional one), from the anatomical face model and
// the mapping of fap_mapping.h.
//
// For each FAP with a muscle group: the group is scaled by one factor found
// with the pose (face_model.h, solve_pose_to) so that the FAP's FDP moves by
// reference x FAPU along the FAP's direction (negative side: -reference);
// the pose's epidermis minus the rest is the target. The jaw FAPs (3, 14,
// 15) set the jaw's rotation or translation so that the chin (2.1) moves by
// the same rule, then solve the tissue around it (secant steps, each from
// the pose of the largest motion solved so far not past its own); the jaw's rigid parts
// (lower teeth, tongue) get a control with the same motion, bent at FAP 3's
// in-betweens (afm/rigid_parts.h, piecewise_controls), so that at each
// target's value the teeth are where its bone is.
//
// The tongue's FAPs (43-47) are no solve: the tongue part's own motion
// (anatomy/tongue.h), exact at its FDP, where the face has a tongue with
// FDPs 6.1-6.4 (else not made, and the outcome says what is missing). The
// visemes add theirs (HighLevelMapping::parts) under the jaw's motion.
// Nor are the pupils' (29, 30): an eye part's pupil dilates where it has
// pupil geometry (anatomy/pupil.h); their outcomes' prescribed and achieved
// motions are the growth of the pupil's diameter, along x. Fear and
// surprise widen them.
//
// In-betweens (FapMapping::farther; formats/afm.md): the same solve at each
// farther reference, kept only where the group reaches it in full. The
// player blends a side's targets piecewise linearly, so a lid follows its
// arc over the eyeball up to there, and the jaw's skin its bone (the chin's
// skin lags the bone more the wider the jaw opens).
//
// An eyelid FAP's closing side whose lid driver was calibrated to less than
// the table's range (the generated heads: no equilibrium at their lids'
// 50-degree turn) turns the lid as a whole instead (face_model.h,
// Activation::lids): the turn that brings the FDP down by the value, found
// by bisection on the placement, up to the turn where the lids meet; an
// in-between short of that is made at the value where they meet (its
// reference), and dropped when that is not past the side's nearer target.
// So does an in-between that a driver's load falls short of, kept where the
// skin stays a face.
// On a simulation mesh the tarsus is held further off the eyeball by what
// the lifted skin over it sinks below its clearance, in one more solve.
//
// FAP 3's targets leave the lower lip's height to the lip's FAPs, whose
// negative sides go on past their reach as the jaw would carry the lip
// (jaw_lips.h). A lip corner's FAP moves the skin around the corner with it ("The
// modiolus" below). FAP targets that move the same skin (the inner and
// outer lip FAPs, the midlip and mid-left/right ones, the brows, ...) then
// split it between
// them (fap_partition.h), so that a stream sending them together moves each
// FDP once; the outcomes are measured on the split targets.
//
// Every target also carries the parts that ride on the skin (lashes, lid
// and brow strips: skin_binding.h), by the skin's displacement under them.
//
// No solve starts from rest where a better first guess is at hand: a muscle
// group's first from its muscles' calibrated poses added (face_model.h,
// superposed_pose), scaled to the share that would reach the value if the
// tissue were linear; a viseme's or expression's the same way, or from the
// pose of the last share kept while bisecting; a jaw FAP's secant steps from
// the pose of the largest motion solved so far not past their own. On Song
// the whole AFM then takes 1,488 Newton iterations instead of 1,950 and the
// same targets (the report's figures unchanged; one FAP lands on the other
// side of a snap-through, as its mirror twin already did).
//
// Mirror twins (anatomy/mirror.h). On a mirror-symmetric skin a right
// FAP's side (FAPs 7, 9, 11, 13, 20, 22, ...: "_r_", "_rm") waits for its left
// twin's and starts from its recipe: the twin's group with the helpers its
// steering kept (their contractions mirrored), its scale and cap, and its
// pose mirrored, in one solve under the load control. The result is kept
// where it ends as the twin's did (reaching the value, or at the cap short
// of it), turns no skin the twin's did not, and misses the prescribed motion
// (off the FAP's direction, or in all where short of the value) by at most
// kSteerGain of the value more than the twin's; else the target is made as
// above. The outcome's message says so ("steered as its mirror twin by ...",
// "... (its mirror twin's finding)"). Song: the right FAPs' CPU 2.7 -> 1.1 s,
// the report's figures unchanged. A right FAP listed alone (only) has its
// twin made too, and dropped, so its target is the one the whole AFM has.
//
// Visemes and expressions (fap_mapping.h, HighLevelMapping): the table's
// muscles and jaw opening posed once; the target holds the skin and, when
// the jaw opens, the jaw's rigid parts carried by it (these targets have no
// rigid control). Where that pose tears the skin (SkinFaults::tears), or
// keeps a triangle turned once untangled as it is stored, the muscles to
// blame (their influence holds the largest turned or stretched triangles
// or a sunk vertex; both sides of a pair) are bisected to the largest
// share that does neither, to a sixteenth, the others kept; failing
// that, everything together. The outcome's message says what is made at
// what share.
//
// The scale is first found within the muscles' calibrated range (s <= 1,
// s = 1: the table's contractions at 100 %). A group that falls short there
// gets one more solve, from that pose, that may pass the range with its
// tensions extrapolated up to kMaxFapScale (and, still short there with the
// skin a face, one more from there up to kFurtherFapScale), each within a
// budget of Newton iterations (none where the skin already folds at s = 1,
// where the FDP moves the wrong way at s = 1: the load control steers an
// action that grows with the load, or where it moves less than a FAP unit);
// its pose is kept if the skin stays a face as the target would store it,
// the triangles it turns untangled (untangle.h, with the FAP's FDP fixed;
// not where the skin sinks or stretches past a tear, SkinFaults::breaks,
// nor at the lip corners, where streams add the targets' slivers up to
// folds): face_model.h, skin_faults: no skin
// triangle turned over, nothing below the skull; on a simulation mesh,
// none of the lifted skin's either (FapSynthesisOptions::sim). Where it
// does not, a pose short of the fold that does (one more solve, to 3/4 of
// the way along which the chord between the two poses keeps the skin a
// face; not for a group that moves its FDP less than a FAP unit at s = 1);
// failing that, the pose at s = 1. A group that cannot reach the reference
// makes its target at that cap: the target under-reaches (the outcome says
// by how much and why). A group that moves its FDP the wrong way, or by less than a
// FAP unit, gets no target.
//
// Reach, then hold. An under-reaching side's pose is stored twice: scaled
// to the whole FAP units it reaches, r = floor(reached x reference), as the
// side's target at r, and as it is, as an in-between at the table's
// reference (FapOutcome::holds). The player blends a side's targets
// piecewise linearly (formats/afm.md), so a value up to r moves the FDP by
// value x FAPU, as MPEG-4 says, and past r the face holds the group's most
// (it grows by the floor's rounding up to the reference, and past the
// reference goes on at that slope). Stored once at the table's reference,
// as before, every value moved the FDP by `reached` of its prescription:
// Song's chin raised (FAP 18) by 28 % of what a stream asked at any value.
// (Stored once at r, a stream's values past it extrapolated the pose: real
// streams then took small targets up to 90 times and tore the face.) Not
// held: a positive side whose negative values would extrapolate it (a
// bidirectional FAP without a negative-side target), the jaw's and the
// lids' FAPs, and a side with in-betweens of its own.
// FapSynthesisOptions::hold_reach = false stores the pose once, at the
// table's reference.
//
// Held past the reference. A lip corner's FAPs move one FDP between them
// (the inner and outer lip's: each moves it by a share), and streams send
// them together, up to kCornerStreamReach times their reference (Xface's
// joy.fap stretches the corners to 110 of 70). Where such a side's target
// and its partners' at the same value, summed and taken that far, turn the
// skin over (the input's too, as the player shows it), the side's target is
// also stored as an in-between at that value (FapOutcome::past_reference):
// past its reference the corner holds the reference's pose instead of
// going on, and the sum at the reference is the most the streams show.
// Song's corners stretched (6, 7, 53, 54), which reach their reference
// past the table's contractions: extrapolated, joy.fap and anger.fap turned
// 2-4 triangles of the cheek in 12-13 frames each. Not for a side that
// holds its reach already.
//
// Second groups (FapMapping::second_positive, _negative). A side whose own
// group falls short of the reference is made again with its second group,
// in the same task right after (mirror twins as above: a right side's
// waits for its left twin's), and the target whose FDP lands nearer the
// prescribed motion (|achieved - prescribed|) is kept, the other's
// outcome message saying so; a kept second group's
// target is the side's only one, reaching, then held, as any. Kept whole
// rather than as an in-between past the own group's reach: Song's upper lip
// sides (FAPs 8, 9, 55, 56) as in-betweens at the reference, 8 to 19 FAP
// units past the reach, were extrapolated along their short last segment,
// and Xface's disgust.fap took 8.5 44 % off its prescribed motion (7.5 %
// with the one target). FapSynthesisOptions::second_groups = false: the
// own groups alone.
//
// Helpers (steer.h; FapMapping::helpers): where a group's pose, at the
// value or at its cap, moves the FDP off the FAP's direction by more than
// kSteerAbove of the prescribed motion, the row's helpers join the group at
// contractions chosen to cancel that motion, and the group is solved again
// under the same load control from the pose reached (up to kSteerRounds
// solves). A round is kept only where the off-axis motion falls, the group
// reaches no less than before, and the skin sinks and tears no more; the
// outcome's message names the helpers. FapSynthesisOptions::steer = false
// leaves the groups alone.
//
// What is measured per target (the fidelity report): the prescribed FDP
// displacement, the achieved one, the error along the FAP's direction and
// off it, both relative to the prescribed length. Along the direction the
// error is the solver's tolerance by construction, or 1 - reached where the
// group under-reaches; off it is the anatomy's answer.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "afm/afm_export.h"
#include "anatomy/face_model.h"
#include "anatomy/sim_mesh.h"
#include "core/status.h"

namespace afmb {

// How far a FAP's muscle group is scaled beyond its table contractions: up
// to kMaxFapScale in one solve from its pose at s = 1, and where it is still
// short there with the skin a face (a weak group, not a folding one), up to
// kFurtherFapScale in one more from that pose (Song's nose wings narrowed:
// 80 % of the reference at 4, all of it at 5.3).
constexpr double kMaxFapScale = 4;
constexpr double kFurtherFapScale = 8;
// How far past their reference streams send the lip corners' FAPs, in
// references: the in-between that holds them ("Held past the reference").
constexpr double kCornerStreamReach = 1.6;

struct FapOutcome {
  afm_target_kind kind = AFM_TARGET_FAP;
  int number = 0;                 // FAP 3..68, viseme 1..14 or expression 1..6, after `kind`
  int side = +1;                  // +1: the positive reference, -1: the negative one
  int reference = 0;              // signed FAP units (63 for visemes and expressions)
  bool in_between = false;        // one of FapMapping::farther (made only where reached in full),
                                  // a hold, a lower lip side past its reach (jaw_lips.h), or
                                  // a lip corner held past its reference
  bool holds = false;             // an in-between at the table's reference holding an
                                  // under-reaching side's pose ("Reach, then hold")
  bool at_reach = false;          // that side's target at the FAP units it reaches
  bool from_jaw = false;          // a lower lip side past its reach (jaw_lips.h), not solved:
                                  // its in-between at FAP 3's farthest reference holding the
                                  // side's pose, or (kind AFM_TARGET_COMBINATION) what FAP 3's
                                  // target adds to it there
  bool past_reference = false;    // an in-between past the table's reference holding a lip
                                  // corner's pose there ("Held past the reference")
  bool made = false;              // a target was made
  std::string message;            // why not, when !made; how far it reaches when it under-reaches
  double reached = 1;             // the achieved share of the prescribed motion along the
                                  // direction when the group under-reaches (< 1), else 1
  Eigen::Vector3d prescribed = Eigen::Vector3d::Zero();  // FDP displacement, model units
  Eigen::Vector3d achieved = Eigen::Vector3d::Zero();
  double along_error = 0;         // |achieved . dir - prescribed . dir| / |prescribed|
  double off_axis = 0;            // |achieved - (achieved . dir) dir| / |prescribed|
  // The off-axis motion split (off_axis^2 = off_face^2 + off_depth^2):
  // across the face, its x and y in the MPEG-4 frame (what a frontal view
  // shows), and in depth, its z (toward the viewer or back).
  double off_face = 0, off_depth = 0;
  // Visemes and expressions have no FDP rule: prescribed, achieved and the
  // errors stay zero; `largest` says how far the face moved.
  double largest = 0;             // the largest skin vertex displacement, model units
  double scale = 0;               // muscle groups: the factor on the table's contractions;
                                  // visemes and expressions: on the muscles the message
                                  // names (1: the table's pose); a lid turned as a
                                  // whole: its turn, radians; jaw FAPs: percent / 100
  int turned = 0;                 // skin triangles the target turns over (turned_faces), on
                                  // the input's skin once lifted (lift_synthesis)
  int sunk = 0;                   // skull-tied skin vertices the target takes more than an
                                  // AFM quantum below their skull node's rest plane
                                  // (skin_faults), on the simulated skin
  int slabs = 0;                  // slabs of tissue that the solved pose turns through
                                  // themselves (turned_slabs, skin_model.h): inside the
                                  // tissue, not in the target, which stores the skin
  int dynamic = 0;                // vertices solved
  bool mirrored = false;          // made from its left twin's recipe ("Mirror twins" above)
  double seconds = 0;
};

// Whether a made outcome is a FAP target the face model solved (muscles,
// jaw, lids): the ones the fidelity figures summarise. The tongue's and the
// pupils' (kinematic_fap) and the lower lip's holds and combinations past
// its reach (from_jaw) are exact by construction (with the jaw), a lip
// corner held past its reference (past_reference) stores its reference's
// pose, and visemes and expressions have no FDP rule.
bool solved_fap_target(const FapOutcome &o);

// Whether a made outcome's pose is its own solve, counted once where a
// synthesis sums what its poses do (FapOutcome::slabs): a solved FAP target,
// a viseme or an expression; not a hold, which stores its reach's pose.
bool solved_own_pose(const FapOutcome &o);

struct FapSynthesisOptions {
  // What to make. All three empty: every mapped FAP, viseme and expression;
  // otherwise only those listed.
  std::vector<int> only;          // FAP numbers
  std::vector<int> only_visemes;  // 1..14
  std::vector<int> only_expressions;  // 1..6
  bool negative_sides = true;     // make the negative side's own target where the table has one
  // Let helpers steer a group's FDP back onto the FAP's direction (steer.h);
  // false: the table's groups act alone.
  bool steer = true;
  // Store an under-reaching side's pose at the FAP units it reaches and hold
  // it to the table's reference ("Reach, then hold"); false: once, at the
  // table's reference.
  bool hold_reach = true;
  // false: no lip corner is held past its reference ("Held past the
  // reference"), for tests of what the targets alone are.
  bool hold_past_reference = true;
  // Make a side its own group leaves short again with its second group
  // (FapMapping::second_positive, _negative) and keep the nearer ("Second
  // groups"); false: the own groups alone.
  bool second_groups = true;
  // Workers (0: one per core). The targets are the same for any number.
  int threads = 0;
  // The simulation mesh the model was built on (sim_mesh.h), when it is
  // decimated: the skin the targets are lifted to may not fold either
  // (SkinFaults::lifted_turned_faces), and the synthesis is lifted to it
  // (lift_synthesis) before it is returned. Not owned; null: the model's
  // skin is the input's.
  const SimMesh *sim = nullptr;
  // Called after each target: done of total, and which (from the workers,
  // one call at a time).
  std::function<void(int done, int total, const std::string &what)> progress;
};

// What a synthesis with `options` poses, for a model built only for it
// (FaceModelOptions::calibrate_muscles, calibrate_only, calibrate_jaw): the
// muscles of every listed FAP's groups, both sides, their fallbacks and
// second groups, and of every listed viseme and expression, and of a listed
// right FAP's left twin (made and dropped: see "Mirror twins"), with every
// right muscle's left twin (face_model.h: it calibrates from it); the jaw
// for the jaw FAPs and a viseme or expression that opens it. Each muscle calibrates on its own, so
// the poses are the same as on a model with every muscle calibrated (the
// targets split shared skin only among those made: fap_partition.h).
// Nothing listed: every muscle and the jaw (`all`).
struct CalibrationNeeds {
  bool all = true;
  std::vector<std::string> muscles;  // names, in table order of first use, once each
  bool jaw = true;
};
CalibrationNeeds calibration_needs(const FapSynthesisOptions &options);

struct FapSynthesis {
  // The made ones: FAPs in number order (positive side first), then the
  // visemes, then the expressions.
  std::vector<MorphTarget> targets;
  std::vector<FapOutcome> outcomes;  // every attempted one, in the same order
  RigidPart jaw;                     // the jaw's rigid parts and controls (parts empty: none)
  // Parts carried by the skin (lashes, lid strips), bound to the skin the
  // synthesis ran on.
  std::vector<SkinBinding> carried;
  // After lift_synthesis on a decimated simulation mesh: the simulation
  // vertices as the AFM's control points (each target's `controls`).
  ControlLift lift;
};

// Fails only on a model without skin; a FAP that cannot be made is an
// outcome with made = false.
Expected<FapSynthesis> synthesize_faps(const Scene &scene, const FaceModel &model,
                                       const FapSynthesisOptions &options = {});

// The modiolus. A FAP whose FDP is a lip corner (2.4, 2.5, 8.3, 8.4: FAPs
// 6, 7, 12, 13, 53, 54, 59, 60) moves the skin within kModiolusRadius x MW0
// of that corner with it, as the modiolus, the knot of fibres where the lip
// and cheek muscles meet beside the corner, carries it: before the split of
// shared skin, each vertex there takes a blend of its solved motion and the
// corner's, the corner's weight (1 - (r / R)^2)^2 at rest distance r (1 at
// the corner, 0 and flat at R). Why: Song's corner is a fan of slivers a
// tenth of a unit wide, and the solve moves the skin around it unevenly
// (raised, a neighbour 0.3 units off goes 0.14 units further out than the
// corner; lowered, the corner goes 1.30 units and a vertex 0.9 away 0.79,
// with 1.3-unit motions over slivers 0.1 wide): the corner's
// whole pose turned 7 triangles, and the inner and outer corner FAPs sent
// together, as streams send them, turned 4-5 at each corner (joy.fap: some
// in 94 of its 108 frames). With R = 0.13 MW0 (3.3 units on Song, 6.6 mm on
// the generated heads) none turn; at 0.1 one did, lowered, where the blend
// ends. The FDP's own motion, which the report measures, is unchanged.
constexpr double kModiolusRadius = 0.13;

// Blends D (#V x 3, model units: the displacement of V0, #V x 3) toward
// the motion of vertex `corner` within `radius` (model units) of it at rest,
// as above. Nothing changes for radius <= 0 or a corner out of range.
void move_modiolus(const Eigen::MatrixXd &V0, int corner, double radius, Eigen::MatrixXd &D);

// The targets a combination target plays with, as a stream that asks for
// it sends them (fap_synthesis.cpp judges and the report draws it so):
// every combination of its gate at its gate reference and reference (itself
// included), the FAP targets they follow, and the gate's target at its
// reference. Indices into `targets`; empty when targets[c] is no
// combination.
std::vector<size_t> played_with(const std::vector<MorphTarget> &targets, size_t c);

// Carries a synthesis made on a simulation mesh (sim_mesh.h: the model built
// on sim_scene) to the skin. synthesize_faps does it when given the mesh
// (FapSynthesisOptions::sim), and only then is the lifted skin checked for
// folds: called on a synthesis made without it, the lift is blind to them.
// What it does: every target's skin displacement becomes #V x 3 over the
// skin's own vertices, and the `largest` of each viseme and expression and
// the `turned` of each target are measured there (a combination's as
// played_with says). The simulation mesh's displacement becomes the
// target's `controls`, and `lift` binds the skin and the carried parts to
// them (formats/afm.md, LIFT). Nothing changes when the simulation mesh is
// the skin, or on a synthesis already lifted.
void lift_synthesis(FapSynthesis &synthesis, const SimMesh &sim);

// The AFM's content: the scene, its input FDPs (bound to `scene`; not the
// model's estimates), the model's FAPU, the synthesis' targets, the eye and
// head rigid parts (afm/rigid_parts.h) and the jaw's, when it has parts.
AfmContent fap_afm_content(const Scene &scene, const FdpSet &fdps, const FaceModel &model, FapSynthesis synthesis);

}  // namespace afmb
