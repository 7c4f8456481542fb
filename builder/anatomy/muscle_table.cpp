#include "anatomy/muscle_table.h"

#include <cctype>
#include <cmath>
#include <map>

namespace afmb {

namespace {

using K = MuscleKind;
using L = PullLine;

// name, kind, attachment | semi-major end, insertion | semi-minor end, epicentre,
// width, sense, max, min, calibrate_minor, skull_free, essential, line[, the
// lid's corners[, whole_thickness]].
// Decisions where the paper's tables slip (docs/anatomy.md):
//  - frontalis_inner_right: the paper writes 11.3 (the left hairline) in its
//    attachment; every other right frontalis uses 11.2, so 11.2 here.
//  - risorius: the paper starts the left one at 5.1 (the cheek's centre,
//    up from the corner: 36 degrees on Song, 5.3 units away) and the right
//    one at 5.4, which makes it the same fibre as zygomaticus_major_right
//    (5.4 -> 8.4). The muscle runs level from the corner to the fascia over
//    the masseter and stretches the lips sideways (FACS AU 20, MPEG-4's
//    stretch_cornerlip), so here it starts level with its corner, half the
//    mouth's width beyond it: 8.3 + 1/2 (8.3 - 8.4) (the right one
//    mirrored), with 15 % of that fibre as its range (20 % folded the skin
//    beside Song's corners in viseme I).
//  - orbicularis_oris: the paper's epicentre (n + m) / 2 with n = 8.2,
//    m = 8.3 lies between the lower lip and the left corner; the mouth's
//    centre, halfway between 8.1 and 8.2, here.
//  - corrugator: the paper's fibre 4.3 -> 4.3 + (4.3 - 4.1) lies a brow
//    segment lateral of the anatomical one, and the inner brow 4.1, which
//    FAPs 37/38 move, lies behind its attachment, outside its influence
//    area. Anatomically it rises from the bone at the brows' inner ends and
//    inserts in the mid-brow skin: attachment a third of the way from 4.1
//    to 4.2, insertion 4.3. Its push (-100 %) goes as far as its pull: with
//    a third of it, FAPs 37/38's negative sides stopped at half their
//    reference, at four times that range.
//  - mentalis: the paper's attachment 2.1 + (2.1 - m) mirrors a point through
//    the chin in depth too, in front of the face on Song, whose two short
//    fibres then missed the lower lip's middle. From the chin straight below
//    its insertion here, pushing the lip up, wider and with a larger range.
const std::vector<MuscleDef> kTable = {
    {"frontalis_inner_left", K::Linear, "11.1 + 1/6 (11.3 - 11.1)", "4.1", nullptr, 0.30, +1, 0.18, 0.06, false, false, false, L::Surface},
    {"frontalis_inner_right", K::Linear, "11.1 + 1/6 (11.2 - 11.1)", "4.2", nullptr, 0.30, +1, 0.18, 0.06, false, false, false, L::Surface},
    {"frontalis_major_left", K::Linear, "11.1 + 1/3 (11.3 - 11.1)", "4.3", nullptr, 0.30, +1, 0.18, 0.06, false, false, false, L::Surface},
    {"frontalis_major_right", K::Linear, "11.1 + 1/3 (11.2 - 11.1)", "4.4", nullptr, 0.30, +1, 0.18, 0.06, false, false, false, L::Surface},
    {"frontalis_outer_left", K::Linear, "11.1 + 2/3 (11.3 - 11.1)", "4.5", nullptr, 0.30, +1, 0.18, 0.06, false, false, false, L::Surface},
    {"frontalis_outer_right", K::Linear, "11.1 + 2/3 (11.2 - 11.1)", "4.6", nullptr, 0.30, +1, 0.18, 0.06, false, false, false, L::Surface},
    {"corrugator_left", K::Linear, "4.1 + 1/3 (4.2 - 4.1)", "4.3", nullptr, 0.40, +1, 0.25, 0.25, false, false, false, L::Surface},
    {"corrugator_right", K::Linear, "4.2 + 1/3 (4.1 - 4.2)", "4.4", nullptr, 0.40, +1, 0.25, 0.25, false, false, false, L::Surface},
    {"nasalis_left", K::Linear, "9.7", "9.1", nullptr, 0.30, +1, 0.15, 0.05, false, false, false, L::Skull},
    {"nasalis_right", K::Linear, "9.6", "9.2", nullptr, 0.30, +1, 0.15, 0.05, false, false, false, L::Skull},
    {"upper_lip_left", K::Linear, "9.5 + 1/2 (9.15 - 9.5)", "8.10", nullptr, 0.40, -1, 0.40, 0.15, false, true, false, L::Skull},
    {"upper_lip_right", K::Linear, "9.4 + 1/2 (9.15 - 9.4)", "8.9", nullptr, 0.40, -1, 0.40, 0.15, false, true, false, L::Skull},
    {"zygomaticus_minor_left", K::Linear, "3.9", "8.5 + 1/2 (2.6 - 8.5)", nullptr, 0.20, +1, 0.20, 0.06, false, true, false, L::Skull},
    {"zygomaticus_minor_right", K::Linear, "3.10", "8.6 + 1/2 (2.7 - 8.6)", nullptr, 0.20, +1, 0.20, 0.06, false, true, false, L::Skull},
    {"zygomaticus_major_left", K::Linear, "5.3", "8.3", nullptr, 0.25, +1, 0.25, 0.08, false, true, true, L::Surface},
    {"zygomaticus_major_right", K::Linear, "5.4", "8.4", nullptr, 0.25, +1, 0.25, 0.08, false, true, true, L::Surface},
    {"risorius_left", K::Linear, "8.3 + 1/2 (8.3 - 8.4)", "8.3", nullptr, 0.25, +1, 0.15, 0.06, false, true, true, L::Surface},
    {"risorius_right", K::Linear, "8.4 + 1/2 (8.4 - 8.3)", "8.4", nullptr, 0.25, +1, 0.15, 0.06, false, true, true, L::Surface},
    {"depressor_anguli_left", K::Linear, "8.3 + (8.3 - 9.1)", "8.3", nullptr, 0.35, +1, 0.30, 0.10, false, false, true, L::Surface},
    {"depressor_anguli_right", K::Linear, "8.4 + (8.4 - 9.2)", "8.4", nullptr, 0.35, +1, 0.30, 0.10, false, false, true, L::Surface},
    {"mentalis_left", K::Linear, "2.10 + (2.8 - 2.3)", "2.8", nullptr, 0.45, -1, 0.12, 0.08, false, false, true, L::Key},
    {"mentalis_right", K::Linear, "2.10 + (2.9 - 2.3)", "2.9", nullptr, 0.45, -1, 0.12, 0.08, false, false, true, L::Key},
    {"orbicularis_oculi_left", K::Sphincter, "3.7", "3.9", "3.5", 1.8, +1, 0.50, 0.20, true, false, false, L::Skull},
    {"orbicularis_oculi_right", K::Sphincter, "3.12", "3.10", "3.6", 1.8, +1, 0.50, 0.20, true, false, false, L::Skull},
    {"orbicularis_oris", K::Sphincter, "8.3", "8.2", "1/2 (8.1 + 8.2)", 1.6, +1, 0.25, 0.10, false, true, true, L::Skull},
    // The lids (not in the paper; docs/anatomy.md "The lids"). +100 % takes
    // the upper margin nine tenths of the opening down the eyeball, -100 %
    // (levator palpebrae) a quarter up; the lower lid half and a sixth.
    {"palpebral_upper_left", K::Lid, "3.1", "3.3", nullptr, 0, +1, 0.90, 0.25, false, true, false, L::Skull, "3.7", "3.11"},
    {"palpebral_upper_right", K::Lid, "3.2", "3.4", nullptr, 0, +1, 0.90, 0.25, false, true, false, L::Skull, "3.8", "3.12"},
    {"palpebral_lower_left", K::Lid, "3.3", "3.1", nullptr, 0, +1, 0.50, 0.15, false, true, false, L::Skull, "3.7", "3.11"},
    {"palpebral_lower_right", K::Lid, "3.4", "3.2", nullptr, 0, +1, 0.50, 0.15, false, true, false, L::Skull, "3.8", "3.12"},
    // The lips pushed out (not in the paper; docs/anatomy.md "Lip
    // protrusion"): each lip's middle pushed from a point behind it, offset
    // from the lip by half the way from the lower lip's middle (2.3) to the
    // midpoint of the jaw's corners (2.13, 2.14): about MW0 back and a little
    // down (on a closed mouth, where 2.2 and 2.3 meet, the two fibres are
    // parallel). A push, like mentalis' (sense -1, PullLine Key); +100 %
    // moves the lip 15 % of the fibre out (about MW0 / 7).
    {"lip_protrusion_upper", K::Linear, "2.2 + 1/4 (2.13 - 2.3) + 1/4 (2.14 - 2.3)", "1/2 (2.2 + 8.1)", nullptr, 0.20, -1, 0.15, 0.05, false, true, false, L::Key, nullptr, nullptr, true},
    {"lip_protrusion_lower", K::Linear, "2.3 + 1/4 (2.13 - 2.3) + 1/4 (2.14 - 2.3)", "1/2 (2.3 + 8.2)", nullptr, 0.20, -1, 0.15, 0.05, false, true, false, L::Key, nullptr, nullptr, true},
    // The nose's wings flared (not in the paper; docs/anatomy.md "Nostril
    // dilators"): the alar part of nasalis, each wing (9.1, 9.2) pushed
    // out from the point between them, its -100 % drawing it in. The
    // paper's nasalis (9.7 -> 9.1) moves the wing back and up.
    {"dilator_naris_left", K::Linear, "1/2 (9.1 + 9.2)", "9.1", nullptr, 0.30, -1, 0.20, 0.10, false, false, false, L::Key, nullptr, nullptr, true},
    {"dilator_naris_right", K::Linear, "1/2 (9.1 + 9.2)", "9.2", nullptr, 0.30, -1, 0.20, 0.10, false, false, false, L::Key, nullptr, nullptr, true},
    // The cheek puffed out (not in the paper; docs/anatomy.md "Cheek puff"):
    // air pressure in the mouth, no muscle, which MPEG-4's puff_l_cheek and
    // puff_r_cheek (FAPs 39, 40) ask for. A push through the cheek's FDP
    // (5.1, 5.2) from half the mouth's width inside it, along the corners'
    // offset (x on a level mouth), and through the cheek's whole thickness:
    // nearly along the skin's normal, as a pressure pushes. +100 % takes the
    // cheek 20 % of the fibre out, -100 % (sucked in) 16 % in: the skull
    // stands behind the cheek, and a quarter of the cheeks' half-distance
    // in crushed the tissue on it (3 slabs turned on the 1k head, even with
    // the collapse floor).
    {"cheek_puff_left", K::Linear, "5.1 + 1/2 (8.4 - 8.3)", "5.1", nullptr, 0.60, -1, 0.20, 0.16, false, false, false, L::Key, nullptr, nullptr, true},
    {"cheek_puff_right", K::Linear, "5.2 + 1/2 (8.3 - 8.4)", "5.2", nullptr, 0.60, -1, 0.20, 0.16, false, false, false, L::Key, nullptr, nullptr, true},
    // The chin raised (not in the paper; docs/anatomy.md "Chin raiser"):
    // mentalis' own pull on the chin's skin (FACS AU 17), which the table's
    // mentalis, driven as a push on the lower lip, leaves out. A fibre along
    // the bone from the chin boss (2.10) up toward the lower lip's middle
    // (8.2), on the skull under it; +100 % takes the boss a fifth of the way
    // up, -100 % (a push) as far down: at a twentieth, four times the range
    // took Song's boss 44 % of FAP 18's way down. Both ends are FDPs, which a
    // simulation mesh keeps anyway: a key point of its own, halfway, changed
    // the 10k head's mesh and with it its lower lip's targets.
    {"chin_raiser", K::Linear, "8.2", "2.10", nullptr, 0.225, +1, 0.20, 0.20, false, false, false, L::Surface},
    // The inner brow lowered (not in the paper; docs/anatomy.md "Depressor
    // supercilii"): the small muscle from the orbit's inner rim up into the
    // inner brow's skin (with corrugator and procerus, FACS AU 4). The
    // paper's only way down is frontalis driven backwards, a push from the
    // hairline. Its attachment lies below the inner brow by the middle
    // brow's height over the upper lid (4.3 over 3.1): beside the nose's
    // root, level with the eye. Pulling along the bone, +100 % moves the
    // brow 35 % of the fibre along its pull; 45 % turned a triangle at
    // Song's inner eye corner.
    {"depressor_supercilii_left", K::Linear, "4.1 + (3.1 - 4.3)", "4.1", nullptr, 0.60, +1, 0.35, 0.08, false, false, false, L::Surface},
    {"depressor_supercilii_right", K::Linear, "4.2 + (3.2 - 4.4)", "4.2", nullptr, 0.60, +1, 0.35, 0.08, false, false, false, L::Surface},
    // The lower lip lowered (not in the paper; docs/anatomy.md "Depressor
    // labii inferioris"): the muscle from the mandible below the lip up
    // into the lower lip's skin (FACS AU 16), which the paper leaves to
    // mentalis driven backwards, a push. Attached below the outer lower
    // lip's middle (8.7) by the lip's height over the chin boss (8.2 over
    // 2.10), it pulls toward that point on the chin's skin: along the bone
    // the lip's edge went back into the mouth. Used by the outer lower lip's
    // FAPs only (fap_mapping.cpp).
    {"depressor_labii_left", K::Linear, "8.7 + (2.10 - 8.2)", "8.7", nullptr, 0.40, +1, 0.35, 0.08, false, false, false, L::Key},
    {"depressor_labii_right", K::Linear, "8.8 + (2.10 - 8.2)", "8.8", nullptr, 0.40, +1, 0.35, 0.08, false, false, false, L::Key},
    // The nose's tip moved (not in the paper; docs/anatomy.md "Nose tip
    // drivers"): MPEG-4's bend_nose and raise_nose (FAPs 64, 63) move the
    // tip (9.3) sideways, up and down, which the paper's nasalis, pulling
    // each wing back and up, barely does (Song's tip moved less than a FAP
    // unit sideways). Each a pull on the tip toward a point level with it:
    // beside it by the wings' distance (x on a level nose; at half that
    // distance the tip came forward too), or above or below it by a
    // quarter of the way from the pupils to the chin (the face's vertical).
    // The load on the tissue's whole thickness, as the cartilage moves as
    // one. +100 % takes the tip a tenth of the fibre sideways, 15 % up or
    // down.
    {"nose_bend_left", K::Linear, "9.3 + (9.1 - 9.2)", "9.3", nullptr, 0.25, +1, 0.10, 0.05, false, false, false, L::Key, nullptr, nullptr, true},
    {"nose_bend_right", K::Linear, "9.3 + (9.2 - 9.1)", "9.3", nullptr, 0.25, +1, 0.10, 0.05, false, false, false, L::Key, nullptr, nullptr, true},
    {"nose_raise", K::Linear, "9.3 + 1/8 (3.5 - 2.1) + 1/8 (3.6 - 2.1)", "9.3", nullptr, 0.30, +1, 0.15, 0.05, false, false, false, L::Key, nullptr, nullptr, true},
    {"nose_lower", K::Linear, "9.3 + 1/8 (2.1 - 3.5) + 1/8 (2.1 - 3.6)", "9.3", nullptr, 0.30, +1, 0.15, 0.05, false, false, false, L::Key, nullptr, nullptr, true},
};

struct Parser {
  const std::string &s;
  size_t at = 0;
  std::string error;

