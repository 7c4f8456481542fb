// Waters muscles placed on the skin model (method paper sections 3.1, 3.2.1,
// 3.2.2): key points from the FDPs, mapped to nodes; influence areas; the
// force fields.
//
// Linear muscle (attachment A on the skull, insertion I on the dermis, fibre
// length L = |I - A| at rest). A dermis node p is in the influence area when
// its distance to the segment AI is below omega L (the width coefficient).
// It is pulled toward A (along the rest direction; MuscleDef::line: for a
// muscle that lies along the bone, that direction's part in the skin's
// tangent plane at p's vertex, scaled back to unit length; for mentalis'
// push, the direction from the attachment's key point instead of its node)
// with the weight
//   w = area(p) cos(alpha) R(D),   alpha = angle(I - A, p - A) (0 beyond 90 deg),
//   D = |p - A|,  R = sin(pi/2 D / L)                       for D <= L,
//                 R = cos(pi/2 (D - L) / (omega L))          for L < D <= (1 + omega) L,
// Waters' angular and radial fall-offs with the fall-off starting at the
// insertion (Rs = L) and ending omega L beyond it (Rf).
//
// Sphincter (epicentre e, semi-axes a along x and b along y, from the key
// points' distances to e along those axes, as in the paper's equation 1).
// A hypodermis node p is in the influence area when
//   ((p.x - e.x) / (k a))^2 + ((p.y - e.y) / (k b))^2 <= 1   (k: the width)
//   and n(p) . n(e) >= 0                                       (equation 2),
// n(e) being the normal of the epidermal vertex nearest e. With
// rho = sqrt(((p.x - e.x) / a)^2 + ((p.y - e.y) / b)^2) the weight is
//   w = area(p) g(rho),  g = 1 for rho <= 1, cos(pi/2 (rho - 1) / (k - 1)) beyond,
// and the pull points at e in the x-y plane: -(d.x, d.y, 0) / max(|d.xy|, b / 3).
//
// Lid (the palpebral part of orbicularis oculi, not in the paper): turns the
// lid about the horizontal axis through its eyeball's centre c (the sphere
// SkinModel::eyes whose surface the margin key point a lies within half a
// radius of), the axis along +-x so that a turns toward the other lid's
// margin b. Its area is the skin reached from a's vertex on a's side of the
// height halfway between the margins, within the eyeball's width and 1.5
// radii of c. A vertex p at a turn alpha beyond a's (about the axis, growing
// away from the opening; alpha_max the area's largest) weighs
//   w = area(p) g(alpha) h(q),  g = 1 for alpha <= 0, (1 - alpha / alpha_max)^4 beyond,
//                               h = cos(pi/2 q^2) on an upper lid, cos(pi/2 q) on a lower one,
// q = 0 over a and 1 at the eye's corner on p's side (and beyond): most at
// the margin, nothing at the orbital rim and the corners; a lower lid's
// load gathers more in its middle (muscles.cpp says why). The load acts on
// the vertex's epidermal, dermal and hypodermal nodes, a third each, except
// nodes within half the eyeball's radius r of the axis. Its potential on a
// node at rest distance rho0 from the axis is -t sense (w/3) (rho0^2 / r)
// theta, theta the node's turn about the axis: a pull of t (w/3) rho0 / r
// along the circle about the axis, so the nodes of the thin lid turn alike.
// The action is the margin node's arc rho0 theta (its epidermal node);
// +-100 % move it a fraction of the opening |a - b|.
//
// A linear muscle with MuscleDef::whole_thickness (the lip protrusion
// drivers, the nostril dilators, the cheek puffs) loads the vertex's
// epidermal, dermal and hypodermal nodes with a third of w each instead of
// its dermal node.
//
// Force on a node: sense x t x w x direction, where t is the signed tension
// (model force per unit area; positive: the muscle's action, negative: the
// other way) and sense is the table's +1 / -1.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "anatomy/muscle_table.h"
#include "anatomy/skin_model.h"
#include "anatomy/solver.h"
#include "core/fdp.h"
#include "core/fapu.h"

