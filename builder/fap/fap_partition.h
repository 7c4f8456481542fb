// FAP targets that move the same skin split it between them, so that a
// stream sending them together moves each FDP once.
//
// Why: the builder makes a FAP's target from its muscle group's pose, and
// the pose moves everything the muscles move. FAPs 4 and 51 (the inner and
// the outer upper lip's midpoint) are both made of the two upper lip
// muscles; FAPs 12 and 59 (the inner and outer corner raised) both of
// zygomaticus major; frontalis inner, major and outer each raise the whole
// brow. Real streams send such FAPs together, the inner and outer lip ones
// with equal values (both of ../shared/data's toolkits do). Summed as they
// were, Song's corner rose twice the prescribed motion and its outer upper
// lip four times (afm-play on Song, 4 + 51 at their references), and
// Xface's fear.fap raised its brows twice as far as it asks.
//
// The rule: two targets are linked when their muscle groups share a muscle
// contracted the same way (a positive-side target of one FAP and a
// negative-side one of another may be linked: both are poses of that
// muscle), or when one's target moves the other's FDP, in any direction, by
// more than kFapOverlap of the other's own target's motion there along its
// FAP's direction (the brows; 41's zygomatici and the lower lip). Any
// direction: a stream sending both moves that FDP by the spill, and a spill
// across the other FAP's direction takes the FDP off its axis as surely as
// one along it overshoots. Counted along the direction only, Song's brow
// squeeze (37, corrugator) was left alone, and it carried the middle brow
// 4.3 inward 1.5 times as far as the inner brow 4.1 it is defined on
// (Candide-3's block: half as far), a horizontal motion that no FAP of 4.3
// has: Xface's hate.fap, which sends 37 with 33, missed its brows' motion by
// 384 % (median; afm-play --fdp-motion), now by 9 %. A linked set (a connected
// component) splits the skin by Shepard's inverse-distance weights on its
// members' FDPs,
//
//     w_k(x) = phi_k(x) / sum_j phi_j(x),   phi_k(x) = 1 / (d(x, p_k)^2 + h^2),
//
// d the length of the shortest path along the mesh's edges (the lips are
// far apart across the mouth even where they touch: on the reference head
// the inner lips' FDPs lie on one point of two vertices), the sum over the
// set's FAPs, each once (both sides of one FAP share an FDP and are never
// active together). That is a partition of unity over the FAPs a stream can
// send together: at equal values the members' targets add up to a blend of
// their poses in which every member's FDP moves by its own target's motion
// there. Alone, a member moves its own region: FAP 4 the inner upper lip's
// middle (the lip grows thinner), as MPEG-4 defines it. h is a millionth of
// the set's span, so w_k(p_k) = 1 to about 1e-12 for distinct FDPs.
//
// Members whose FDPs are one vertex and whose FAPs have one direction (the
// inner and outer lip corners, 2.4 and 8.3, on Song and on the reference
// head) get equal shares there: each moves the corner by half its motion,
// and the two together by all of it. FAPs of one FDP with different
// directions (63 raises the nose tip, 64 bends it) are different motions of
// that point: neither counts in the other's sum, so each keeps the whole of
// it (near it, the two together may weigh more than one: raise and bend),
// and in a third FAP's sum the point counts as its largest direction class
// (once for the nose tip, twice for the corners).
//
// The eyelid FAPs (19-22) are left out: their targets already split
// orbicularis oculi's pose between the two lids (fap_synthesis.cpp). So are
// the cheek puffs (39, 40), air pressure that streams do not send with the
// FAPs around the cheek (FapMapping::own_skin).
//
// Where a share turns the skin over, the set's weights are evened out
// (unfold_shared_weights). Shepard's weights are flat at each FDP and fall
// fastest halfway to the next: between two FDPs a distance L apart, with a
// slope of 2 / L, twice the mean. Where a member's pose carries its FDP most
// of the way to another member's FDP, which its share leaves in place, that
// slope turns the skin between over. Song's FAP 57 raises 8.7 by 3.03 units
// toward 2.8 (FAP 10's), which rests 3.35 above it, and its share turned 3
// triangles halfway between; the untangling could not mend them, since
// their patch grows to the FAP's own FDP, which keeps its motion
// (untangle.h). The 10k head's 10 and 11 lowered and 57 and 58 raised
// turned 1-2 each.
//
// The rule: the facing of a triangle (a, b, c) under a share w P, its normal
// along the rest normal n0 over |n0|^2 (1 at rest, below 0 turned over),
// with p = X + w P, is linear in each corner's weight:
//
//     d facing / d w_a = (P_a x (p_b - p_c)) . n0 / |n0|^2   (and cyclically).
//
// Each triangle that a member's whole pose keeps facing at least
// kUnfoldMargin, and its share does not, is projected onto that bound: a
// Kaczmarz step on the member's FAP's weights at the triangle's corners that
// are no member's FDP (those keep their weights, so every FDP moves as
// before). At each such corner the set's other FAPs take the difference in
// proportion to their weights, so that the weights there add up as before
// (the members at equal values still move every FDP by its own target's
// motion). Sweeps go over the triangles around the corners the last sweep
// changed, up to kUnfoldSweeps. A set none of whose shares turns a
// triangle its pose keeps is left as it is; otherwise the evened weights
// are kept when the shares, as they will be stored, turn fewer triangles
// than before. Song: 57's and 58's 3 each -> 0, the weights changed at 23
// vertices by 0.047 at most; the 10k head's six -> 0. Every frame of
// ../shared/data's thirteen streams turns as many triangles as before
// (afm-play --folds).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace afmb {

