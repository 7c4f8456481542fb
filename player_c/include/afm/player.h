/* The player: FAP semantics, morph blending and rigid parts, in fixed point.
 *
 * C99, no dependencies, no globals, no floating point, no allocation: the
 * caller measures, provides one buffer, and nothing is allocated per frame.
 *
 *   afm_doc (formats/include/afm/format.h)      the model, read once
 *   afm_fap_frame (afm/fap_stream.h)            what a stream sends
 *     -> afm_fap_state_apply                    what is in effect (values persist)
 *     -> afm_fap_cursor                         states around a render time
 *     -> afm_player_pose                        positions and normals
 *
 * Semantics (formats/fap.md has the details):
 *   - A FAP not sent in a frame keeps its last value (0 until first sent).
 *   - Low-level FAP f with value v moves its morph target by weight
 *     v / reference; a negative v uses the FAP's negative-side target when the
 *     AFM has one, else extrapolates the positive one. A side with in-betweens
 *     (several targets, formats/afm.md) blends the two around v piecewise
 *     linearly, the last segment extrapolated past the farthest. A
 *     combination target (AFM 1.4) takes the weight of the target it follows,
 *     capped by its gate FAP's value / gate reference, never below 0.
 *   - FAP 1: viseme_select1 at blend/63 plus viseme_select2 at (63 - blend)/63.
 *   - FAP 2: expression_select1 at intensity1/63 plus expression_select2 at
 *     intensity2/63. init_face and the def flags are decoded and kept; they do
 *     not change blending.
 *   - Control points (the AFM's LIFT chunk): targets move the controls, and
 *     each bound vertex follows the Q15-weighted blend of its three controls
 *     (formats/fap.md, "Control points").
 *   - Rigid parts (eyeballs, jaw, head) turn about their pivots as the AFM's
 *     RIGD chunk says, after the morph targets: jaw and eyes first, then the
 *     head. Rotations compose as yaw (local y) after pitch (local x) after
 *     roll (local z).
 *   - Mirroring, off by default (see afm_fap_state_apply).
 */
#ifndef AFM_PLAYER_H
#define AFM_PLAYER_H

#include <stddef.h>
#include <stdint.h>

#include "afm/fap_stream.h"
#include "afm/fixed.h"
#include "afm/format.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- FAP state ----------------------------------------------------------- */

typedef struct afm_fap_state {
  int32_t value[AFM_FAP_COUNT + 1]; /* FAP 3..68 in FAP units; [0..2] unused */
  afm_viseme_value viseme;          /* select 0 = none */
  afm_expression_value expression;  /* select 0 = neutral */
} afm_fap_state;

/* Mirroring flags: when a frame sends one FAP of a pair and not the other,
 * the other takes the same value (every pair's positive directions are
 * mirror images, so equal values are a symmetric motion).
 *
 * Off by default: the standard says an unsent FAP keeps its value, and our
 * morph targets already move the whole lip region each muscle moves, so
 * copying inner-lip values onto outer-lip FAPs would move the lips twice.
 * Turn them on for streams from one-sided trackers. */
#define AFM_MIRROR_LEFT_RIGHT 0x1u  /* 6/7, 8/9, ... 65/66, 67/68 */
#define AFM_MIRROR_INNER_OUTER 0x2u /* 4..13 <-> 51..60 */

/* The neutral state: every value 0, no viseme, no expression. */
void afm_fap_state_reset(afm_fap_state *state);
/* Applies one frame: sent values replace the state's, then mirroring. */
void afm_fap_state_apply(afm_fap_state *state, const afm_fap_frame *frame, uint32_t mirror_flags);

/* ---- playing a stream at its rate ---------------------------------------- */

/* Walks the frames of a parsed stream in time. The time of frame i is
 * (number_i - number_0) / fps; no frame is dropped: every frame between two
 * render times is applied, so a value sent only there still persists. */
typedef struct afm_fap_cursor {
  const afm_fap_frame *frames; /* borrowed */
  uint32_t count;
  uint32_t fps_num, fps_den;
  uint32_t mirror_flags;
  uint32_t next;               /* private: next frame to apply */
  afm_fap_state before;        /* state at the last frame at or before the time */
  afm_fap_state after;         /* state at the frame following it */
  uint64_t before_us, after_us;
  int has_after;               /* private */
} afm_fap_cursor;

/* fps is fps_num / fps_den (afm_fap_header); both > 0. */
afm_result afm_fap_cursor_init(afm_fap_cursor *cursor, const afm_fap_frame *frames,
                               uint32_t count, uint32_t fps_num, uint32_t fps_den,
                               uint32_t mirror_flags);
