/* The player: memory layout, init, and the stages of a pose (afm/player.h).
 * The stages live in weights.c, blend.c, normals.c and rigid.c. */
#include <string.h>

#include "player_internal.h"

static size_t align8(size_t n) { return (n + 7u) & ~(size_t)7u; }

static int recomputes_normals(uint32_t flags) {
  return !(flags & (AFM_PLAYER_NORMAL_DELTAS | AFM_PLAYER_NO_NORMALS));
}

/* Runs of all targets and of the lift: what bounds the pose's spans. */
static uint64_t total_runs(const afm_doc *doc) {
  uint64_t n = doc->lift ? doc->lift->run_count : 0;
  uint32_t i;
  for (i = 0; i < doc->target_count; ++i) n += doc->targets[i].run_count;
  return n;
}

/* Carves the arrays out of `base` (p NULL: only measures). Returns the size,
 * or 0 when it passes size_t. */
static size_t layout(afm_player *p, uint8_t *base, const afm_doc *doc, uint32_t flags) {
  const uint64_t V = doc->geometry.vertex_count, T = doc->geometry.triangle_count,
                 N = doc->target_count, R = total_runs(doc), P = doc->geometry.part_count,
                 E = afm_doc_entry_count(doc);
  uint64_t at = align8(sizeof(afm_player));
#define TAKE(field, type, count)                                     \
  do {                                                               \
    if (p) p->field = (type *)(void *)(base + at);                   \
    at += ((uint64_t)(count) * sizeof(type) + 7u) & ~(uint64_t)7u;   \
  } while (0)
  TAKE(max_delta, int32_t, N);
  TAKE(next_target, int32_t, N);
  TAKE(weight_scratch, int32_t, 2 * N);
  TAKE(weights, afm_q12, N);
  TAKE(acc, int32_t, 3 * E);
  TAKE(moved, uint8_t, E);
  TAKE(dirty, afm_span, R + 1);
  TAKE(restore, afm_span, R + 4 * P + 1);
  TAKE(positions, int32_t, 3 * V);
  TAKE(normals, afm_q14, 3 * V);
  if (flags & AFM_PLAYER_NO_NORMALS) {
    /* positions only */
  } else if (flags & AFM_PLAYER_NORMAL_DELTAS) {
    TAKE(normal_acc, int32_t, 3 * E);
  } else {
    TAKE(ring_start, uint32_t, V + 1);
    TAKE(ring, uint32_t, 3 * T);
    TAKE(twin_next, uint32_t, V);
    TAKE(stale_flag, uint8_t, V);
    TAKE(stale, uint32_t, V);
    TAKE(normal_sum, int64_t, 3 * V);
    TAKE(face_stamp, uint32_t, T);
  }
#undef TAKE
  if (p) {
    p->restore_capacity = (uint32_t)(R + 4 * P + 1);
  }
  return at > (uint64_t)SIZE_MAX / 2 ? 0 : (size_t)at;
}

static afm_result check_doc(const afm_doc *doc) {
  if (!doc || !doc->geometry.px || !doc->geometry.parts || doc->geometry.vertex_count == 0)
    return AFM_ERR_ARGUMENT;
  /* The kernels rely on arithmetic right shifts of negative values. */
  if ((-5 >> 1) != -3) return AFM_ERR_STATE;
  if (total_runs(doc) > 0x3FFFFFFFu || afm_doc_entry_count(doc) > 0x3FFFFFFFu) return AFM_ERR_LIMIT;
  return afm_rigids_check(doc);
}

afm_result afm_player_measure(const afm_doc *doc, const afm_player_options *options,
                              size_t *bytes) {
  uint32_t flags = options ? options->flags : 0;
  afm_result r = check_doc(doc);
  if (r != AFM_OK) return r;
  if (!bytes) return AFM_ERR_ARGUMENT;
  if ((flags & AFM_PLAYER_NORMAL_DELTAS) && !(flags & AFM_PLAYER_NO_NORMALS) && !doc->geometry.nx)
    return AFM_ERR_ARGUMENT;
  *bytes = layout(NULL, NULL, doc, flags);
  return *bytes ? AFM_OK : AFM_ERR_LIMIT;
}

