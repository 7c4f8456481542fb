#include "fap/fap_mapping.h"

#include <afm/mpeg4.h>

#include <algorithm>
#include <cstdio>

namespace afmb {

namespace {

using D = FapDriver;

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
  // Inner lip (2.x) and outer lip (8.x) FAPs use the same groups: the lip
  // moves as one; the FDP measured differs.
  for (int outer = 0; outer < 2; ++outer) {
    const int o = outer ? 47 : 0;  // 4 -> 51, 5 -> 52, ... 13 -> 60
    const char *io = outer ? "outer lip" : "inner lip";
    add(4 + o, D::Muscles, 100, {{"upper_lip_left", 100}, {"upper_lip_right", 100}},
        {{"upper_lip_left", -100}, {"upper_lip_right", -100}}, io);
    add(5 + o, D::Muscles, 350, {{"mentalis_left", 100}, {"mentalis_right", 100}},
        {{"mentalis_left", -100}, {"mentalis_right", -100}}, io);
    add(6 + o, D::Muscles, 70, {{"risorius_left", 100}}, {{"orbicularis_oris", 100}}, io);
    add(7 + o, D::Muscles, 70, {{"risorius_right", 100}}, {{"orbicularis_oris", 100}}, io);
    add(8 + o, D::Muscles, 120, {{"upper_lip_left", 100}}, {{"upper_lip_left", -100}}, io);
    add(9 + o, D::Muscles, 120, {{"upper_lip_right", 100}}, {{"upper_lip_right", -100}}, io);
    add(10 + o, D::Muscles, 350, {{"mentalis_left", 100}}, {{"mentalis_left", -100}}, io);
    add(11 + o, D::Muscles, 350, {{"mentalis_right", 100}}, {{"mentalis_right", -100}}, io);
    add(12 + o, D::Muscles, 150, {{"zygomaticus_major_left", 100}}, {{"depressor_anguli_left", 100}}, io);
    add(13 + o, D::Muscles, 150, {{"zygomaticus_major_right", 100}}, {{"depressor_anguli_right", 100}}, io);
  }
  add(14, D::JawThrust, 30, {}, {}, "the jaw's forward translation");
  add(15, D::JawShift, 40, {}, {}, "the jaw's sideways translation");
  add(16, D::Muscles, 40, {{"orbicularis_oris", 100}}, {{"orbicularis_oris", -100}}, "pursing pushes the lips out");
  add(17, D::Muscles, 30, {{"orbicularis_oris", 100}}, {{"orbicularis_oris", -100}}, "pursing pushes the lips out");
  add(18, D::Muscles, 300, {{"mentalis_left", 100}, {"mentalis_right", 100}},
      {{"mentalis_left", -100}, {"mentalis_right", -100}}, "mentalis lifts the chin's skin");
  // ---- group 3: eyelids, eyeballs, pupils ----
  add(19, D::Muscles, 300, {{"orbicularis_oculi_left", 100}}, {{"orbicularis_oculi_left", -100}}, "");
  add(20, D::Muscles, 300, {{"orbicularis_oculi_right", 100}}, {{"orbicularis_oculi_right", -100}}, "");
  add(21, D::Muscles, 300, {{"orbicularis_oculi_left", 100}}, {{"orbicularis_oculi_left", -100}}, "");
  add(22, D::Muscles, 300, {{"orbicularis_oculi_right", 100}}, {{"orbicularis_oculi_right", -100}}, "");
  for (int f = 23; f <= 28; ++f) add(f, D::Rigid, 0, {}, {}, rigid_eye);
  add(29, D::None, 0, {}, {}, "pupil dilation needs pupil geometry, which the eye parts do not have");
  add(30, D::None, 0, {}, {}, "pupil dilation needs pupil geometry, which the eye parts do not have");
  // ---- group 4: eyebrows ----
  add(31, D::Muscles, 200, {{"frontalis_inner_left", 100}}, {{"frontalis_inner_left", -100}}, "");
  add(32, D::Muscles, 200, {{"frontalis_inner_right", 100}}, {{"frontalis_inner_right", -100}}, "");
  add(33, D::Muscles, 150, {{"frontalis_major_left", 100}}, {{"frontalis_major_left", -100}}, "");
  add(34, D::Muscles, 150, {{"frontalis_major_right", 100}}, {{"frontalis_major_right", -100}}, "");
  add(35, D::Muscles, 110, {{"frontalis_outer_left", 100}}, {{"frontalis_outer_left", -100}}, "");
  add(36, D::Muscles, 110, {{"frontalis_outer_right", 100}}, {{"frontalis_outer_right", -100}}, "");
  add(37, D::Muscles, 200, {{"corrugator_left", 100}}, {{"corrugator_left", -100}}, "");
  add(38, D::Muscles, 200, {{"corrugator_right", 100}}, {{"corrugator_right", -100}}, "");
  // ---- group 5: cheeks ----
  add(39, D::None, 0, {}, {}, "a puffed cheek is air pressure, not a muscle");
  add(40, D::None, 0, {}, {}, "a puffed cheek is air pressure, not a muscle");
  add(41, D::Muscles, 120, {{"zygomaticus_major_left", 100}, {"zygomaticus_minor_left", 100}}, {}, "");
  add(42, D::Muscles, 120, {{"zygomaticus_major_right", 100}, {"zygomaticus_minor_right", 100}}, {}, "");
  // ---- group 6: tongue ----
  for (int f = 43; f <= 47; ++f) add(f, D::None, 0, {}, {}, "the tongue is not simulated yet");
  // ---- group 7: head ----
  for (int f = 48; f <= 50; ++f) add(f, D::Rigid, 0, {}, {}, rigid_head);
  // ---- group 9: nose ----
  add(61, D::Muscles, 100, {{"nasalis_left", -100}}, {{"nasalis_left", 100}}, "");
  add(62, D::Muscles, 100, {{"nasalis_right", -100}}, {{"nasalis_right", 100}}, "");
  add(63, D::Muscles, 60, {{"nasalis_left", 100}, {"nasalis_right", 100}},
      {{"nasalis_left", -100}, {"nasalis_right", -100}}, "");
  add(64, D::Muscles, 60, {{"nasalis_left", 100}, {"nasalis_right", -100}},
      {{"nasalis_right", 100}, {"nasalis_left", -100}}, "");
  // ---- group 10: ears ----
  for (int f = 65; f <= 68; ++f)
    add(f, D::None, 0, {}, {}, "human ears do not move: the auricular muscles are vestigial");
  std::sort(t.begin(), t.end(), [](const FapMapping &a, const FapMapping &b) { return a.fap < b.fap; });
  return t;
}

}  // namespace

const std::vector<FapMapping> &fap_mappings() {
  static const std::vector<FapMapping> table = make_table();
  return table;
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
      std::snprintf(b, sizeof b, "%s%s %+g%%", s.empty() ? "" : ", ", c.muscle, c.percent);
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
    if (!m.positive.empty()) out += "  + " + group(m.positive);
    if (!m.negative.empty()) out += "  - " + group(m.negative);
    if (m.note && *m.note) out += std::string("  (") + m.note + ")";
    out += "\n";
  }
  return out;
}

}  // namespace afmb
