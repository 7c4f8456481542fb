/* MPEG-4 face animation tables (see afm/mpeg4.h).
 *
 * Hand-written from ISO/IEC 14496-2 Annex C as compiled in
 * ../shared/reference/mpeg4-fap-table.csv and mpeg4-fdp-list.csv;
 * tests/formats/test_mpeg4_tables.cpp reads those files and checks every
 * field here against them, so a typo on either side fails a test.
 */
#include "afm/mpeg4.h"

#include <string.h>

/* Unit vectors in the MPEG-4 frame: +x the face's own left, +y up, +z forward. */
#define D_NONE {0, 0, 0}
#define D_LEFT {1, 0, 0}
#define D_RIGHT {-1, 0, 0}
#define D_UP {0, 1, 0}
#define D_DOWN {0, -1, 0}
#define D_FORWARD {0, 0, 1}
/* Rotation axes, right-hand rule, chosen so a positive angle gives the
 * table's positive motion:
 *   yaw "left":   about +y, gaze +z turns toward +x (the face's left);
 *   pitch "down": about +x, gaze +z turns toward -y;
 *   roll "right": about +z, the top of the head (+y) turns toward -x. */
#define A_YAW_LEFT {0, 1, 0}
#define A_PITCH_DOWN {1, 0, 0}
#define A_ROLL_RIGHT {0, 0, 1}

#define HL AFM_MOTION_HIGH_LEVEL
#define TR AFM_MOTION_TRANSLATE
#define RO AFM_MOTION_ROTATE
#define DI AFM_MOTION_DILATE
#define RL AFM_MOTION_ROLL

