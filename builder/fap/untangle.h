// Untangling the slivers a target turns over.
//
// Why: a solved pose can turn a few skin triangles over where the mesh is
// much finer than the motion. The springs keep lengths, not a sliver's
// facing. Song's mouth corners hold a fan of slivers a tenth of a
// millimetre wide between the lower lip, which the jaw carries, and the
// upper lip, which stays; opening the jaw turned a dozen of them, and as
// many when the skin was solved on all of Song's vertices: a finer
// simulation does not help.
//
// The rule: the corners of each turned triangle join one patch, and each
// patch takes the affine motion nearest the solved one (least squares over
// its members). An affine motion stretches and shears the patch evenly: a
// sliver inside turns only if the whole patch does. A patch inside which a
// triangle still turns moves as one piece instead (the mean of its
// members' motion), which turns nothing inside. Triangles that turn then,
// at a patch's edge, join it in the next round, until nothing turns or
// kUntangleMaxRounds. A patch holding a vertex marked fixed (a FAP's own
// FDP, which keeps the motion it was measured by) stays as solved: moved
// with the FDP, as one piece or as a harmonic blend, the skin around the
// 10k head's lower lip FDP went 7 mm. A patch holding a vertex marked held
// (the skin the solver holds off an eyeball) moves only where that changes
// none of its vertices by more than kHeldPatchShare of the mesh's mean rest
// edge, else stays as solved: moved without that bound, a patch of Song's
// closing upper lid left a hole in it, and its lids' in-betweens at 1024
// changed 49-53 vertices by up to 3.9 units. Held patches that stayed as
// solved stopped Song's brows lowered (31, 32, 34) at 94-99 % of their
// reference, the search past their range judging a pose by its untangled
// skin; now they reach it. The rest shape is kept; only the motion within
// the patches changes. Where the solve tears a corner apart (Song's
// mouth corner: the lower lip, carried by the jaw, moves 1.6 mm from the
// upper one, which stays, within a millimetre) the change is about half of
// that jump.
//
// Then the slivers still turned, one vertex each: the corner opposite a
// turned triangle's longest rest edge (its apex) takes the motion of its
// foot on that edge, so that it keeps its rest place beside the edge, when
// that changes it by at most kSliverShare of the edge, it is not fixed (a
// held one may move: Song's lids at their corners, 0.09-0.18 units, which
// takes them further off the eyeball), and fewer triangles turn after. What
// still turns stays turned, for the caller to report. The folds
// that the split of shared skin made between a FAP's FDP and another FAP's
// (Song's FAP 57 raises 8.7 3.03 units toward 2.8, which rests 3.35 above
// it and stays) are evened out in the split's weights before
// (fap_partition.h).
//
// A sliver (under kNearTurnArea of the skin's mean triangle) that a target
// turns nearly edge-on (the cosine of its normal with its rest normal below
// kNearTurnCos) is untangled as if turned, though not counted as turned:
// another target added to it turns it. The jaw's opening left slivers at
// Song's left mouth corner 5-13 degrees short of edge-on, and the Xface
// streams that add the jaw's thrust to it turned them (joy.fap's frame 24,
// FAPs 3 at 314 and 14 at 31). A larger triangle that far turned is the
// skin rolling (a lip curled), and stays as solved. (The coarse skin's
// slivers: the lifted skin's count when turned.)
//
// On a simulation mesh (`sim` decimated), what is stored is the lifted
// skin (sim_mesh.h), so its turned triangles count too: each stands for
// the coarse vertices its corners are bound to.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "anatomy/sim_mesh.h"

namespace afmb {

constexpr int kUntangleMaxRounds = 32;  // then it gives up, keeping the best round
constexpr double kSliverShare = 0.25;    // the most a sliver's apex moves, of its longest edge
constexpr double kHeldPatchShare = 0.25; // the most a held patch's vertex moves, of the mean rest edge
constexpr double kNearTurnArea = 0.02;   // a sliver: under this share of the mean triangle's area
constexpr double kNearTurnCos = 0.3;     // nearly edge-on: turned more than 72.5 degrees from its rest facing

// What untangle() may do with a vertex's motion.
enum UntangleHold : char {
  kUntangleFree = 0,   // anything
  kUntangleHeld = 1,   // its patch moves within kHeldPatchShare, else stays as solved; as a sliver's apex it may move
  kUntangleFixed = 2,  // nothing
};

struct Untangled {
  int turned_before = 0;  // turned triangles before (coarse plus lifted; nearly turned slivers not counted)
  int turned_after = 0;   // after: 0 unless it gave up or a held or fixed vertex holds a fold
  int near_before = 0;    // nearly turned slivers before (untangled as if turned)
  int moved = 0;          // vertices whose displacement changed (patches, apices)
  double largest_change = 0;  // the largest change of a vertex's displacement, model units
};

// Untangles D (#V x 3, model units: the displacement of the mesh V0 #V x 3,
// F #F x 3) in place. `hold`: #V UntangleHold values, or empty (all free).
// `sim`: the simulation mesh whose coarse skin V0 is, or null. D is left as it was when nothing
// turns; when not everything untangles, D is the round with the fewest
// turned triangles.
Untangled untangle(const Eigen::MatrixXd &V0, const Eigen::MatrixXi &F, const std::vector<char> &hold,
                   const SimMesh *sim, Eigen::MatrixXd &D);

}  // namespace afmb
