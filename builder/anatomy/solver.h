// The integrator: brings the tissue to static equilibrium under muscle forces,
// only on a dynamic node set (method paper sections 3.2 and 3.2.4).
//
// Unknowns: the epidermis, dermis and hypodermis nodes (layers 0-2) of the
// dynamic vertices, 3 coordinates each. Everything else (static vertices,
// every skull node) stays where X has it. Forces (docs/anatomy.md):
//   springs   biphasic, SkinModel::stiffness(); tangent stiffness
//             T'(l) u u^T + T / l (I - u u^T);
//   volume    per element, Lee, Terzopoulos and Waters' two terms in
//             energy form (docs/anatomy.md): E_v = k_v (V - V0)^2 / (2 |V0|),
//             force -k_v (V - V0) / |V0| dV/dp, Hessian
//             k_v / |V0| (dV/dp dV/dp^T + (V - V0) d2V/dp2); and the shape
//             term E_s = k_s |V0| / R^2 / 2 sum_i |d_i - mean(d)|^2 over the
//             element's 12 nodes, d = X - reference, R^2 the element's
//             squared radius of gyration at rest (their k2 term: each node
//             held at its rest place relative to the element's centre;
//             divided by R^2, a strain energy independent of the mesh
//             resolution), with the constant Hessian
//             k_s |V0| / R^2 (delta_ij - 1/12) I. `reference` is the
//             unloaded shape: the rest state, or the rest state carried by
//             the jaw for a jaw pose;
//   floor     off unless TissueParams::collapse_modulus k_c > 0: per slab s
//             that holds tissue (slab_holds_tissue), with J = V_s / V_s0,
//             E_c = k_c V_nom,s ((j0 - J) / j0)^3 below the knee j0
//             (collapse_knee), 0 above; V_nom,s the slab's depth share of
//             the element's nominal volume. Its tangent is the Gauss-Newton
//             part k_c V_nom,s psi''(J) / V_s0^2 dV_s/dp dV_s/dp^T only,
//             in both forms;
//   layers    off unless TissueParams::layer_volume_modulus k_l > 0: per
//             slab s that holds tissue, E_l = k_l (V_s - V_s0)^2 / (2 |V_s0|),
//             force -k_l (V_s - V_s0) / |V_s0| dV_s/dp, and its Gauss-Newton
//             part k_l / |V_s0| dV_s/dp dV_s/dp^T in both forms;
//             The tangent above is the full one. Its "projected" form drops
//             the compressed springs' negative T / l and the volume's
//             second-order part, and is positive semi-definite everywhere.
//             The solvers use the full tangent where it is definite and the
//             projected one where it is not (implicit-euler: always the
//             projected one); the newton solvers, after two projected
//             refreshes in a row, the full one with its diagonal raised by
//             1 + mu first (mu 1e-3 to 0.1) where that is definite;
//   muscles   the ForceField, a conservative load, with its Hessian;
//   skull     non-penetration as a constraint: a node below the plane of
//             its skull node (normal: the vertex's rest normal) is put back
//             on it and may only slide along it (the constraint filter of
//             Baraff and Witkin's modified CG); within one solve a node
//             once held stays held (releasing makes the active set
//             chatter). Skull-free vertices and vertices whose surface
//             faces the centre of gravity (lip curls, nostrils) are never
//             constrained;
//   eyeballs  the epidermal node of a vertex near an eyeball
//             (SkinModel::eye_near) is held off its sphere, grown by the
//             node's clearance in the pose (eye_clearance_in: the rest one
//             grown as its edges stretch), the same way: put back on it when
//             inside, then held with the sphere's tangent plane at the node,
//             renewed at every update, as its plane. A
//             node that also has a skull plane keeps it until it meets the
//             sphere;
//   lips      with SolverOptions::lip_contact, each lip pair's energy
//             (lip_contact.h): a cubic penalty on the upper lip's vertex
//             sinking below its partner on the lower lip, coupling the two
//             nodes (its Hessian is positive semi-definite: in both
//             tangents).
//
// Solvers (bench_builder compares them; docs/anatomy.md has the figures):
//   newton          Newton's method on the static equations. The step solves
//                   the (constraint-filtered) tangent system with CG
//                   preconditioned by an LDL^T factorisation (block_ldlt.h) of
//                   the filtered tangent itself, so CG takes one or two
//                   iterations, to SolverOptions::newton_forcing (an inexact
//                   step); the factorisation is reused while CG stays
//                   cheap and refreshed once a linear solve spends over a
//                   third of a factorisation's cost in CG iterations (counted
//                   from the pattern: deterministic); a CG run past a whole
//                   factorisation's worth stops and the step starts over
//                   with a fresh one. The fill-reducing
//                   ordering is computed once per dynamic set (FactorCache),
//                   and a solve on a set starts with the factorisation the
//                   last solve there ended on. After a step that moved no
//                   node more than 10 tol, and less than a quarter of the
//                   step before, the next one is made on the last full
//                   tangent (a chord step), assembling the force alone
//                   (SolverOptions::keep_tangent).
//                   The tangent: the Hessian where it is definite; where
//                   not, the one with half its indefinite parts (compressed
//                   springs' negative transverse stiffness, the volume's
//                   own curvature) where that is definite
//                   (SolverOptions::half_tangent), else the projected one
//                   without them, or after two projected ones in a row the
//                   Hessian with its diagonal raised (Levenberg-Marquardt).
//                   A backtracking (Armijo) line search on the total energy;
//                   a whole step made on the half, projected or shifted
//                   tangent, which is stiffer than the skin along the modes
//                   that compressed springs soften, is also tried at 2, 4 and 8
//                   times its length while the energy keeps falling
//                   (SolverOptions::extend_steps).
//                   The default: the fastest at the whole AFM in
//                   bench_builder (1.2 to 10 times the others on Song's
//                   irregular mesh), and no solve of it fails there.
//   newton-rest     the same, preconditioned by one factorisation of the
//                   rest-state Hessian of the set, shared by every solve on
//                   it (FactorCache), until CG needs more than 30 iterations.
//   implicit-euler  the paper's scheme: Baraff-Witkin implicit Euler steps
//                   (M (1 + h gamma) + h^2 K) dv = h (f - h K v), the modified
//                   (constraint-filtered) CG with a Jacobi preconditioner, run
//                   until the motion stops.
//   newton-jacobi   Newton with a Jacobi-preconditioned CG: no factorisation.
//
// Load control (calibration, section 3.3): with a LoadControl the load is
// `forces` + t x `unit_load`, and t is an unknown too, fixed by one more
// equation: action(X) = value. Each Newton step is the bordered one: with
// u = K^-1 r and w = K^-1 g (g the unit load), t moves by dt such that the
// linearised action of X + u + dt w meets the value, and the step is
// u + dt w (t grows at most fourfold per step, since the tissue stiffens,
// and falls at most by half). The solve fails when t would pass 50 times its
// first estimate (the tissue locks: LoadControl::unreachable), or fall below
// 1/50 of it, or below zero (the load moves the action the wrong way).
// With max_tension, t stops there and the solve finishes at that load.
// The newton solvers only.
//
// Stopping rule, the same for all three, with tol = SolverOptions::tolerance
// (afm-build passes half the AFM position quantum, so the result is exact to
// the stored grid, except along a soft mode, where the equilibrium is flat:
// the Jacobi estimate misses it, and Song's lids at their calibrated range
// stop 118-158 quanta short; docs/anatomy.md, "Stopping in flat directions"):
//   the last update moved no node more than tol, and the Jacobi estimate of
//   the remaining displacement, max over unknowns |r_i| / K_ii (residual
//   force over the diagonal stiffness), is below tol.
// The newton solvers measure it before a step too: where the estimate is
// below tol and the Newton step (under load control, with the action's
// linearised gap after it) is too, that step is taken whole and the solve
// ends, without a line search and another force and tangent to confirm.
// A solve that does not meet it within max_iterations, or meets a non-finite
// number, fails; so does a newton solve whose remaining displacement has not
// fallen below half its best for 60 iterations (it cycles: the generated
// heads' upper lids at their table turn; the converging solves of three
// heads' whole AFMs halve it every few iterations, and the AFMs are
// byte-identical with the rule and without). On failure `converged` is
// false, X holds the last finite iterate and `message` says why. Nothing in
// it is NaN.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "anatomy/skin_model.h"

