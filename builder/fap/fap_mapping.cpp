#include "fap/fap_mapping.h"

#include <afm/mpeg4.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "anatomy/muscle_table.h"

namespace afmb {

namespace {

using D = FapDriver;
using Group = std::vector<FapContraction>;

// Contraction signs follow muscle_table.cpp: a positive upper lip lowers the
// upper lip and a positive mentalis raises the lower one, as the paper's
// Table 3 drives them.

std::vector<FapMapping> make_table() {
  std::vector<FapMapping> t;
  auto add = [&](int fap, D driver, int ref, std::vector<FapContraction> pos, std::vector<FapContraction> neg,
                 const char *note) {
    FapMapping m;
    m.fap = fap;
    m.driver = driver;
    m.reference = ref;
    m.positive = std::move(pos);
    m.negative = std::move(neg);
    m.note = note;
    t.push_back(std::move(m));
  };
  const char *rigid_eye = "eyeball rotation or thrust: a rigid control of the eye part";
  const char *rigid_head = "head rotation: a rigid control of every part";
  // ---- group 2: jaw, chin, inner lip, corner lip, mid lip ----
  add(3, D::JawOpen, 320, {}, {}, "the jaw's rotation about the condyles");
  // Streams open the jaw past 320 (Xface's fear.fap to 713): the chin's
  // skin lags the bone more the wider it opens, so one target extrapolated
  // folds under the chin (Song: 6 skin triangles at 600, 18 at 1024). The
  // in-betweens follow it (none up to 1024, 8 at 1200), and the jaw's
  // controls bend with them (formats/afm.md, RIGD knots).
  t.back().farther = {640, 1024};
  // Inner lip (2.x) and outer lip (8.x) FAPs use the same groups: the lip
  // moves as one; the FDP measured differs. Except the lower lip lowered:
  // on the outer lip, depressor labii inferioris pulls it down toward the
  // chin while mentalis, driven backwards, pushes. Mentalis alone took
  // Song's 8.7 62 % of the reference down and the generated heads' 87-88 %;
  // with the depressors all three reach it. The inner lip's FDPs keep
  // mentalis alone: with the depressors Song's skin folded before 2.3 came
  // down 35 % (docs/anatomy.md, "Depressor labii inferioris"), and the 10k
  // head's 2.3 reaches 71 % with them, all of it alone. Its middle has them
  // as a second group: mentalis alone took Song's 2.3 90 % of the way down
  // and turned 2 triangles; with the depressors it comes the whole way and
  // turns none (since the fifty-ninth session judged poses with their
  // slivers untangled). So do its sides (10, 11), each with its own side's
  // depressor: mentalis alone took Song's 2.8 and 2.9 90 % of the way at
  // four times its range, 32 % off-axis, the 2k head's 90 %, the 1k head's
  // 99 %; with it all three the whole way, 4.5-8 % off-axis, none folding.
  for (int outer = 0; outer < 2; ++outer) {
    const int o = outer ? 47 : 0;  // 4 -> 51, 5 -> 52, ... 13 -> 60
    const char *io = outer ? "outer lip" : "inner lip";
    auto with = [](Group push, const Group &pull) {
      push.insert(push.end(), pull.begin(), pull.end());
      return push;
    };
    auto lowered = [&with, outer](Group push, const Group &pull) { return outer ? with(push, pull) : push; };
    add(4 + o, D::Muscles, 100, {{"upper_lip_left", 100}, {"upper_lip_right", 100}},
        {{"upper_lip_left", -100}, {"upper_lip_right", -100}}, io);
    // The middle raised, where the upper lip muscles alone fall short (the
    // 2,000-vertex head's cover 4 vertices: 2.2 38 % of the reference, 8.1
    // 95 %): orbicularis oris, driven backwards, parts the lips with them.
    t.back().second_negative = {{"upper_lip_left", -100}, {"upper_lip_right", -100}, {"orbicularis_oris", -50}};
    const Group middle_push = {{"mentalis_left", -100}, {"mentalis_right", -100}},
                middle_pull = {{"depressor_labii_left", 100}, {"depressor_labii_right", 100}};
    add(5 + o, D::Muscles, 350, {{"mentalis_left", 100}, {"mentalis_right", 100}},
        lowered(middle_push, middle_pull), io);
    if (!outer) t.back().second_negative = with(middle_push, middle_pull);  // the outer lip's group
    add(6 + o, D::Muscles, 70, {{"risorius_left", 100}}, {{"orbicularis_oris", 100}}, io);
    add(7 + o, D::Muscles, 70, {{"risorius_right", 100}}, {{"orbicularis_oris", 100}}, io);
    // The corner drawn in, where orbicularis oris alone falls short (Song:
    // 61 % of the reference, the skin folding past its range): risorius,
    // driven backwards, pushes the corner toward the mouth's middle, and
    // zygomaticus major's push, less, adds to it. Song's corner then comes
    // in the whole reference, lower by a quarter of it and forward (the
    // lips purse); the generated heads' reach it with the sphincter alone.
    for (int k = 0; k < 2; ++k) {
      const std::string side = k ? "right" : "left";
      t[t.size() - 2 + static_cast<size_t>(k)].second_negative = {
          {"orbicularis_oris", 100}, {"risorius_" + side, -100}, {"zygomaticus_major_" + side, -30}};
    }
    add(8 + o, D::Muscles, 120, {{"upper_lip_left", 100}}, {{"upper_lip_left", -100}}, io);
    add(9 + o, D::Muscles, 120, {{"upper_lip_right", 100}}, {{"upper_lip_right", -100}}, io);
    // The lip's side, where the upper lip muscle alone falls short: pushed
    // down at its insertion (8.10), it dents the lip there and turns the
    // skin over at the outer lip (Song: 2.6 down 45 % of the reference, the
    // generated 10k head's 40 % either way). Zygomaticus minor inserts
    // between 2.6 and 8.5 (muscle_table.cpp), and the paper's Table 3
    // already gives it a share of FAP 8; driven backwards with the upper lip
    // it lowers the lip's side as a whole, and with it raises it.
    for (int k = 0; k < 2; ++k) {
      FapMapping &m = t[t.size() - 2 + static_cast<size_t>(k)];
      const std::string side = k ? "right" : "left";
      m.second_positive = {{"upper_lip_" + side, 100}, {"zygomaticus_minor_" + side, -100}};
      m.second_negative = {{"upper_lip_" + side, -100}, {"zygomaticus_minor_" + side, 15}};
    }
    add(10 + o, D::Muscles, 350, {{"mentalis_left", 100}},
        lowered({{"mentalis_left", -100}}, {{"depressor_labii_left", 100}}), io);
    add(11 + o, D::Muscles, 350, {{"mentalis_right", 100}},
        lowered({{"mentalis_right", -100}}, {{"depressor_labii_right", 100}}), io);
    if (!outer)
      for (int k = 0; k < 2; ++k) {
        const std::string side = k ? "right" : "left";
        t[t.size() - 2 + static_cast<size_t>(k)].second_negative = {{"mentalis_" + side, -100},
                                                                      {"depressor_labii_" + side, 100}};
      }
    add(12 + o, D::Muscles, 150, {{"zygomaticus_major_left", 100}}, {{"depressor_anguli_left", 100}}, io);
    add(13 + o, D::Muscles, 150, {{"zygomaticus_major_right", 100}}, {{"depressor_anguli_right", 100}}, io);
  }
  add(14, D::JawThrust, 30, {}, {}, "the jaw's forward translation");
  add(15, D::JawShift, 40, {}, {}, "the jaw's sideways translation");
  add(16, D::Muscles, 40, {{"lip_protrusion_lower", 100}}, {{"lip_protrusion_lower", -100}}, "the lower lip pushed out");
  add(17, D::Muscles, 30, {{"lip_protrusion_upper", 100}}, {{"lip_protrusion_upper", -100}}, "the upper lip pushed out");
  // The chin boss (2.10) raised by the chin raiser (mentalis' pull on the
  // chin's skin). Mentalis' push on the lower lip, which had it, took the
  // boss up 28-51 % of the reference (Song: 84 of 300). Lowered:
  // no muscle pulls the chin's skin down without the jaw, and no stream in
  // ../shared/data sends a negative value; the raiser's push with mentalis'
  // on the lip reaches furthest (docs/anatomy.md "Chin raiser").
  add(18, D::Muscles, 300, {{"chin_raiser", 100}},
      {{"chin_raiser", -100}, {"mentalis_left", -100}, {"mentalis_right", -100}},
      "the chin raiser (mentalis' pull) lifts the chin's skin");
  // ---- group 3: eyelids, eyeballs, pupils ----
  const char *upper = "the upper lid's driver turns it down over the eyeball; where its load falls short, the "
                      "lid turned as a whole by its tarsus (without an eye part: the upper lid's half of "
                      "orbicularis oculi's pose)";
  const char *lower = "the lower lid's driver turns it up over the eyeball; where its load falls short, the "
                      "lid turned as a whole by its tarsus (without an eye part: the lower lid's half of "
                      "orbicularis oculi's pose)";
  add(19, D::Muscles, 300, {{"palpebral_upper_left", 100}}, {{"palpebral_upper_left", -100}}, upper);
  add(20, D::Muscles, 300, {{"palpebral_upper_right", 100}}, {{"palpebral_upper_right", -100}}, upper);
  add(21, D::Muscles, 300, {{"palpebral_lower_left", 100}}, {{"palpebral_lower_left", -100}}, lower);
  add(22, D::Muscles, 300, {{"palpebral_lower_right", 100}}, {{"palpebral_lower_right", -100}}, lower);
  for (size_t k = t.size() - 4; k < t.size(); ++k) {
    const std::string sphincter = t[k].fap % 2 ? "orbicularis_oculi_left" : "orbicularis_oculi_right";
    t[k].lid = t[k].fap <= 20 ? +1 : -1;
    t[k].fallback_positive = {{sphincter, 100}};
    t[k].fallback_negative = {{sphincter, -100}};
    // Real streams close the upper lids to 1024 (the iris' diameter: shut
    // on MPEG-4's neutral face) and the lower ones to 380-530.
    t[k].farther = t[k].lid > 0 ? std::vector<int>{600, 1024} : std::vector<int>{600};
  }
  for (int f = 23; f <= 28; ++f) add(f, D::Rigid, 0, {}, {}, rigid_eye);
  // Dilation where the eye part draws its pupil with vertices: the
  // diameter grows by about a third of the iris' (the neutral pupil's own
  // third to two thirds) at the reference.
  const char *pupil = "the eye part's pupil ring widens, the iris narrows: anatomy/pupil.h";
  add(29, D::Pupil, 300, {}, {}, pupil);
  add(30, D::Pupil, 300, {}, {}, pupil);
  // ---- group 4: eyebrows ----
  // The inner brow lowered: depressor supercilii pulls it down from below
  // while frontalis, driven backwards, pushes from above. Frontalis alone
  // took Song's inner brow 26 % of the reference down (its brows sit 5.6
  // units over the lids, the reference asks 5.0) and the reference heads'
  // at 2.8-2.9 times its range (docs/anatomy.md "Depressor supercilii").
  add(31, D::Muscles, 200, {{"frontalis_inner_left", 100}},
      {{"frontalis_inner_left", -100}, {"depressor_supercilii_left", 100}}, "");
  add(32, D::Muscles, 200, {{"frontalis_inner_right", 100}},
      {{"frontalis_inner_right", -100}, {"depressor_supercilii_right", 100}}, "");
  add(33, D::Muscles, 150, {{"frontalis_major_left", 100}}, {{"frontalis_major_left", -100}}, "");
  add(34, D::Muscles, 150, {{"frontalis_major_right", 100}}, {{"frontalis_major_right", -100}}, "");
  add(35, D::Muscles, 110, {{"frontalis_outer_left", 100}}, {{"frontalis_outer_left", -100}}, "");
  add(36, D::Muscles, 110, {{"frontalis_outer_right", 100}}, {{"frontalis_outer_right", -100}}, "");
  // Squeezing takes half the streams' 90th percentile: at 200 the inner brow
  // would pass the corrugator's attachment (docs/fap_mapping.md).
  add(37, D::Muscles, 100, {{"corrugator_left", 100}}, {{"corrugator_left", -100}}, "");
  add(38, D::Muscles, 100, {{"corrugator_right", 100}}, {{"corrugator_right", -100}}, "");
  // ---- group 5: cheeks ----
  add(39, D::Muscles, 60, {{"cheek_puff_left", 100}}, {{"cheek_puff_left", -100}}, "air pressure in the mouth");
  add(40, D::Muscles, 60, {{"cheek_puff_right", 100}}, {{"cheek_puff_right", -100}}, "air pressure in the mouth");
  t[t.size() - 2].own_skin = t.back().own_skin = true;  // no share of the skin (fap_mapping.h)
  add(41, D::Muscles, 120, {{"zygomaticus_major_left", 100}, {"zygomaticus_minor_left", 100}}, {}, "");
  add(42, D::Muscles, 120, {{"zygomaticus_major_right", 100}, {"zygomaticus_minor_right", 100}}, {}, "");
  // ---- group 6: tongue ----
  // No stream in ../shared/data sends them: references from the mouth's
  // size, about a centimetre on an adult face (MW0 about 5 cm, MNS0 about
  // 2 cm), and a 30-degree roll.
  const char *tongue = "the tongue part's own motion, exact at its FDP: anatomy/tongue.h";
  add(43, D::Tongue, 200, {}, {}, tongue);
  add(44, D::Tongue, 512, {}, {}, tongue);
  add(45, D::Tongue, 200, {}, {}, tongue);
  add(46, D::Tongue, 512, {}, {}, tongue);
  add(47, D::Tongue, 52360, {}, {}, tongue);
  // ---- group 7: head ----
  for (int f = 48; f <= 50; ++f) add(f, D::Rigid, 0, {}, {}, rigid_head);
  // ---- group 9: nose ----
  add(61, D::Muscles, 100, {{"dilator_naris_left", 100}}, {{"dilator_naris_left", -100}}, "the nose's wing flared");
  add(62, D::Muscles, 100, {{"dilator_naris_right", 100}}, {{"dilator_naris_right", -100}}, "the nose's wing flared");
  add(63, D::Muscles, 60, {{"nose_raise", 100}}, {{"nose_lower", 100}}, "the nose's tip raised");
  add(64, D::Muscles, 60, {{"nose_bend_right", 100}}, {{"nose_bend_left", 100}}, "the nose's tip bent sideways");
  // ---- group 10: ears ----
  for (int f = 65; f <= 68; ++f)
    add(f, D::None, 0, {}, {}, "human ears do not move: the auricular muscles are vestigial");
  std::sort(t.begin(), t.end(), [](const FapMapping &a, const FapMapping &b) { return a.fap < b.fap; });
  // Helpers (fap_mapping.h): the muscles beside the group's that move its
  // FDP, on the FAP's own side, and orbicularis oris, which spans both (its
  // cost, steer.h, counts the whole face it moves); for the lips' vertical
  // FAPs, the lip's protrusion driver, the one muscle that moves a lip in
  // depth (a raised or lowered lip's middle comes forward or goes back).
  // Left out: the lids (they follow the eyeball, and so does their off-axis
  // motion), the chin, bending the nose.
  auto help = [&t](int fap, std::vector<std::string> names) {
    t[static_cast<size_t>(fap - 3)].helpers = std::move(names);
  };
  for (int o : {0, 47}) {
    help(4 + o, {"orbicularis_oris", "lip_protrusion_upper"});
    help(5 + o, {"orbicularis_oris", "depressor_anguli_left", "depressor_anguli_right", "lip_protrusion_lower"});
    for (const char *s : {"left", "right"}) {
      const std::string side = s;
      const int k = side == "left" ? 0 : 1;
      help(6 + k + o, {"zygomaticus_major_" + side, "depressor_anguli_" + side});
      help(8 + k + o, {"zygomaticus_minor_" + side, "orbicularis_oris", "lip_protrusion_upper"});
      help(10 + k + o, {"depressor_anguli_" + side, "orbicularis_oris", "lip_protrusion_lower"});
      help(12 + k + o, {"zygomaticus_minor_" + side, "upper_lip_" + side, "risorius_" + side, "orbicularis_oris"});
    }
  }
  for (const char *s : {"left", "right"}) {
    const std::string side = s;
    const int k = side == "left" ? 0 : 1;
    help(31 + k, {"corrugator_" + side, "frontalis_major_" + side});
    help(33 + k, {"frontalis_inner_" + side, "frontalis_outer_" + side, "corrugator_" + side});
    help(35 + k, {"frontalis_major_" + side, "corrugator_" + side});
    help(37 + k, {"frontalis_inner_" + side});
    help(41 + k, {"orbicularis_oculi_" + side, "risorius_" + side, "upper_lip_" + side});
    help(61 + k, {"upper_lip_" + side, "zygomaticus_minor_" + side});
  }
  help(63, {"upper_lip_left", "upper_lip_right"});
  // The lips pushed out: mentalis and upper lip hold each lip's middle level.
  help(16, {"mentalis_left", "mentalis_right"});
  help(17, {"upper_lip_left", "upper_lip_right"});
  return t;
}

// Visemes and expressions. Muscles by pair name ("zygomaticus_major" is
// both sides) or by their own (orbicularis oris, each lip's protrusion
// driver); the signs as above: a negative upper lip raises the upper
// lip, a negative orbicularis oculi widens the eye. Jaw openings in FAP 3
// units (the table's reference, wide open, is 320). Mentalis, the chin
// raiser (AU 17), presses the lower lip up.
std::vector<HighLevelMapping> make_high_level_table() {
  std::vector<HighLevelMapping> t;
  struct Pair {
    const char *muscle;  // a muscle's name (muscle_table.h), else a pair's (both sides)
    double percent;
  };
  auto add = [&](bool expression, int number, int jaw, std::vector<Pair> pairs, const char *note,
                 std::vector<std::pair<int, int>> parts = {}) {
    HighLevelMapping m;
    m.expression = expression;
    m.number = number;
    m.jaw_open = jaw;
    m.note = note;
    m.parts = std::move(parts);
    for (const Pair &p : pairs) {
      const std::string name = p.muscle;
      if (find_muscle(name) >= 0) m.muscles.push_back({name, p.percent});
      else
        for (const char *side : {"_left", "_right"}) m.muscles.push_back({name + side, p.percent});
    }
    t.push_back(std::move(m));
  };
  // ---- visemes (ISO/IEC 14496-2 Table C-1) ----
  // The tongue (FAPs 43-47; references 200 MW and 512 MNS units, about a
  // centimetre): the tip forward between the teeth for the dental /T, D/,
  // up to the ridge behind the upper teeth for /t, d/, /n, l/ and the
  // sibilants, curled back for /r/, the body up to the soft palate for /k, g/,
  // high for the front vowels, low for the open ones.
  add(false, 1, 0, {{"orbicularis_oris", 50}, {"mentalis", 40}}, "lips pressed together");
  add(false, 2, 60, {{"mentalis", 60}, {"upper_lip", -30}}, "lower lip up against the upper teeth");
  add(false, 3, 100, {}, "jaw a little open, tongue between the teeth", {{45, 150}, {44, 100}});
  add(false, 4, 90, {}, "jaw a little open, tongue tip up to the ridge", {{44, 400}, {45, 50}});
  add(false, 5, 130, {}, "jaw half open, tongue body up to the soft palate", {{46, 450}});
  // The rounded visemes push the lips out too (docs/anatomy.md, "Lip
  // protrusion"): orbicularis oris alone rounds them in place.
  add(false, 6, 80,
      {{"orbicularis_oris", 60}, {"upper_lip", -20}, {"lip_protrusion_upper", 50}, {"lip_protrusion_lower", 50}},
      "lips rounded and pushed out, tongue blade up", {{44, 300}, {46, 200}});
  add(false, 7, 50, {{"risorius", 50}}, "teeth near, lips spread, tongue tip up", {{44, 300}});
  add(false, 8, 100, {}, "jaw a little open, tongue tip up to the ridge", {{44, 400}});
  add(false, 9, 90, {{"orbicularis_oris", 40}, {"lip_protrusion_upper", 25}, {"lip_protrusion_lower", 25}},
      "lips a little rounded, tongue tip up and back", {{44, 250}, {45, -100}});
  add(false, 10, 300, {}, "jaw wide open, tongue low", {{46, -200}});
  add(false, 11, 180, {{"risorius", 50}, {"zygomaticus_major", 20}}, "jaw open, lips spread, tongue half high",
      {{46, 150}});
  add(false, 12, 100, {{"risorius", 70}, {"zygomaticus_major", 30}}, "lips spread wide, tongue high",
      {{46, 250}});
  add(false, 13, 250, {{"orbicularis_oris", 40}, {"lip_protrusion_upper", 40}, {"lip_protrusion_lower", 40}},
      "jaw open, lips rounded, tongue low", {{46, -150}});
  add(false, 14, 90, {{"orbicularis_oris", 90}, {"lip_protrusion_upper", 80}, {"lip_protrusion_lower", 80}},
      "lips tightly rounded and pushed out, tongue back up", {{46, 200}});
  // ---- expressions (ISO/IEC 14496-2 Table C-3) ----
  // Fear widens the pupils (the sympathetic response; FAPs 29, 30, reference
  // 300 IRISD units), surprise a little.
  add(true, 1, 40,
      {{"zygomaticus_major", 100}, {"zygomaticus_minor", 50}, {"risorius", 20}, {"orbicularis_oculi", 40}},
      "joy: corners up and back, cheeks raised, eyes narrowed");
  add(true, 2, 0,
      {{"frontalis_inner", 80}, {"corrugator", 50}, {"depressor_anguli", 100}, {"mentalis", 50}},
      "sadness: inner brows up and together, corners down, chin raised");
  add(true, 3, 0,
      {{"corrugator", 100}, {"depressor_supercilii", 60}, {"orbicularis_oculi", 40}, {"orbicularis_oris", 50},
       {"mentalis", 40}},
      "anger: brows down and together, eyes narrowed, lips pressed");
  add(true, 4, 80,
      {{"frontalis_inner", 100}, {"frontalis_major", 50}, {"corrugator", 40}, {"risorius", 70},
       {"orbicularis_oculi", -50}},
      "fear: brows up and together, eyes wide, pupils wide, lips stretched, jaw dropped", {{29, 200}, {30, 200}});
  add(true, 5, 0,
      {{"upper_lip", -100}, {"nasalis", 60}, {"corrugator", 40}, {"depressor_anguli", 30}, {"mentalis", 30}},
      "disgust: upper lip raised, nose wrinkled, brows lowered");
  add(true, 6, 220,
      {{"frontalis_inner", 100}, {"frontalis_major", 100}, {"frontalis_outer", 100}, {"orbicularis_oculi", -60}},
      "surprise: brows raised, eyes wide, pupils a little wide, jaw dropped", {{29, 100}, {30, 100}});
  return t;
}

}  // namespace

const std::vector<HighLevelMapping> &high_level_mappings() {
  static const std::vector<HighLevelMapping> table = make_high_level_table();
  return table;
}

const HighLevelMapping *find_high_level_mapping(bool expression, int number) {
  for (const HighLevelMapping &m : high_level_mappings())
    if (m.expression == expression && m.number == number) return &m;
  return nullptr;
}

const std::vector<FapMapping> &fap_mappings() {
  static const std::vector<FapMapping> table = make_table();
  return table;
}

bool kinematic_fap(int fap) {
  const FapMapping *m = find_fap_mapping(fap);
  return m && (m->driver == FapDriver::Tongue || m->driver == FapDriver::Pupil);
}

const FapMapping *find_fap_mapping(int fap) {
  const std::vector<FapMapping> &t = fap_mappings();
  if (fap < 3 || fap > 68) return nullptr;
  return &t[static_cast<size_t>(fap - 3)];
}

const char *fap_driver_name(FapDriver driver) {
  switch (driver) {
    case FapDriver::Muscles: return "muscles";
    case FapDriver::JawOpen: return "jaw-open";
    case FapDriver::JawThrust: return "jaw-thrust";
    case FapDriver::JawShift: return "jaw-shift";
    case FapDriver::Tongue: return "tongue";
    case FapDriver::Pupil: return "pupil";
    case FapDriver::Rigid: return "rigid";
    case FapDriver::None: return "none";
  }
  return "?";
}

std::string fap_mapping_text() {
  std::string out;
  auto group = [](const std::vector<FapContraction> &g) {
    std::string s;
    for (const FapContraction &c : g) {
      char b[96];
      std::snprintf(b, sizeof b, "%s%s %+g%%", s.empty() ? "" : ", ", c.muscle.c_str(), c.percent);
      s += b;
    }
    return s;
  };
  for (const FapMapping &m : fap_mappings()) {
    const afm_fap_info *info = afm_fap(m.fap);
    char head[128];
    std::snprintf(head, sizeof head, "%2d %-22s %-10s", m.fap, info ? info->name : "?", fap_driver_name(m.driver));
    out += head;
    if (m.reference > 0) out += " ref " + std::to_string(m.reference);
    for (int r : m.farther) out += "," + std::to_string(r);
    if (!m.positive.empty()) out += "  + " + group(m.positive);
    if (!m.negative.empty()) out += "  - " + group(m.negative);
    if (!m.second_positive.empty()) out += "  second + " + group(m.second_positive);
    if (!m.second_negative.empty()) out += "  second - " + group(m.second_negative);
    for (size_t k = 0; k < m.helpers.size(); ++k) out += (k ? ", " : "  helpers ") + m.helpers[k];
    if (m.note && *m.note) out += std::string("  (") + m.note + ")";
    out += "\n";
  }
  for (const HighLevelMapping &m : high_level_mappings()) {
    char head[128];
    std::snprintf(head, sizeof head, "%s%-2d %-22s %-10s ref 63", m.expression ? "e" : "v", m.number,
                  m.expression ? afm_expression_name(m.number) : afm_viseme_phonemes(m.number), "muscles");
    out += head;
    if (m.jaw_open) out += "  jaw " + std::to_string(m.jaw_open);
    if (!m.muscles.empty()) out += "  + " + group(m.muscles);
    for (size_t k = 0; k < m.parts.size(); ++k)
      out += (k ? ", " : "  FAPs ") + std::to_string(m.parts[k].first) + " " +
             (m.parts[k].second > 0 ? "+" : "") + std::to_string(m.parts[k].second);
    out += std::string("  (") + m.note + ")\n";
  }
  return out;
}

}  // namespace afmb