namespace afmb {

struct Muscle {
  int def = -1;            // index into muscle_table()
  std::string name;
  MuscleKind kind = MuscleKind::Linear;
  int sense = 1;
  // Key points as computed from the FDPs (model units), before mapping.
  Eigen::Vector3d key_a = Eigen::Vector3d::Zero();  // attachment, or semi-major end
  Eigen::Vector3d key_b = Eigen::Vector3d::Zero();  // insertion, or semi-minor end
  // Mapped nodes (global node indices into SkinModel::X0).
  int node_a = -1;         // linear: skull node; sphincter: hypodermis node; lid: epidermal margin
  int node_b = -1;         // linear: dermis node; sphincter: hypodermis node; lid: the other margin
  double length = 0;       // linear: rest fibre length |node_b - node_a|; lid: the opening
  // Sphincter.
  Eigen::Vector3d epicentre = Eigen::Vector3d::Zero();
  double semi_a = 0, semi_b = 0;  // model units, along x and y, at the hypodermis key nodes
                                  // (the calibration's scale and the pull's core)
  double area_a = 0, area_b = 0;  // the ellipse through the key points on the skin's
                                  // surface: equation 1's axes, and what pictures draw
  double width = 0;        // omega, or the sphincter's ellipse scale k
  int force_layer = kDermis;  // kDermis (linear; TissueParams::skin_load_share of its load
                              // goes on the epidermis), kHypodermis (sphincter); lid: 0..2
  // Lid: the eyeball (index into SkinModel::eyes; its centre is `epicentre`)
  // and the axis (+x or -x) the lid turns about as it closes.
  int eye = -1;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  std::vector<int> influence;   // skin vertices, sorted
  std::vector<double> weight;   // per influence vertex
  // Lid, per influence vertex: the share of the lid's turn it takes when the
  // lid is turned as a whole (Activation::lids, face_model.h), 0..1, and
  // whether it is on the tarsus: the stiff band along the margin (and the
  // margin's underside), which turns rigidly with it and is held there;
  // the rest of the lid follows through the tissue (its share is the first
  // guess only).
  std::vector<double> turn_share;
  std::vector<char> tarsus;
  // Lid: the turn (radians) that takes its margin at the key point to the
  // other lid's margin at rest: the lids meet.
  double closing_turn = 0;
  // Calibration (section 3.3): tension at +100 % and at -100 % contraction.
  double tension_max = 0, tension_min = 0;
  // The part of the table's range (max_fraction, min_fraction) that +-100 %
  // stands for: 1, or 1/2, 1/4 or 1/8 when the tissue locked before the key node
  // got there (a non-essential muscle; the model's warnings say so).
  double range_max = 1, range_min = 1;
  std::vector<int> dynamic;     // V_d: vertices the elastic wave moves, sorted
  // The calibrated poses at +100 % and -100 %, from rest. First guesses for
  // poses that combine muscles (face_model.h, superposed_pose).
  NodeDisplacement response_max, response_min;
};

// Places one muscle of the table: evaluates its key points, maps them to the
// nearest node of the proper layer (a key point that is one FDP to the FDP's
// own vertex where several lie at that place, as on a closed mouth's lip
// line) and computes its influence area. Fails
// naming the FDPs when some are missing from `fdps`.
Expected<Muscle> place_muscle(const SkinModel &skin, const FdpSet &fdps, int def);

// The mouth window of section 3.2.1, in model units along x and y.
struct MouthWindow {
  double top = 0, bottom = 0, left = 0, right = 0;  // left < right (x), bottom < top (y)
};
// top = 9.15.y (else the FAPU's nose-base height), bottom = 2.11.y -
// |2.11.y - 2.2.y| / 2 (else 2.1.y), and the sides at the inner lip corners
// 2.4 and 2.5: the paper's margin of MW0/20 beyond them lets the search
// round the corners into the other lip on meshes whose lips meet there.
Expected<MouthWindow> mouth_window(const FdpSet &fdps);

// Breadth-first search over the skin mesh from vertex `start`, through
// vertices strictly inside the window. Returns the vertices reached, sorted.
std::vector<int> mouth_window_search(const SkinModel &skin, const MouthWindow &w, int start);

// The two searches of section 3.2.1 (and 3.2.3): from the skin vertex of FDP
// 2.2 (else the one nearest it) the upper lip, from 2.3's the lower lip and
// chin. Both sorted. Fails as mouth_window() does.
struct MouthLips {
  std::vector<int> upper, lower;
};
Expected<MouthLips> mouth_lips(const SkinModel &skin, const FdpSet &fdps);

// Removes `vertices` (sorted) from a muscle's influence area.
void remove_from_influence(Muscle &m, const std::vector<int> &vertices);

// The muscle's load at signed tension t and positions X: returns its
// potential energy; when F is given, adds its forces (4n x 3); when K is
// given, appends its Hessian (a ForceField's, solver.h: the contracting
// sphincter's and the positive part of a lid's, the others are dead loads). The field
// is conservative: a linear muscle's pull is a dead load along the rest
// direction u0 from the node to A (tangent to the skin for a muscle along
// the bone, from the key point for mentalis), potential -t sense w (p - p0) . u0 (a
// push away from a moving point would be unstable across the fibre); a
// sphincter's, contracting (t sense > 0), t sense w h(|d.xy|) with d the
// node's offset from the epicentre, h(r) = r beyond the floor b / 3 and
// r^2 / (2 floor) + floor / 2 within it; widening, a dead load outward
// along the rest offset, for the same reason as the linear push.
double muscle_load(const SkinModel &skin, const Muscle &m, double tension, const Eigen::MatrixXd &X,
                   Eigen::MatrixXd *F, NodeBlocks *K = nullptr);

// How far the muscle has acted at positions X (model units, positive in the
// direction of its action): linear, the insertion's motion along its pull
// direction u0 (toward the attachment's node or key point, or the tangent
// part of the former: MuscleDef::line) times sense; sphincter, the calibrated semi-axis
// node's motion toward the epicentre in the x-y plane; lid, the margin
// node's arc about the axis toward the other lid. When `gradient` is
// given, adds the action's gradient with respect to X (4n x 3) to it.
double muscle_action(const SkinModel &skin, const Muscle &m, const Eigen::MatrixXd &X,
                     Eigen::MatrixXd *gradient = nullptr);
// The action at +100 % (positive) and at -100 % (negative) contraction: the
// table's fraction of the fibre (semi-axis, lid opening) times range_max /
// range_min.
double muscle_action_target(const Muscle &m, bool maximum);

}  // namespace afmb