  void skip() {
    while (at < s.size() && std::isspace(static_cast<unsigned char>(s[at]))) ++at;
  }
  bool fail(const std::string &what) {
    if (error.empty())
      error = "key point '" + s + "': " + what + " at column " + std::to_string(at + 1);
    return false;
  }
  // Digits and dots: "11.3", "1", "6".
  std::string number() {
    size_t start = at;
    while (at < s.size() && (std::isdigit(static_cast<unsigned char>(s[at])) || s[at] == '.')) ++at;
    return s.substr(start, at - start);
  }
  bool term(double scale, std::map<FdpId, double> &out) {
    skip();
    if (at < s.size() && std::isdigit(static_cast<unsigned char>(s[at]))) {
      const size_t start = at;
      std::string a = number();
      skip();
      if (at < s.size() && s[at] == '/') {  // a fraction, then a term
        ++at;
        skip();
        std::string b = number();
        if (a.find('.') != std::string::npos || b.empty() || b.find('.') != std::string::npos ||
            std::stoi(b) == 0)
          return fail("bad fraction");
        return term(scale * std::stoi(a) / std::stoi(b), out);
      }
      std::optional<FdpId> id = FdpId::parse(a);
      if (!id) {
        at = start;
        return fail("'" + a + "' is not an FDP");
      }
      out[*id] += scale;
      return true;
    }
    if (at < s.size() && s[at] == '(') {
      ++at;
      if (!expr(scale, out)) return false;
      skip();
      if (at >= s.size() || s[at] != ')') return fail("expected ')'");
      ++at;
      return true;
    }
    return fail("expected an FDP, a fraction or '('");
  }
  bool expr(double scale, std::map<FdpId, double> &out) {
    if (!term(scale, out)) return false;
    for (;;) {
      skip();
      if (at >= s.size() || (s[at] != '+' && s[at] != '-')) return true;
      const double sign = s[at] == '+' ? 1.0 : -1.0;
      ++at;
      if (!term(scale * sign, out)) return false;
    }
  }
};

}  // namespace

const std::vector<MuscleDef> &muscle_table() { return kTable; }

const char *muscle_kind_name(MuscleKind kind) {
  switch (kind) {
    case MuscleKind::Linear: return "linear";
    case MuscleKind::Sphincter: return "sphincter";
    case MuscleKind::Lid: return "lid";
  }
  return "?";
}

int find_muscle(const std::string &name) {
  for (size_t i = 0; i < kTable.size(); ++i)
    if (name == kTable[i].name) return static_cast<int>(i);
  return -1;
}

Expected<Keypoint> parse_keypoint(const std::string &text) {
  Parser p{text, 0, {}};
  std::map<FdpId, double> terms;
  if (!p.expr(1.0, terms)) return Status::error(p.error);
  p.skip();
  if (p.at != text.size()) {
    p.fail("unexpected text");
    return Status::error(p.error);
  }
  Keypoint k;
  k.text = text;
  double sum = 0;
  for (const auto &[id, c] : terms) {
    if (std::abs(c) < 1e-12) continue;  // 11.1 - 11.1 and the like
    k.terms.emplace_back(id, c);
    sum += c;
  }
  if (std::abs(sum - 1.0) > 1e-9)
    return Status::error("key point '" + text + "': coefficients sum to " + std::to_string(sum) +
                         ", not 1: not a point");
  return k;
}

std::vector<FdpId> missing_fdps(const Keypoint &k, const FdpSet &fdps) {
  std::vector<FdpId> out;
  for (const auto &[id, c] : k.terms)
    if (!fdps.find(id)) out.push_back(id);
  return out;
}

Eigen::Vector3d eval_keypoint(const Keypoint &k, const FdpSet &fdps) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (const auto &[id, c] : k.terms) p += c * fdps.find(id)->pos;
  return p;
}

}  // namespace afmb