namespace afmb {

enum class SolverKind { Newton, NewtonRest, ImplicitEuler, NewtonJacobi };
constexpr SolverKind kSolverKinds[] = {SolverKind::Newton, SolverKind::NewtonRest, SolverKind::ImplicitEuler,
                                       SolverKind::NewtonJacobi};
// "newton", "newton-rest", "implicit-euler", "newton-jacobi"
const char *solver_name(SolverKind kind);
bool solver_from_name(const std::string &name, SolverKind *kind);

// Solver work as plain numbers: SolveStats' counts summed over solves
// (SolveTotals::counts()).
struct SolveCounts {
  long long solves = 0, failed = 0, iterations = 0, cg_iterations = 0, factorisations = 0, assemblies = 0,
            energies = 0;
  SolveCounts operator-(const SolveCounts &o) const;  // the work between two snapshots
  // "S solves (F failed), I Newton iterations, C CG iterations, ..."
  std::string text() const;
};

// Work summed over the solves that share it (SolverOptions::totals): each
// solve adds its counts (SolveStats) when it ends, converged or not.
// Thread-safe: a builder's workers add to one. Deterministic for a
// deterministic sequence of solves (one worker); with several, a solve's
// warm start may depend on what its worker solved before it, and the counts
// with it, while the results do not.
struct SolveTotals {
  std::atomic<long long> solves{0}, failed{0}, iterations{0}, cg_iterations{0}, factorisations{0}, assemblies{0},
      energies{0};
  SolveCounts counts() const;  // a snapshot
};

struct SolverOptions {
  SolverKind kind = SolverKind::Newton;
  double tolerance = 0;       // model units, > 0 (see the stopping rule)
  int max_iterations = 0;     // Newton iterations or time steps; 0: 400 (Newton), 2000 (Euler)
  int max_cg = 4000;          // CG iterations per linear solve
  double cg_relative = 1e-5;  // implicit-euler: CG stops when the preconditioned residual fell by this
  // newton solvers: the same for each step's linear solve. A Newton step
  // need not be solved exactly (an inexact Newton method, Dembo, Eisenstat
  // and Steihaug 1982): the stopping rule on the positions is unchanged, so
  // the equilibrium is the same within the tolerance. 0.1 against 1e-5
  // (the old setting): CPU for Song's AFM 0.77 times, the 10k head's 0.84
  // (docs/anatomy.md, "Solver"), same reports.
  double newton_forcing = 0.1;
  // implicit-euler: step and mass-proportional damping in units of the
  // system's own time t0 = sqrt(mean mass / mean stiffness diagonal).
  double time_step = 20.0;
  double damping = 0.5;
  // newton solvers: a whole step made on the half, projected or shifted tangent
  // that the line search accepts is tried again at 2, 4 and 8 times its
  // length while the total energy keeps falling (see "newton" above).
  bool extend_steps = true;
  // newton solvers: where the full tangent is indefinite, the one with half
  // its indefinite parts first, kept where it is definite, before the
  // projected one (see "newton" above). Off: the projected one directly.
  bool half_tangent = true;
  // newton solvers: after a step that moved no node more than 10 tol and
  // less than a quarter of the step before (converging fast), the next one
  // is made on the last full tangent, and only the force is assembled (see
  // "newton" above). Off: a tangent every step.
  bool keep_tangent = true;
  // newton solvers, for tests: after each carried energy (SolveStats::
  // carried_energies), evaluate the whole one too and record the gap.
  bool check_carried_energy = false;
  // Hold the lips apart (SkinModel::lip_pairs, lip_contact.h; "lips" above).
  // Off for the FAP targets and the muscles' calibration: MPEG-4 moves each
  // lip by its own FAPs, and a FAP that presses one lip onto the other moves
  // it past the other's rest place (the player's sum of both lips' targets is
  // the pressed lips). On for poses of several groups at once: visemes and
  // expressions.
  bool lip_contact = false;
  // Not owned; when set, every solve adds its work to it (afm-build --stats).
  SolveTotals *totals = nullptr;
};

struct SolveStats {
  bool converged = false;
  int iterations = 0;     // Newton iterations or time steps
  int cg_iterations = 0;  // summed over every linear solve
  int factorisations = 0; // numeric factorisations of the tangent (newton)
  int half_steps = 0;     // Newton steps made on the half tangent (SolverOptions::half_tangent)
  int chord_steps = 0;    // Newton steps made on a kept full tangent, none assembled (SolverOptions::keep_tangent)
  int assemblies = 0;     // tangents assembled (each with the force at the same positions, or alone)
  int energies = 0;       // total energies evaluated (the newton solvers' line search)
  // Newton steps after which the contacts moved nodes and the line search's
  // tissue energy was carried over, with the change of the terms the moved
  // nodes are in, instead of evaluated again; and, with
  // SolverOptions::check_carried_energy, the largest gap between the carried
  // energy and the one evaluated there, relative to the latter.
  int carried_energies = 0;
  double carried_energy_gap = 0;
  int unknowns = 0;       // 3 x free nodes
  int contacts = 0;       // nodes held on the skull at the end
  double residual = 0;    // the Jacobi displacement estimate at the end, model units
  double last_step = 0;   // largest node motion of the last update, model units
  double seconds = 0;
  std::string message;    // why it failed; empty when converged
};

// Adds `more`'s work (the counts from iterations to carried_energies, and
// the seconds) to `into`'s, and keeps the larger carried_energy_gap; the
// rest of `into` stays.
void add_work(SolveStats &into, const SolveStats &more);

// The Hessian of a load's potential, as 3 x 3 blocks on single nodes
// (global node index, block): the loads here act node by node.
using NodeBlocks = std::vector<std::pair<int, Eigen::Matrix3d>>;

// A conservative external load: returns its potential energy at positions X;
// when F is given, adds its forces (4n x 3, model force units; only the rows
// of free nodes are read); when K is given, appends the Hessian of its
// potential (nothing for a dead load; must be positive semi-definite, since
// the projected tangent takes it as it is). Newton's line search minimises
// the total energy, springs + volume + this potential. Leaving out a load
// whose direction turns with the nodes stalls Newton: a sphincter pulling
// lips toward its epicentre did, 400 iterations at a thirty-second of a step.
using ForceField = std::function<double(const Eigen::MatrixXd &X, Eigen::MatrixXd *F, NodeBlocks *K)>;

// Per dynamic set (and skin model) and lip contact (on or off: with it the
// lip pairs join the pattern, and their coupling of the two lips costs
// fill-in in every factorisation): the unknowns, the Hessian's sparsity
// pattern, its fill-reducing ordering, the last newton factorisation, and
// the rest-state factorisation once a solver needed it; reused by every
// solve on the same set, so results depend on the order of the solves made
// with one cache (keep that order fixed for deterministic output). Not
// thread-safe: one cache per thread.
class FactorCache {
 public:
  FactorCache();
  ~FactorCache();
  struct Entry;
  Entry *find(const std::vector<int> &vertices, bool lip_contact) const;
  Entry *insert(const std::vector<int> &vertices, bool lip_contact, std::unique_ptr<Entry> e);
  size_t size() const { return entries_.size(); }
  void clear();