static const afm_fap_info kFaps[AFM_FAP_COUNT] = {
    /* number, name, unit, bidirectional, motion, direction, positive, group, fdp, quant */
    {1, "viseme", AFM_FAPU_NONE, 0, HL, D_NONE, "na", 1, 0, 0, 1},
    {2, "expression", AFM_FAPU_NONE, 0, HL, D_NONE, "na", 1, 0, 0, 1},
    {3, "open_jaw", AFM_FAPU_MNS, 0, TR, D_DOWN, "down", 2, 2, 1, 4},
    {4, "lower_t_midlip", AFM_FAPU_MNS, 1, TR, D_DOWN, "down", 2, 2, 2, 2},
    {5, "raise_b_midlip", AFM_FAPU_MNS, 1, TR, D_UP, "up", 2, 2, 3, 2},
    {6, "stretch_l_cornerlip", AFM_FAPU_MW, 1, TR, D_LEFT, "left", 2, 2, 4, 2},
    {7, "stretch_r_cornerlip", AFM_FAPU_MW, 1, TR, D_RIGHT, "right", 2, 2, 5, 2},
    {8, "lower_t_lip_lm", AFM_FAPU_MNS, 1, TR, D_DOWN, "down", 2, 2, 6, 2},
    {9, "lower_t_lip_rm", AFM_FAPU_MNS, 1, TR, D_DOWN, "down", 2, 2, 7, 2},
    {10, "raise_b_lip_lm", AFM_FAPU_MNS, 1, TR, D_UP, "up", 2, 2, 8, 2},
    {11, "raise_b_lip_rm", AFM_FAPU_MNS, 1, TR, D_UP, "up", 2, 2, 9, 2},
    {12, "raise_l_cornerlip", AFM_FAPU_MNS, 1, TR, D_UP, "up", 2, 2, 4, 2},
    {13, "raise_r_cornerlip", AFM_FAPU_MNS, 1, TR, D_UP, "up", 2, 2, 5, 2},
    {14, "thrust_jaw", AFM_FAPU_MNS, 0, TR, D_FORWARD, "forward", 2, 2, 1, 1},
    /* Candide-3.1.6 gives MNS for FAP 15; the standard (and Greta, Cal3D) MW. */
    {15, "shift_jaw", AFM_FAPU_MW, 1, TR, D_RIGHT, "right", 2, 2, 1, 1},
    {16, "push_b_lip", AFM_FAPU_MNS, 1, TR, D_FORWARD, "forward", 2, 2, 3, 1},
    {17, "push_t_lip", AFM_FAPU_MNS, 1, TR, D_FORWARD, "forward", 2, 2, 2, 1},
    {18, "depress_chin", AFM_FAPU_MNS, 1, TR, D_UP, "up", 2, 2, 10, 1},
    {19, "close_t_l_eyelid", AFM_FAPU_IRISD, 1, TR, D_DOWN, "down", 3, 3, 1, 1},
    {20, "close_t_r_eyelid", AFM_FAPU_IRISD, 1, TR, D_DOWN, "down", 3, 3, 2, 1},
    {21, "close_b_l_eyelid", AFM_FAPU_IRISD, 1, TR, D_UP, "up", 3, 3, 3, 1},
    {22, "close_b_r_eyelid", AFM_FAPU_IRISD, 1, TR, D_UP, "up", 3, 3, 4, 1},
    /* Eyeball rotations and thrusts move the whole eyeball (FDP 3.5 / 3.6),
     * which the standard's table lists as no FDP subgroup. */
    {23, "yaw_l_eyeball", AFM_FAPU_AU, 1, RO, A_YAW_LEFT, "left", 3, 0, 0, 128},
    {24, "yaw_r_eyeball", AFM_FAPU_AU, 1, RO, A_YAW_LEFT, "left", 3, 0, 0, 128},
    {25, "pitch_l_eyeball", AFM_FAPU_AU, 1, RO, A_PITCH_DOWN, "down", 3, 0, 0, 128},
    {26, "pitch_r_eyeball", AFM_FAPU_AU, 1, RO, A_PITCH_DOWN, "down", 3, 0, 0, 128},
    {27, "thrust_l_eyeball", AFM_FAPU_ES, 1, TR, D_FORWARD, "forward", 3, 0, 0, 1},
    {28, "thrust_r_eyeball", AFM_FAPU_ES, 1, TR, D_FORWARD, "forward", 3, 0, 0, 1},
    {29, "dilate_l_pupil", AFM_FAPU_IRISD, 1, DI, D_NONE, "growing", 3, 3, 5, 1},
    {30, "dilate_r_pupil", AFM_FAPU_IRISD, 1, DI, D_NONE, "growing", 3, 3, 6, 1},
    {31, "raise_l_i_eyebrow", AFM_FAPU_ENS, 1, TR, D_UP, "up", 4, 4, 1, 2},
    {32, "raise_r_i_eyebrow", AFM_FAPU_ENS, 1, TR, D_UP, "up", 4, 4, 2, 2},
    {33, "raise_l_m_eyebrow", AFM_FAPU_ENS, 1, TR, D_UP, "up", 4, 4, 3, 2},
    {34, "raise_r_m_eyebrow", AFM_FAPU_ENS, 1, TR, D_UP, "up", 4, 4, 4, 2},
    {35, "raise_l_o_eyebrow", AFM_FAPU_ENS, 1, TR, D_UP, "up", 4, 4, 5, 2},
    {36, "raise_r_o_eyebrow", AFM_FAPU_ENS, 1, TR, D_UP, "up", 4, 4, 6, 2},
    {37, "squeeze_l_eyebrow", AFM_FAPU_ES, 1, TR, D_RIGHT, "right", 4, 4, 1, 1},
    {38, "squeeze_r_eyebrow", AFM_FAPU_ES, 1, TR, D_LEFT, "left", 4, 4, 2, 1},
    {39, "puff_l_cheek", AFM_FAPU_ES, 1, TR, D_LEFT, "left", 5, 5, 1, 2},
    {40, "puff_r_cheek", AFM_FAPU_ES, 1, TR, D_RIGHT, "right", 5, 5, 2, 2},
    {41, "lift_l_cheek", AFM_FAPU_ENS, 0, TR, D_UP, "up", 5, 5, 3, 2},
    {42, "lift_r_cheek", AFM_FAPU_ENS, 0, TR, D_UP, "up", 5, 5, 4, 2},
    {43, "shift_tongue_tip", AFM_FAPU_MW, 1, TR, D_RIGHT, "right", 6, 6, 1, 1},
    {44, "raise_tongue_tip", AFM_FAPU_MNS, 1, TR, D_UP, "up", 6, 6, 1, 1},
    {45, "thrust_tongue_tip", AFM_FAPU_MW, 1, TR, D_FORWARD, "forward", 6, 6, 1, 1},
    {46, "raise_tongue", AFM_FAPU_MNS, 1, TR, D_UP, "up", 6, 6, 2, 1},
    /* Tongue roll bends the tongue through 6.3 and 6.4; the table keeps the
     * first. */
    {47, "tongue_roll", AFM_FAPU_AU, 0, RL, D_NONE, "concave upward", 6, 6, 3, 512},
    /* Head rotations turn about the top of the spine (FDP 7.1), which the
     * table lists as no FDP subgroup. */
    {48, "head_pitch", AFM_FAPU_AU, 1, RO, A_PITCH_DOWN, "down", 7, 0, 0, 170},
    {49, "head_yaw", AFM_FAPU_AU, 1, RO, A_YAW_LEFT, "left", 7, 0, 0, 170},
    {50, "head_roll", AFM_FAPU_AU, 1, RO, A_ROLL_RIGHT, "right", 7, 0, 0, 170},
    {51, "lower_t_midlip_o", AFM_FAPU_MNS, 1, TR, D_DOWN, "down", 8, 8, 1, 2},
    {52, "raise_b_midlip_o", AFM_FAPU_MNS, 1, TR, D_UP, "up", 8, 8, 2, 2},
    {53, "stretch_l_cornerlip_o", AFM_FAPU_MW, 1, TR, D_LEFT, "left", 8, 8, 3, 2},
    {54, "stretch_r_cornerlip_o", AFM_FAPU_MW, 1, TR, D_RIGHT, "right", 8, 8, 4, 2},
    {55, "lower_t_lip_lm_o", AFM_FAPU_MNS, 1, TR, D_DOWN, "down", 8, 8, 5, 2},
    {56, "lower_t_lip_rm_o", AFM_FAPU_MNS, 1, TR, D_DOWN, "down", 8, 8, 6, 2},
    {57, "raise_b_lip_lm_o", AFM_FAPU_MNS, 1, TR, D_UP, "up", 8, 8, 7, 2},
    {58, "raise_b_lip_rm_o", AFM_FAPU_MNS, 1, TR, D_UP, "up", 8, 8, 8, 2},
    {59, "raise_l_cornerlip_o", AFM_FAPU_MNS, 1, TR, D_UP, "up", 8, 8, 3, 2},
    {60, "raise_r_cornerlip_o", AFM_FAPU_MNS, 1, TR, D_UP, "up", 8, 8, 4, 2},
    {61, "stretch_l_nose", AFM_FAPU_ENS, 1, TR, D_LEFT, "left", 9, 9, 1, 1},
    {62, "stretch_r_nose", AFM_FAPU_ENS, 1, TR, D_RIGHT, "right", 9, 9, 2, 1},
    {63, "raise_nose", AFM_FAPU_ENS, 1, TR, D_UP, "up", 9, 9, 3, 1},
    {64, "bend_nose", AFM_FAPU_ENS, 1, TR, D_RIGHT, "right", 9, 9, 3, 1},
    {65, "raise_l_ear", AFM_FAPU_ENS, 1, TR, D_UP, "up", 10, 10, 1, 1},
    {66, "raise_r_ear", AFM_FAPU_ENS, 1, TR, D_UP, "up", 10, 10, 2, 1},
    {67, "pull_l_ear", AFM_FAPU_ENS, 1, TR, D_LEFT, "left", 10, 10, 3, 1},
    {68, "pull_r_ear", AFM_FAPU_ENS, 1, TR, D_RIGHT, "right", 10, 10, 4, 1},
};