// The overlap that links two targets of different muscles (see above).
// Measured with afm-play --fdp-motion on seven of the real streams, summing
// the median distance from the prescription over streams and FDP groups:
// 16 % less than linking by shared muscles alone on Song, 10 % less on the
// 2k head. With the spill counted in any direction, on Song's whole AFM
// and all twelve real streams: 0.1 1679, 0.25 1690, 0.5 1689, 1.0 1711
// (2344 counted along the direction at 0.25).
constexpr double kFapOverlap = 0.25;

struct SharingTarget {
  int fap = 0;      // its FAP: the sides of one FAP count once in a set's sum
  int vertex = -1;  // its FDP's vertex on the mesh the weights are for
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // its FAP's positive direction
  int side = +1;                                        // its target's side of the FAP
  const Eigen::MatrixXd *displacement = nullptr;        // #V x 3, its target (null: no overlap test, no unfolding)
  // The muscles of its group, each with the sign of its contraction (+1, -1).
  std::vector<std::pair<std::string, int>> muscles;
};

struct FapPartition {
  std::vector<int> component;        // per target: its linked set (0, 1, ...)
  std::vector<Eigen::VectorXd> weight;  // per target: #V weights in [0, 1]; empty when alone
};

// X: #V x 3 rest positions (model units); F: #F x 3 triangles over them
// (empty: straight distances). Targets with vertex < 0 or no muscle are
// alone.
FapPartition partition_shared_targets(const Eigen::MatrixXd &X, const Eigen::MatrixXi &F,
                                      const std::vector<SharingTarget> &targets);

// The least facing the evening out asks of a share's triangle where the
// whole pose keeps it (see above; 1 at rest). Song, in 50 sweeps: at 0.02
// every bound met (in 36), at 0.05 all but one, at 0.1 all but 12, the
// weights changed by up to 0.038, 0.047 and 0.072, and no share turned a
// triangle; 0.05 leaves the slivers less thin than 0.02.
constexpr double kUnfoldMargin = 0.05;
constexpr int kUnfoldSweeps = 50;

struct UnfoldedShares {
  std::vector<int> turned_before;  // per target: triangles its share turned (0: not evened out or none)
  std::vector<int> turned_after;   // per target: after (the same as before where the weights were kept)
  int vertices = 0;                // vertices whose weights changed
  double largest_change = 0;       // the largest change of a weight (0..1)
};

// Evens out `partition`'s weights where the shares turn skin over (see
// above). X, F, targets: as given to partition_shared_targets; `turned(k,
// w)`: how many triangles target k's share (its displacement times w, #V
// weights) turns over as it will be stored, called from `threads` workers
// (0: one per core; parallel.h) at once. Targets without a displacement or a
// weight are left alone. The same result for any number of workers.
UnfoldedShares unfold_shared_weights(const Eigen::MatrixXd &X, const Eigen::MatrixXi &F,
                                     const std::vector<SharingTarget> &targets, FapPartition &partition,
                                     const std::function<int(size_t, const Eigen::VectorXd &)> &turned,
                                     int threads);

}  // namespace afmb
