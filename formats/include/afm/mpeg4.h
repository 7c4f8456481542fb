/* MPEG-4 face animation tables: FAPs, FDPs, visemes, expressions.
 *
 * The vocabulary every part of the toolkit shares. Values follow ISO/IEC
 * 14496-2 Annex C as compiled in ../shared/reference/mpeg4-fap-table.csv and
 * mpeg4-fdp-list.csv; tests/formats/test_mpeg4_tables.cpp checks them against
 * those files.
 *
 * Frame: right-handed, +x the face's own left, +y up, +z forward (gaze).
 * All tables are static const data: no initialisation, no allocation,
 * safe from any thread. C99, no dependencies.
 */
#ifndef AFM_MPEG4_H
#define AFM_MPEG4_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* FAP units. Each distance unit is the neutral-face distance X0 / 1024. */
typedef enum afm_fapu {
  AFM_FAPU_NONE = 0, /* high-level FAPs 1 and 2 */
  AFM_FAPU_IRISD = 1, /* iris diameter IRISD0 / 1024 */
  AFM_FAPU_ES = 2,    /* eye separation ES0 / 1024 */
  AFM_FAPU_ENS = 3,   /* eye-nose separation ENS0 / 1024 */
  AFM_FAPU_MNS = 4,   /* mouth-nose separation MNS0 / 1024 */
  AFM_FAPU_MW = 5,    /* mouth width MW0 / 1024 */
  AFM_FAPU_AU = 6     /* angle unit, 1e-5 rad */
} afm_fapu;

/* How a FAP's value acts. */
typedef enum afm_fap_motion {
  AFM_MOTION_HIGH_LEVEL = 0, /* FAP 1 viseme, FAP 2 expression */
  AFM_MOTION_TRANSLATE = 1,  /* the FDP moves value x FAPU along `direction` */
  AFM_MOTION_ROTATE = 2,     /* rotation by value x AU about `direction`
                                (right-hand rule) */
  AFM_MOTION_DILATE = 3,     /* pupil dilation: grows with the value */
  AFM_MOTION_ROLL = 4        /* tongue roll: concave upward with the value */
} afm_fap_motion;

typedef struct afm_fap_info {
  uint8_t number;         /* 1..68 */
  const char *name;       /* "open_jaw" */
  afm_fapu unit;
  uint8_t bidirectional;  /* 1 = B (negative values meaningful), 0 = U */
  afm_fap_motion motion;
  int8_t direction[3];    /* unit vector of the positive motion (translate)
                             or rotation axis (rotate); 0,0,0 otherwise */
  const char *positive;   /* the table's words: "down", "left", "concave upward";
                             "na" for FAPs 1 and 2 */
  uint8_t group;          /* FAP group 1..10 */
  uint8_t fdp_group;      /* FDP the FAP moves, e.g. 2 and 1 for 2.1; */
  uint8_t fdp_index;      /*   0 and 0 when none (rotations, eyeball thrusts,
                             high level); FAP 47 (tongue_roll) moves 6.3 and
                             6.4 and lists 6.3 here */
  uint16_t quant_step;    /* quantisation step of the binary FAP stream */
} afm_fap_info;

#define AFM_FAP_COUNT 68

/* FAP `number` (1..68), or NULL if out of range. */
const afm_fap_info *afm_fap(int number);
/* FAP by name ("open_jaw"), or NULL. */
const afm_fap_info *afm_fap_by_name(const char *name);

typedef struct afm_fdp_info {
  uint8_t group;            /* 2..11 */
  uint8_t index;            /* 1..15 */
  const char *description;  /* "Bottom of the chin" */
} afm_fdp_info;

#define AFM_FDP_COUNT 84

/* The 84 FDPs in table order (2.1, 2.2, ... 11.6). */
const afm_fdp_info *afm_fdp_table(void);
/* FDP group.index, or NULL when the standard defines no such point. */
const afm_fdp_info *afm_fdp_find(int group, int index);
/* Parses "2.10" into group 2, index 10. Returns 1 on success, 0 when the text
 * is not a defined FDP name. Accepts no spaces, signs or leading zeros ("2.01");
 * `text` need not be NUL-terminated and may be NULL when length is 0. On
 * failure *group and *index are left alone; either may be NULL. */
int afm_fdp_parse(const char *text, size_t length, int *group, int *index);

#define AFM_VISEME_COUNT 15     /* 0..14, 0 = none */
#define AFM_EXPRESSION_COUNT 7  /* 0..6, 0 = neutral */

/* "none", "p_b_m", "f_v", "T_D", "t_d", "k_g", "tS_dZ_S", "s_z", "n_l", "r",
 * "A", "e", "I", "Q", "U" for 0..14, or NULL when out of range. */
const char *afm_viseme_name(int number);
/* Phonemes the viseme stands for, as in the standard: "p, b, m", "A:";
 * "" for viseme 0; NULL when out of range. */
const char *afm_viseme_phonemes(int number);
/* "neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise" for
 * 0..6, or NULL when out of range. */
const char *afm_expression_name(int number);

/* Short name of a FAP unit: "IRISD", "ES", "ENS", "MNS", "MW", "AU", "na";
 * "?" for a value outside the enum. */
const char *afm_fapu_name(afm_fapu unit);

#ifdef __cplusplus
}
#endif

#endif /* AFM_MPEG4_H */