/* Moves to `time_us` from the first frame (a time before the previous call
 * rewinds and replays). Gives the states on either side and the blend factor
 * for afm_player_pose; past the last frame, the last state with t = 0. */
afm_result afm_fap_cursor_seek(afm_fap_cursor *cursor, uint64_t time_us,
                               const afm_fap_state **a, const afm_fap_state **b, afm_q16 *t);
/* Microseconds from frame 0 to the last frame. */
uint64_t afm_fap_cursor_duration_us(const afm_fap_cursor *cursor);

/* ---- the player ------------------------------------------------------------ */

#define AFM_PLAYER_NORMAL_DELTAS 0x1u /* blend the AFM's normal deltas (Q14) instead
                                         of recomputing normals from positions */
#define AFM_PLAYER_NO_NORMALS 0x4u    /* positions only: normals stay the neutral ones
                                         (for renderers that derive their own) */
#define AFM_PLAYER_HEAD_MATRIX 0x2u   /* leave the head's rigid motion out of the vertices;
                                         a renderer applies afm_player_head_transform as
                                         its model matrix (saves a pass over every vertex) */

/* A rigid transform in the AFM's grid: p' = R p + t, R in Q14 (row-major),
 * t in position quanta. Normals turn by R alone. */
typedef struct afm_rigid_transform {
  afm_q14 rotation[9];
  int32_t translation[3];
} afm_rigid_transform;

/* Zeroed: the defaults (normals recomputed; see formats/fap.md "Normals"). */
typedef struct afm_player_options {
  uint32_t flags; /* AFM_PLAYER_* */
} afm_player_options;

typedef struct afm_player afm_player; /* lives in the caller's buffer */

/* What the last pose did. */
typedef struct afm_pose_info {
  uint32_t active_targets;  /* morph targets with a nonzero weight */
  uint32_t updates;         /* vertex-target updates (sum of their delta counts) */
  uint32_t clamped_weights; /* weights beyond [-8, 8) that were clamped */
  uint32_t weight_shift;    /* > 0 when weights were scaled by 2^-shift to keep the
                               accumulators within 32 bits (never with sane models) */
} afm_pose_info;

/* Bytes afm_player_init needs for this model. `doc` is the decoded AFM. */
afm_result afm_player_measure(const afm_doc *doc, const afm_player_options *options,
                              size_t *bytes);
/* Builds a player in buffer[0..size) (8-byte aligned). It reads `doc`, which
 * must outlive it, and poses the neutral face. No allocation. */
afm_result afm_player_init(const afm_doc *doc, const afm_player_options *options, void *buffer,
                           size_t size, afm_player **player);

/* Poses the face for state a blended toward b by t (Q16, 0 = a, 65536 = b;
 * b may be NULL for a alone). No allocation; O(vertices + updates). */
afm_result afm_player_pose(afm_player *player, const afm_fap_state *a, const afm_fap_state *b,
                           afm_q16 t);

/* Outputs of the last pose, valid until the next one. Positions: [3V] int32
 * quanta on the AFM grid (model = origin + quanta * step), x y z per vertex;
 * rigid motion can leave the int16 range of the neutral mesh. Normals: [3V]
 * Q14 unit vectors. */
const int32_t *afm_player_positions(const afm_player *player);
const afm_q14 *afm_player_normals(const afm_player *player);
const afm_pose_info *afm_player_info(const afm_player *player);

/* Weight of each morph target in the last pose, Q12, in doc->targets order. */
const afm_q12 *afm_player_weights(const afm_player *player);

/* The head's transform in the last pose: what AFM_PLAYER_HEAD_MATRIX leaves
 * to the renderer (identity when the AFM has no head rigid). Without that
 * flag the vertices already include it. */
const afm_rigid_transform *afm_player_head_transform(const afm_player *player);

/* The transform of one rigid part (an entry of doc->rigids) for state a
 * blended toward b by t, exactly as afm_player_pose moves that part's
 * vertices: the exact identity when none of its degrees of freedom moves.
 * The jaw's and eyes' transforms act in the neutral frame; the head's acts
 * after them (p' = H (E p)). For exporters that keep parts rigid and animate
 * transforms instead of vertices. a NULL is the neutral state; b NULL is a
 * alone. Use it on a model afm_player_init accepted (it checks the rigids'
 * axes and pivots). AFM_ERR_ARGUMENT for a NULL rigid or out, or t outside
 * [0, 65536]. No allocation. */
afm_result afm_rigid_pose(const afm_rigid *rigid, const afm_fap_state *a, const afm_fap_state *b,
                          afm_q16 t, afm_rigid_transform *out);

#ifdef __cplusplus
}
#endif

#endif /* AFM_PLAYER_H */
