// How each MPEG-4 low-level FAP is made (method paper section 4): the
// mapping from FAPs to muscle groups, the jaw or a rigid part, as data. The
// table is in fap_mapping.cpp; docs/fap_mapping.md explains the choices and
// `afm-build --list-faps` prints it.
//
// A muscle group is a pattern of contractions (percent of each muscle's
// calibrated range, face_model.h). The synthesis (fap_synthesis.h) scales
// the whole pattern by one factor s > 0 so that the FAP's FDP moves by
// reference x FAPU along the FAP's direction (MPEG-4 semantics), and the
// pose it reaches becomes the morph target. So the table fixes which muscles
// act and in which proportions; the amount comes from the face.
//
// Reference values: near the 90th percentile of |value| in the real FAP
// streams of ../shared/data/fap (docs/fap_mapping.md lists them), so that
// most frames interpolate and few extrapolate.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace afmb {

enum class FapDriver {
  Muscles,    // a muscle group: a morph target
  JawOpen,    // the jaw's rotation: a morph target and the jaw's rigid control
  JawThrust,  // the jaw's forward translation: likewise
  JawShift,   // the jaw's sideways translation: likewise
  Tongue,     // the tongue part's kinematic motion (anatomy/tongue.h): a morph target
  Pupil,      // an eye part's pupil dilation (anatomy/pupil.h): a morph target
  Rigid,      // eyeballs and head: a rigid part's control in the AFM, no target
  None,       // not synthesized; `note` says why
};

struct FapContraction {
  std::string muscle;   // FaceModel muscle name
  double percent;       // contraction at scale 1, -100..100
};

struct FapMapping {
  int fap = 0;                              // 3..68
  FapDriver driver = FapDriver::None;
  int reference = 0;                        // FAP units (> 0) for targets
  std::vector<FapContraction> positive;     // the group at +reference
  // Bidirectional FAPs: the group at -reference (its own target). Empty:
  // the positive target is extrapolated (the report checks that side).
  std::vector<FapContraction> negative;
  const char *note = "";                    // why (None), or a remark
  // The groups for a model that lacks a muscle of `positive` / `negative`
  // (empty: none; the FAP is then not made).
  std::vector<FapContraction> fallback_positive, fallback_negative;
  // Second groups (empty: none): where the side's own group falls short of
  // the reference (fap_synthesis.h, "Reach, then hold"), this one is tried
  // too, and its target is kept where it takes the FDP nearer the
  // prescribed motion (|achieved - prescribed|). For a region one muscle
  // moves well only in part: the upper lip muscle, pushed, dents the lip at
  // its insertion (8.10) before the lip's side (2.6) comes down half way;
  // mentalis, driven backwards, takes the inner lower lip's middle (2.3)
  // down most of the way, and its depressors the rest on some faces.
  std::vector<FapContraction> second_positive, second_negative;
  // Eyelid FAPs (19-22) act through their lid's driver (the palpebral part
  // of orbicularis oculi, muscle_table.h), which needs an eye part under the
  // lid. Without one they fall back to orbicularis oculi, which closes both
  // lids, and the target keeps only its lid's half of that pose: +1 the upper
  // lid, -1 the lower, split at the height halfway between the lid centres
  // (3.1/3.3 or 3.2/3.4) and blended over the lids' opening. 0: not a lid.
  int lid = 0;
  // The cheek puffs (39, 40): air pressure, not a pose of muscles that
  // other FAPs use. Their targets keep all the skin they move, and no other
  // target gives them a share of its own (fap_partition.h): streams lift the
  // cheeks (41, 42) and move the corners without puffing them (every Xface
  // stream), and split with the puff, those targets stopped short beside
  // 5.1 (Song's joy.fap turned a triangle in 2 frames).
  bool own_skin = false;
  // In-between targets past `reference` on the positive side, FAP units,
  // ascending (formats/afm.md: the player blends a side's targets piecewise
  // linearly). For motions that turn rather than translate: a lid closing
  // over its eyeball follows an arc, and one target extrapolated past its
  // reference takes the lid along the chord, into the eyeball. Each is made
  // only where the group reaches it in full; the report lists the others.
  std::vector<int> farther;
  // Helpers: muscles around the FDP that may join the group, at most
  // kHelperBound of their range either way, to steer the FDP's motion back
  // onto the FAP's direction where the group's own pose drifts off it (the
  // synthesis, fap_synthesis.h, chooses how much). The group's own muscles
  // never help their own side. Empty: the group acts alone.
  std::vector<std::string> helpers;
};

// Whether FAP `fap`'s target is a part's own kinematic motion (the tongue's,
// a pupil's), exact at its FDP by construction, rather than a solve of the
// face model.
bool kinematic_fap(int fap);

// Every FAP 3..68 once, in number order.
const std::vector<FapMapping> &fap_mappings();

// The mapping of FAP `fap`, or nullptr when fap is not in 3..68.
const FapMapping *find_fap_mapping(int fap);

// "muscles", "jaw-open", "jaw-thrust", "jaw-shift", "tongue", "pupil", "rigid",
// "none".
const char *fap_driver_name(FapDriver driver);

// The 14 visemes and 6 expressions (FAP 1 and 2): each a fixed muscle
// combination and jaw opening, posed once; the pose is the target, stored
// at reference 63 (the top of viseme_blend and expression_intensity). No
// FDP rule applies to them, so nothing is steered: the table's numbers are
// the face at full intensity.
struct HighLevelMapping {
  bool expression = false;                  // false: viseme
  int number = 0;                           // viseme 1..14, expression 1..6
  std::vector<FapContraction> muscles;      // percent of each muscle's calibrated range
  int jaw_open = 0;                         // FAP 3 (open_jaw) units, MNS/1024: how far the chin drops
  // The tongue's and the pupils' FAPs (43-47; 29, 30) and their values, FAP
  // units: their own motions (anatomy/tongue.h, pupil.h) in the target, the
  // tongue's under the jaw's, where the face has them.
  std::vector<std::pair<int, int>> parts;
  const char *note = "";                    // what the face does
};

// The 14 visemes, then the 6 expressions, in number order.
const std::vector<HighLevelMapping> &high_level_mappings();

// The mapping of viseme (expression = false) or expression `number`, or
// nullptr when out of range.
const HighLevelMapping *find_high_level_mapping(bool expression, int number);

// Both tables as text, one FAP, viseme or expression per line (afm-build
// --list-faps).
std::string fap_mapping_text();

}  // namespace afmb