 private:
  std::map<std::pair<bool, std::vector<int>>, std::unique_ptr<Entry>> entries_;
};

// Solving for a tension as well (calibration): see "Load control" above.
struct LoadControl {
  ForceField unit_load;  // the load at tension 1
  // The controlled quantity at X (model units), adding its gradient (4n x 3)
  // to `gradient` when given.
  std::function<double(const Eigen::MatrixXd &X, Eigen::MatrixXd *gradient)> action;
  double value = 0;    // the action wanted
  double tension = 0;  // in: the start (0: from rest); out: the tension found (> 0)
  // > 0: the tension may not pass this. Once a step would, the tension stays
  // there, the action's equation is dropped, and the solve ends at the
  // equilibrium under that load with `capped` set (the action short of the
  // value): one solve instead of a failed one and a second.
  double max_tension = 0;
  bool capped = false;  // out
  // out: the solve failed because the tension passed 50 times its linear
  // estimate before the action got there (the tissue locks first).
  bool unreachable = false;
};

// Solves for equilibrium on `vertices` (sorted, unique skin vertex indices;
// vertices in no triangle are ignored), the shape term measured from
// `reference` (4n x 3), starting from X (4n x 3; also holds every fixed
// node) and writing the result into X. `cache` may be null (everything is
// then built for this call only). With `control`, the tension is solved for
// too and written back to control->tension on success.
SolveStats solve_equilibrium(const SkinModel &model, const std::vector<int> &vertices,
                             const ForceField &forces, const Eigen::MatrixXd &reference, Eigen::MatrixXd &X,
                             const SolverOptions &options, FactorCache *cache, LoadControl *control = nullptr);

// The rest state's linear displacement under `load` (4n x 3, zero outside
// `vertices`): K0^-1 f, no skull contacts. Cheap once the set's rest
// factorisation is cached; used to estimate how far a muscle's wave reaches.
Expected<Eigen::MatrixXd> linear_response(const SkinModel &model, const std::vector<int> &vertices,
                                          const ForceField &load, FactorCache *cache);

// The residual force (4n x 3, zero on fixed nodes) of positions X: springs,
// volume, the lips' contact when `lip_contact` (SolverOptions::lip_contact)
// and `forces`, for checks and tests.
Eigen::MatrixXd residual_forces(const SkinModel &model, const std::vector<int> &vertices,
                                const ForceField &forces, const Eigen::MatrixXd &reference,
                                const Eigen::MatrixXd &X, bool lip_contact = false);

// Whether the skull rejects vertex v's nodes (see the header comment).
bool skull_rejects(const SkinModel &model, int v);

}  // namespace afmb
