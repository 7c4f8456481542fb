// The 25 muscles of the method paper (Tables 1 and 2), as data, and the
// drivers this project adds: four for the lids (the palpebral part of
// orbicularis oculi, one per lid: docs/anatomy.md "The lids"), two that
// push the lips out (docs/anatomy.md "Lip protrusion"), two that flare
// the nose's wings (docs/anatomy.md "Nostril dilators"), two that puff
// the cheeks out (air pressure in the mouth: docs/anatomy.md "Cheek
// puff"), one that raises the chin (docs/anatomy.md "Chin raiser"), two
// that lower the inner brows (docs/anatomy.md "Depressor supercilii"), two
// that lower the lower lip (docs/anatomy.md "Depressor labii inferioris")
// and four that move the nose's tip up, down and sideways (docs/anatomy.md
// "Nose tip drivers").
//
// Key points are written as in the paper, affine combinations of FDP
// positions: "11.1 + 1/6 (11.3 - 11.1)". parse_keypoint() turns one into
// (FDP, coefficient) pairs and eval_keypoint() evaluates it on a bound FDP
// set. docs/anatomy.md lists the table with the decisions taken where the
// paper's Table 1 and 2 slip.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/fdp.h"
#include "core/status.h"

namespace afmb {

// Lid: the palpebral part of orbicularis oculi in one lid, which turns the
// lid about its eyeball's horizontal axis (muscles.h). Not in the paper.
enum class MuscleKind { Linear, Sphincter, Lid };

// The line a linear muscle pulls (or pushes) each node of its area along
// (muscles.h, linear_pull; docs/anatomy.md, "Muscles", says why each muscle
// has its own):
//   Skull    straight toward the attachment's skull node, through the
//            tissue: Waters' vector muscle, as the paper maps it;
//   Surface  that line's part in the skin's tangent plane at the node's
//            vertex: a muscle lying along the bone under the skin, whose
//            fibre wraps over the skull;
//   Key      straight toward the attachment's key point itself, on the
//            skin's surface where the FDPs are: a push from below the skin,
//            or a pull toward a point on the skin that stands forward of
//            the insertion (the lower lip turned out as it comes down),
//            or toward a point off it (the nose's tip drawn sideways).
enum class PullLine { Skull, Surface, Key };

// One row of Table 1 or 2 plus the constants the paper leaves to the
// implementer. Sides are the face's own (MPEG-4: left is +x).
struct MuscleDef {
  const char *name;  // "zygomaticus_major_left": lower case, '_' separated, unique
  MuscleKind kind;
  // Linear: attachment (skull) and insertion (dermis) key points.
  // Sphincter: a = end of the semi-major axis, b = end of the semi-minor
  // axis (both on the hypodermis) and the epicentre (a free point).
  // Lid: a = the lid's margin (3.1 for the upper left lid), b = the other
  // lid's margin; the eyeball under a gives the centre.
  const char *attachment_or_major;
  const char *insertion_or_minor;
  const char *epicentre;  // sphincters only, else nullptr
  // Linear: the muscular width coefficient omega (section 3.2.1): a node is
  // in the influence area when its distance to the central fibre is below
  // omega x fibre length. Sphincter: the influence ellipse is the key-point
  // ellipse scaled by this factor (the paper's equation 1 with the axes
  // multiplied by it; 1 would cover the lid margins and lips only).
  double width;
  // +1: contracting pulls the insertion toward the attachment (every real
  // linear muscle). -1: the paper drives this muscle the other way (Table 3
  // raises the lower lip with "mentalis 150" and lowers the upper lip with
  // "upper lip 150" although both attachments lie on the far side), so its
  // anatomical action, a positive contraction here, pushes.
  int sense;
  // The displacement at +100 % and at -100 % contraction (section 3.3),
  // as fractions of the fibre length (linear: the insertion moves along its
  // pull, muscles.h) or of the semi-axis (sphincter: the semi-axis key node moves
  // toward the epicentre; which axis is `calibrate_minor`; lid: the margin
  // moves along the eyeball toward the other lid, a fraction of the opening).
  double max_fraction, min_fraction;
  bool calibrate_minor;  // sphincters: calibrate on the minor axis node
  // Lips and cheeks (section 3.2.4), and the lids: the nodes of the
  // influence area are not tied to the skull (hypodermis-to-skull springs of
  // zero stiffness, no skull rejection).
  bool skull_free;
  // Without it the face cannot make its basic FAPs: a build without its FDPs
  // fails instead of skipping the muscle.
  bool essential;
  // Linear: its line of action (PullLine): Surface for the muscles along the
  // bone (frontalis, corrugator, zygomaticus major, risorius, depressor
  // anguli, the chin raiser, depressor supercilii), Key for the pushes
  // (mentalis, the lip protrusion drivers, the nostril dilators, the cheek
  // puffs) and the pulls toward a point on or off the skin (depressor labii,
  // the nose's tip drivers), Skull for the others (nasalis, upper lip,
  // zygomaticus minor). Others: Skull (unused).
  PullLine line;
  // Lid: the eye's corners (outer, inner), where the margin is held: the
  // load fades to nothing there. Others: nullptr.
  const char *corner_outer = nullptr, *corner_inner = nullptr;
  // Linear: the load acts on each influence vertex's epidermal, dermal and
  // hypodermal nodes, a third each, instead of the dermal node alone: a
  // muscle inside the tissue it moves (the lip protrusion drivers: the lip's
  // own orbicularis; the nostril dilators: the wing's; the cheek puffs:
  // the air's pressure on the cheek from inside; the nose's tip drivers: the
  // cartilage, moved as one), not under it.
  // Pushed by its dermis alone, the upper lip's dermis passed through its
  // epidermis (docs/anatomy.md).
  bool whole_thickness = false;
};

// The 25 muscles, in the paper's order (Table 1 top to bottom, left before
// right, then Table 2), then the four lid drivers (upper left, upper right,
// lower left, lower right), then the two lip protrusion drivers (upper,
// lower), the two nostril dilators (left, right) and the two cheek puffs
// (left, right): linear muscles that push; last the chin raiser, the two
// depressores supercilii, the two depressores labii (left, right) and the
// nose's tip drivers (bend left, bend right, raise, lower), linear muscles
// that pull.
const std::vector<MuscleDef> &muscle_table();
// "linear", "sphincter", "lid".
const char *muscle_kind_name(MuscleKind kind);
constexpr int kPaperMuscles = 25;
// Index in muscle_table() of a muscle name, or -1.
int find_muscle(const std::string &name);

// A key point: sum of coefficient x FDP position, coefficients summing to 1.
struct Keypoint {
  std::vector<std::pair<FdpId, double>> terms;
  std::string text;  // as written in the table
};

// Grammar: expr := term { ('+' | '-') term }; term := [a/b] ( FDP | '(' expr ')' ).
// Errors quote the text and the offending position.
Expected<Keypoint> parse_keypoint(const std::string &text);

// The FDPs a key point needs that `fdps` lacks (empty: it can be evaluated).
std::vector<FdpId> missing_fdps(const Keypoint &k, const FdpSet &fdps);
// Evaluates on the first point of each FDP. Precondition: nothing missing.
Eigen::Vector3d eval_keypoint(const Keypoint &k, const FdpSet &fdps);

}  // namespace afmb