/* Descriptions as in mpeg4-fdp-list.csv (after the Candide-3 report); the
 * parenthesised ones are the standard's group captions where the report lists
 * no single point. 3.8 / 3.12 (right eye inner / outer corner) agree with the
 * standard's eye figure (../shared/reference/fdp-diagrams/fdp_eyes.png).
 *
 * Ten deviate from the CSV, which mirrors them:
 *  - 2.6-2.9 and 8.5-8.8: the CSV puts 2.6 between 2.2 and 2.5 (the right
 *    corner), but FAP 8 lower_t_lip_lm (left middle) moves 2.6, FAP 55
 *    lower_t_lip_lm_o moves 8.5, the paper's Table 1 pairs 2.6 and 8.5 in the
 *    left zygomaticus minor, and Song's 2.6 and 8.5 lie at +x beside 2.4 / 8.3;
 *  - 10.7 / 10.8: the face figure (fdp_face.png) draws 10.7 at the lower
 *    contact of the left ear and 10.8 of the right one.
 * tests/formats/test_mpeg4_tables.cpp lists the CSV's wording for each. */
static const afm_fdp_info kFdps[AFM_FDP_COUNT] = {
    {2, 1, "Bottom of the chin"},
    {2, 2, "Middle point of inner upper lip contour"},
    {2, 3, "Middle point of inner lower lip contour"},
    {2, 4, "Left corner of inner lip contour"},
    {2, 5, "Right corner of inner lip contour"},
    {2, 6, "Midpoint between FFP 2.2 and 2.4 on the inner upper lip contour"},
    {2, 7, "Midpoint between FFP 2.2 and 2.5 on the inner upper lip contour"},
    {2, 8, "Midpoint between FFP 2.3 and 2.4 on the inner lower lip contour"},
    {2, 9, "Midpoint between FFP 2.3 and 2.5 on the inner lower lip contour"},
    {2, 10, "Chin boss"},
    {2, 11, "Chin left corner"},
    {2, 12, "Chin right corner"},
    {2, 13, "Left corner of jaw bone"},
    {2, 14, "Right corner of jaw bone"},
    {3, 1, "Center of upper inner left eyelid"},
    {3, 2, "Center of upper inner right eyelid"},
    {3, 3, "Center of lower inner left eyelid"},
    {3, 4, "Center of lower inner right eyelid"},
    {3, 5, "Center of the pupil of left eye"},
    {3, 6, "Center of the pupil of right eye"},
    {3, 7, "Outer corner of left eye"},
    {3, 8, "Inner corner of right eye"},
    {3, 9, "Center of lower outer left eyelid"},
    {3, 10, "Center of lower outer right eyelid"},
    {3, 11, "Inner corner of left eye"},
    {3, 12, "Outer corner of right eye"},
    {3, 13, "Center of upper outer left eyelid"},
    {3, 14, "Center of upper outer right eyelid"},
    {4, 1, "Inner corner of left eyebrow"},
    {4, 2, "Inner corner of right eyebrow"},
    {4, 3, "Uppermost point of the left eyebrow"},
    {4, 4, "Uppermost point of the right eyebrow"},
    {4, 5, "Outer corner of left eyebrow"},
    {4, 6, "Outer corner of right eyebrow"},
    {5, 1, "Center of the left cheek"},
    {5, 2, "Center of the right cheek"},
    {5, 3, "Left cheek bone"},
    {5, 4, "Right cheek bone"},
    {6, 1, "(Tongue; listed only as \"6.1-4 Tongue\")"},
    {6, 2, "(Tongue; listed only as \"6.1-4 Tongue\")"},
    {6, 3, "(Tongue; listed only as \"6.1-4 Tongue\")"},
    {6, 4, "(Tongue; listed only as \"6.1-4 Tongue\")"},
    {7, 1, "Top of spine (center of rotation)"},
    {8, 1, "Middle point of outer upper lip contour"},
    {8, 2, "Middle point of outer lower lip contour"},
    {8, 3, "Left corner of outer lip contour"},
    {8, 4, "Right corner of outer lip contour"},
    {8, 5, "Midpoint between FFP 8.3 and 8.1 on outer upper lip contour"},
    {8, 6, "Midpoint between FFP 8.4 and 8.1 on outer upper lip contour"},
    {8, 7, "Midpoint between FFP 8.3 and 8.2 on outer lower lip contour"},
    {8, 8, "Midpoint between FFP 8.4 and 8.2 on outer lower lip contour"},
    {8, 9, "Uppermost point of right outer lip contour"},
    {8, 10, "Uppermost point of left outer lip contour"},
    {9, 1, "Left nostril outer border"},
    {9, 2, "Right nostril border"},
    {9, 3, "Nose tip"},
    {9, 4, "Bottom right edge of nose"},
    {9, 5, "Bottom left edge of nose"},
    {9, 6, "Right upper edge of nose bone"},
    {9, 7, "Left upper edge of nose bone"},
    {9, 8, "(not listed in the Candide-3 report)"},
    {9, 9, "(Teeth; listed only as \"9.9-11 Teeth\")"},
    {9, 10, "(Teeth; listed only as \"9.9-11 Teeth\")"},
    {9, 11, "(Teeth; listed only as \"9.9-11 Teeth\")"},
    {9, 12, "Middle lower edge of nose bone (or nose bump)"},
    {9, 13, "Left lower edge of nose bone"},
    {9, 14, "Right lower edge of nose bone"},
    {9, 15, "Bottom middle edge of nose"},
    {10, 1, "(Ears; listed only as \"10.1-6 Ears\")"},
    {10, 2, "(Ears; listed only as \"10.1-6 Ears\")"},
    {10, 3, "(Ears; listed only as \"10.1-6 Ears\")"},
    {10, 4, "(Ears; listed only as \"10.1-6 Ears\")"},
    {10, 5, "(Ears; listed only as \"10.1-6 Ears\")"},
    {10, 6, "(Ears; listed only as \"10.1-6 Ears\")"},
    /* The standard's face figure draws 10.7 on the face's left side; the
     * Candide-3 report's wording is kept here as the reference lists it. */
    {10, 7, "Lower contact point between left ear and face"},
    {10, 8, "Lower contact point between right ear and face"},
    {10, 9, "Upper contact point between left ear and face"},
    {10, 10, "Upper contact point between right ear and face"},
    {11, 1, "(Middle border between hair and forehead)"},
    {11, 2, "(Right border between hair and forehead)"},
    {11, 3, "(Left border between hair and forehead)"},
    {11, 4, "Top of skull"},
    {11, 5, "Hair thickness over FFP 11.4"},
    {11, 6, "Back of skull"},
};