afm_result afm_player_init(const afm_doc *doc, const afm_player_options *options, void *buffer,
                           size_t size, afm_player **out) {
  uint32_t flags = options ? options->flags : 0;
  afm_player *p;
  size_t need;
  afm_result r = afm_player_measure(doc, options, &need);
  if (r != AFM_OK) return r;
  if (!buffer || !out || ((uintptr_t)buffer & 7u)) return AFM_ERR_ARGUMENT;
  if (size < need) return AFM_ERR_BUFFER_TOO_SMALL;
  if (flags & AFM_PLAYER_NO_NORMALS) flags &= ~(uint32_t)AFM_PLAYER_NORMAL_DELTAS;
  memset(buffer, 0, sizeof(afm_player));
  p = (afm_player *)buffer;
  p->doc = doc;
  p->flags = flags;
  p->vertex_count = doc->geometry.vertex_count;
  p->entry_count = (uint32_t)afm_doc_entry_count(doc);
  p->target_count = doc->target_count;
  p->triangle_count = doc->geometry.triangle_count;
  layout(p, (uint8_t *)buffer, doc, flags);
  afm_weights_init(p);
  memset(p->moved, 0, p->entry_count); /* the caller's buffer may hold anything */
  if (recomputes_normals(flags)) afm_normals_init(p);
  afm_neutral_outputs(p, 0, p->vertex_count);
  afm_blend_reset(p, kWeightBits);
  *out = p;
  return afm_player_pose(p, NULL, NULL, 0);
}

afm_result afm_player_pose(afm_player *p, const afm_fap_state *a, const afm_fap_state *b,
                           afm_q16 t) {
  static const afm_fap_state kNeutral; /* zero-initialised constant, not mutable state */
  int64_t bound;
  int shift;
  if (!p || t < 0 || t > AFM_Q16_ONE) return AFM_ERR_ARGUMENT;
  if (!a) a = &kNeutral;
  if (!b) b = a, t = 0;
  memset(&p->info, 0, sizeof p->info);

  bound = afm_pose_weights(p, a, b, t);
  /* The accumulator bound: |neutral << shift| + sum |w| * max|d| / 2^(12 - shift)
   * must stay below 2^31. The neutral term is below 2^15 << shift. Shift 12
   * keeps full weight precision and only absurd poses need less. */
  shift = kWeightBits;
  while (shift > 0 && bound + ((int64_t)1 << (15 + shift)) >= ((int64_t)1 << 31)) {
    --shift;
    bound >>= 1;
  }
  p->info.weight_shift = (uint32_t)(kWeightBits - shift);

  /* Undo the last pose where it changed anything. */
  afm_blend_restore(p);
  if (shift != p->acc_shift) afm_blend_reset(p, shift);
  afm_restore_outputs(p);
  if (recomputes_normals(p->flags)) afm_normals_restore(p);

  afm_blend_targets(p, shift);
  afm_blend_output(p, shift);
  if (recomputes_normals(p->flags) && p->dirty_count) afm_normals_recompute(p);
  afm_rigids_apply(p, a, b, t);
  return AFM_OK;
}

const int32_t *afm_player_positions(const afm_player *p) { return p ? p->positions : NULL; }
const afm_q14 *afm_player_normals(const afm_player *p) { return p ? p->normals : NULL; }
const afm_pose_info *afm_player_info(const afm_player *p) { return p ? &p->info : NULL; }
const afm_q12 *afm_player_weights(const afm_player *p) { return p ? p->weights : NULL; }
const afm_rigid_transform *afm_player_head_transform(const afm_player *p) {
  return p ? &p->head : NULL;
}
