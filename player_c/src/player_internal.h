/* The player's state and the stages of a pose, shared by the player's source
 * files (not a public header):
 *   weights.c  FAP state -> morph target weights (Q12)
 *   blend.c    the blend kernel: spans, accumulators, output positions
 *   normals.c  seam groups, vertex rings, normal recomputation
 *   rigid.c    eyeballs, jaw and head
 *   player.c   memory layout, init, pose, accessors */
#ifndef AFM_PLAYER_INTERNAL_H
#define AFM_PLAYER_INTERNAL_H

#include "afm/player.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A half-open vertex range [start, end). */
typedef struct afm_span {
  uint32_t start, end;
} afm_span;

enum { kWeightBits = 12 }; /* weights are Q12 */

struct afm_player {
  const afm_doc *doc;
  uint32_t flags; /* AFM_PLAYER_* */
  uint32_t vertex_count, target_count, triangle_count;

  /* weights.c: target lookup (index into doc->targets, or -1). A FAP side's
   * targets form a chain from the reference nearest zero outward. */
  int32_t fap_positive[AFM_FAP_COUNT + 1], fap_negative[AFM_FAP_COUNT + 1];
  int32_t *next_target;    /* [targets] the same FAP side's next farther target, or -1;
                              for a combination, the FAP target it follows */
  int32_t viseme[AFM_VISEME_COUNT], expression[AFM_EXPRESSION_COUNT];
  int32_t *max_delta;      /* [targets] largest |delta| component (quanta or Q14) */
  int32_t *weight_scratch; /* [2 targets] */
  afm_q12 *weights;        /* [targets] */

  /* blend.c. Accumulators hold entries: the V vertices, then the AFM's
   * C control points (LIFT; E = V + C), whose neutral value is 0. Between
   * poses, acc == neutral << acc_shift everywhere but in the spans `dirty`,
   * which the next pose restores first. */
  uint32_t entry_count; /* E */
  int acc_shift;
  int32_t *acc;        /* [3E] planar: x[E], y[E], z[E] */
  int32_t *normal_acc; /* [3E] planar, AFM_PLAYER_NORMAL_DELTAS only */
  uint8_t *moved;        /* [E] marks of this pose's morphed entries; all 0 between poses */
  afm_span *dirty;       /* [all runs + lift runs + 1] disjoint entry spans the pose
                            moved, ascending (may reach past V: controls) */
  uint32_t dirty_count;

  /* Outputs, and what the last pose changed in them: the spans in
   * `restore` (morphed vertices and rigid parts) and the `stale` normals. */
  int32_t *positions; /* [3V] interleaved quanta */
  afm_q14 *normals;   /* [3V] interleaved Q14 */
  afm_span *restore;  /* [all runs + lift runs + 4 P + 1] */
  uint32_t restore_count, restore_capacity;

  /* normals.c (recomputation mode). */
  uint32_t *ring_start;  /* [V + 1] CSR: triangles around each vertex */
  uint32_t *ring;        /* [3T] */
  uint32_t *twin_next;   /* [V] circular list of a vertex's seam group */
  uint8_t *stale_flag;   /* [V] */
  uint32_t *stale;       /* [V] vertices whose normal the last pose recomputed */
  uint32_t stale_count;
  int64_t *normal_sum;   /* [3V] area-weighted sums of stale vertices */
  uint32_t *face_stamp;  /* [T] pose number when the face's normal was added */
  uint32_t pose_number;

  afm_pose_info info;
  afm_rigid_transform head; /* the head's transform in the last pose */
};

/* weights.c: Q12 weights of the pose into p->weights; returns the sum over
 * targets of |weight| * max|delta| (the accumulator bound, Q12 units). */
int64_t afm_pose_weights(afm_player *p, const afm_fap_state *a, const afm_fap_state *b, afm_q16 t);
void afm_weights_init(afm_player *p);
int32_t afm_lerp_value(int32_t a, int32_t b, afm_q16 t);

/* blend.c */
void afm_blend_reset(afm_player *p, int shift);
void afm_blend_restore(afm_player *p);
void afm_blend_targets(afm_player *p, int shift);
void afm_blend_output(afm_player *p, int shift);
void afm_neutral_outputs(afm_player *p, uint32_t start, uint32_t end);
void afm_restore_outputs(afm_player *p);
void afm_add_restore_span(afm_player *p, uint32_t start, uint32_t end);

/* normals.c */
void afm_normals_init(afm_player *p);
void afm_normals_recompute(afm_player *p);
void afm_normals_restore(afm_player *p);
void afm_normalize_q14(int64_t x, int64_t y, int64_t z, afm_q14 out[3]);

/* rigid.c */
afm_result afm_rigids_check(const afm_doc *doc);
void afm_rigids_apply(afm_player *p, const afm_fap_state *a, const afm_fap_state *b, afm_q16 t);

#ifdef __cplusplus
}
#endif

#endif /* AFM_PLAYER_INTERNAL_H */