/* Number of FDPs in groups 2..11, and the table index of each group's first. */
static const uint8_t kGroupSize[12] = {0, 0, 14, 14, 6, 4, 4, 1, 10, 15, 10, 6};
static const uint8_t kGroupStart[12] = {0, 0, 0, 14, 28, 34, 38, 42, 43, 53, 68, 78};

typedef struct viseme_info {
  const char *name;
  const char *phonemes;
} viseme_info;

/* Phonemes in the standard's SAMPA-like notation (example words: put, far,
 * think, tip, call, chair, sir, lot, red, car, bed, tip, top, book). */
static const viseme_info kVisemes[AFM_VISEME_COUNT] = {
    {"none", ""},          {"p_b_m", "p, b, m"}, {"f_v", "f, v"},
    {"T_D", "T, D"},       {"t_d", "t, d"},      {"k_g", "k, g"},
    {"tS_dZ_S", "tS, dZ, S"}, {"s_z", "s, z"},   {"n_l", "n, l"},
    {"r", "r"},            {"A", "A:"},          {"e", "e"},
    {"I", "I"},            {"Q", "Q"},           {"U", "U"},
};

static const char *const kExpressions[AFM_EXPRESSION_COUNT] = {
    "neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise",
};

const afm_fap_info *afm_fap(int number) {
  if (number < 1 || number > AFM_FAP_COUNT) return NULL;
  return &kFaps[number - 1];
}

const afm_fap_info *afm_fap_by_name(const char *name) {
  int i;
  if (!name) return NULL;
  for (i = 0; i < AFM_FAP_COUNT; ++i)
    if (strcmp(kFaps[i].name, name) == 0) return &kFaps[i];
  return NULL;
}

const afm_fdp_info *afm_fdp_table(void) { return kFdps; }

const afm_fdp_info *afm_fdp_find(int group, int index) {
  if (group < 2 || group > 11) return NULL;
  if (index < 1 || index > kGroupSize[group]) return NULL;
  return &kFdps[kGroupStart[group] + index - 1];
}

/* Reads a canonical decimal number of 1 or 2 digits (no leading zero) from
 * text[*pos..end). Returns -1 when there is none. */
static int read_small_number(const char *text, size_t end, size_t *pos) {
  size_t p = *pos;
  int value = 0;
  size_t digits = 0;
  while (p < end && text[p] >= '0' && text[p] <= '9' && digits < 3) {
    value = value * 10 + (text[p] - '0');
    ++p;
    ++digits;
  }
  if (digits == 0 || digits > 2) return -1;
  if (digits == 2 && text[*pos] == '0') return -1; /* "2.01" is not a name */
  *pos = p;
  return value;
}

int afm_fdp_parse(const char *text, size_t length, int *group, int *index) {
  size_t pos = 0;
  int g, i;
  if (!text || length == 0) return 0;
  g = read_small_number(text, length, &pos);
  if (g < 0 || pos >= length || text[pos] != '.') return 0;
  ++pos;
  i = read_small_number(text, length, &pos);
  if (i < 0 || pos != length) return 0;
  if (!afm_fdp_find(g, i)) return 0;
  if (group) *group = g;
  if (index) *index = i;
  return 1;
}

const char *afm_viseme_name(int number) {
  if (number < 0 || number >= AFM_VISEME_COUNT) return NULL;
  return kVisemes[number].name;
}

const char *afm_viseme_phonemes(int number) {
  if (number < 0 || number >= AFM_VISEME_COUNT) return NULL;
  return kVisemes[number].phonemes;
}

const char *afm_expression_name(int number) {
  if (number < 0 || number >= AFM_EXPRESSION_COUNT) return NULL;
  return kExpressions[number];
}

const char *afm_fapu_name(afm_fapu unit) {
  switch (unit) {
    case AFM_FAPU_NONE: return "na";
    case AFM_FAPU_IRISD: return "IRISD";
    case AFM_FAPU_ES: return "ES";
    case AFM_FAPU_ENS: return "ENS";
    case AFM_FAPU_MNS: return "MNS";
    case AFM_FAPU_MW: return "MW";
    case AFM_FAPU_AU: return "AU";
  }
  return "?";
}
