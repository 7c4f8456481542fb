/* The blend kernel: positions = neutral + sum over targets of weight * delta.
 *
 * Data layout (all from the AFM's MTGT chunk, untouched): per target, runs of
 * consecutive vertices and planar int16 deltas (x[], y[], z[]). Accumulators
 * are planar int32 arrays, one per coordinate, so one run of one target is a
 * contiguous multiply-add of int16 by a constant into int32 (pmaddwd/pmullw-
 * class instructions on x86, SMLABB on ARMv5TE).
 *
 * Q formats and widths (per coordinate):
 *   delta d        int16, position quanta (normal deltas: Q14)
 *   weight w       Q12 within [-2^15, 2^15), pre-shifted by (12 - shift)
 *   product w * d  int32, |w * d| < 2^30
 *   accumulator    int32 in Q(shift): neutral << shift plus the products
 *   output         round(acc / 2^shift), halves up: one rounding per pose
 * Overflow: the pose picks shift (12 normally) so that |neutral << shift| +
 * sum over active targets of |w| * max|d| < 2^31 (see afm_player_pose); no
 * intermediate can then overflow. Rounding happens once, at the output.
 *
 * Control points (the AFM's LIFT chunk): accumulator entries V..V+C-1 hold
 * the controls, neutral 0, blended like vertices. A bound vertex then takes
 *   acc[v] = neutral << shift + round(sum_i w_i * acc[V + c_i] / 2^15)
 *   w_i     Q15, >= 0, summing to 2^15
 *   product int64: |w_i * acc| < 2^15 * 2^31 = 2^46, the sum below 2^47
 *   result  a convex blend of control accumulators, so within the pose's
 *           bound like any vertex's (+ 1/2 of rounding: the bound keeps 2^shift
 *           of slack); rounded to Q(shift), then once more at the output
 * A pose with no control moved skips the lift.
 *
 * Between poses the accumulators hold neutral << acc_shift everywhere except
 * the spans the last pose moved (`dirty`): the next pose resets those first,
 * so a pose costs O(updates + moved vertices), not O(vertices). */
#include <string.h>

#include "player_internal.h"

/* Writes neutral << shift into the accumulators of entries [s, e):
 * vertices take their neutral position, controls 0. */
static void reset_span(afm_player *p, uint32_t s, uint32_t e, int shift) {
  const afm_geometry *g = &p->doc->geometry;
  const uint32_t E = p->entry_count, V = p->vertex_count, ve = e < V ? e : V;
  int32_t *ax = p->acc, *ay = p->acc + E, *az = p->acc + 2 * (size_t)E;
  uint32_t v;
  for (v = s; v < ve; ++v) ax[v] = (int32_t)g->px[v] * ((int32_t)1 << shift);
  for (v = s; v < ve; ++v) ay[v] = (int32_t)g->py[v] * ((int32_t)1 << shift);
  for (v = s; v < ve; ++v) az[v] = (int32_t)g->pz[v] * ((int32_t)1 << shift);
  for (v = s > V ? s : V; v < e; ++v) ax[v] = ay[v] = az[v] = 0;
  if (p->normal_acc) {
    int32_t *nx = p->normal_acc, *ny = nx + E, *nz = nx + 2 * (size_t)E;
    for (v = s; v < ve; ++v) nx[v] = (int32_t)g->nx[v] * ((int32_t)1 << shift);
    for (v = s; v < ve; ++v) ny[v] = (int32_t)g->ny[v] * ((int32_t)1 << shift);
    for (v = s; v < ve; ++v) nz[v] = (int32_t)g->nz[v] * ((int32_t)1 << shift);
    for (v = s > V ? s : V; v < e; ++v) nx[v] = ny[v] = nz[v] = 0;
  }
}

void afm_blend_reset(afm_player *p, int shift) {
  reset_span(p, 0, p->entry_count, shift);
  p->acc_shift = shift;
  p->dirty_count = 0;
}

void afm_blend_restore(afm_player *p) {
  uint32_t i;
  for (i = 0; i < p->dirty_count; ++i) reset_span(p, p->dirty[i].start, p->dirty[i].end, p->acc_shift);
  p->dirty_count = 0;
}

/* acc[i] += w * d[i]: the kernel. A 16 x 16 -> 32-bit multiply-add:
 * |w| < 2^15, |d| < 2^15, so |w * d| < 2^30. Written so that compilers see
 * the widening multiply (pmullw/pmulhw on x86, SMLABB on ARMv5TE). */
static void axpy16(int32_t *restrict acc, const int16_t *restrict d, int16_t w, uint32_t n) {
  uint32_t i;
  for (i = 0; i < n; ++i) acc[i] += (int32_t)w * (int32_t)d[i];
}

static void blend_runs(int32_t *acc, uint32_t V, const afm_target *t, const int16_t *dx,
                       const int16_t *dy, const int16_t *dz, int16_t w) {
  uint32_t r, k = 0;
  for (r = 0; r < t->run_count; ++r) {
    uint32_t s = t->runs[r].start, n = t->runs[r].length;
    axpy16(acc + s, dx + k, w, n);
    axpy16(acc + V + s, dy + k, w, n);
    axpy16(acc + 2 * (size_t)V + s, dz + k, w, n);
    k += n;
  }
}

/* Bound vertices from their controls (see the header comment for widths). */
static void lift_bound(afm_player *p, int shift) {
  const afm_lift *l = p->doc->lift;
  const afm_geometry *g = &p->doc->geometry;
  const uint32_t E = p->entry_count, V = p->vertex_count;
  const int32_t *cx = p->acc + V, *cy = p->acc + E + V, *cz = p->acc + 2 * (size_t)E + V;
  int32_t *ax = p->acc, *ay = p->acc + E, *az = p->acc + 2 * (size_t)E;
  uint32_t r, i, b = 0;
  for (r = 0; r < l->run_count; ++r)
    for (i = 0; i < l->runs[r].length; ++i, ++b) {
      const uint32_t v = l->runs[r].start + i, c0 = l->c0[b], c1 = l->c1[b], c2 = l->c2[b];
      const int64_t w1 = l->w1[b], w2 = l->w2[b], w0 = 32768 - w1 - w2;
      ax[v] = (int32_t)g->px[v] * ((int32_t)1 << shift) +
              (int32_t)afm_round_shift64(w0 * cx[c0] + w1 * cx[c1] + w2 * cx[c2], 15);
      ay[v] = (int32_t)g->py[v] * ((int32_t)1 << shift) +
              (int32_t)afm_round_shift64(w0 * cy[c0] + w1 * cy[c1] + w2 * cy[c2], 15);
      az[v] = (int32_t)g->pz[v] * ((int32_t)1 << shift) +
              (int32_t)afm_round_shift64(w0 * cz[c0] + w1 * cz[c1] + w2 * cz[c2], 15);
    }
}

void afm_blend_targets(afm_player *p, int shift) {
  const afm_doc *doc = p->doc;
  const uint32_t E = p->entry_count, V = p->vertex_count;
  uint32_t i, r, lo = E, hi = 0;
  for (i = 0; i < p->target_count; ++i) {
    const afm_target *t = &doc->targets[i];
    int32_t w = p->weights[i];
    if (!w) continue;
    if (shift < kWeightBits) w = afm_round_shift32(w, kWeightBits - shift);
    blend_runs(p->acc, E, t, t->dx, t->dy, t->dz, (int16_t)w);
    if (p->normal_acc && t->nx)
      blend_runs(p->normal_acc, E, t, t->nx, t->ny, t->nz, (int16_t)w);
    /* Mark the moved entries; spans come from one scan below. */
    for (r = 0; r < t->run_count; ++r) {
      uint32_t s = t->runs[r].start, e = s + t->runs[r].length;
      memset(p->moved + s, 1, t->runs[r].length);
      if (s < lo) lo = s;
      if (e > hi) hi = e;
    }
  }
  /* A control moved: every bound vertex follows (the reader keeps bound
   * vertices off the targets' runs, so nothing above wrote them). */
  if (doc->lift && hi > V) {
    const afm_lift *l = doc->lift;
    lift_bound(p, shift);
    for (r = 0; r < l->run_count; ++r) {
      uint32_t s = l->runs[r].start, e = s + l->runs[r].length;
      memset(p->moved + s, 1, l->runs[r].length);
      if (s < lo) lo = s;
      if (e > hi) hi = e;
    }
  }
  /* The marked vertices as sorted, disjoint spans; marks cleared on the way. */
  p->dirty_count = 0;
  while (lo < hi) {
    const uint8_t *start = (const uint8_t *)memchr(p->moved + lo, 1, hi - lo), *end;
    if (!start) break;
    lo = (uint32_t)(start - p->moved);
    end = (const uint8_t *)memchr(start, 0, hi - lo);
    p->dirty[p->dirty_count].start = lo;
    lo = end ? (uint32_t)(end - p->moved) : hi;
    p->dirty[p->dirty_count].end = lo;
    memset(p->moved + p->dirty[p->dirty_count].start, 0, lo - p->dirty[p->dirty_count].start);
    p->dirty_count++;
  }
}

void afm_blend_output(afm_player *p, int shift) {
  const uint32_t V = p->vertex_count, E = p->entry_count;
  const int32_t *ax = p->acc, *ay = p->acc + E, *az = p->acc + 2 * (size_t)E;
  uint32_t i, v;
  for (i = 0; i < p->dirty_count; ++i) {
    afm_span s = p->dirty[i];
    if (s.start >= V) break; /* controls: no output of their own */
    if (s.end > V) s.end = V;
    for (v = s.start; v < s.end; ++v) {
      int32_t *o = p->positions + 3 * (size_t)v;
      /* |acc| < 2^31 - 2^(shift-1) by the pose's bound: the rounding add fits. */
      o[0] = shift ? afm_round_shift32(ax[v], shift) : ax[v];
      o[1] = shift ? afm_round_shift32(ay[v], shift) : ay[v];
      o[2] = shift ? afm_round_shift32(az[v], shift) : az[v];
    }
    if (p->normal_acc) {
      const int32_t *nx = p->normal_acc, *ny = nx + E, *nz = nx + 2 * (size_t)E;
      for (v = s.start; v < s.end; ++v) afm_normalize_q14(nx[v], ny[v], nz[v], p->normals + 3 * (size_t)v);
    }
    afm_add_restore_span(p, s.start, s.end);
  }
}

void afm_add_restore_span(afm_player *p, uint32_t start, uint32_t end) {
  if (p->restore_count < p->restore_capacity) {
    p->restore[p->restore_count].start = start;
    p->restore[p->restore_count].end = end;
    p->restore_count++;
  } else {
    /* Cannot happen with the capacity init reserves; stay correct anyway by
     * widening the last span. */
    afm_span *last = &p->restore[p->restore_capacity - 1];
    if (start < last->start) last->start = start;
    if (end > last->end) last->end = end;
  }
}

void afm_neutral_outputs(afm_player *p, uint32_t start, uint32_t end) {
  const afm_geometry *g = &p->doc->geometry;
  uint32_t v;
  for (v = start; v < end; ++v) {
    int32_t *o = p->positions + 3 * (size_t)v;
    afm_q14 *n = p->normals + 3 * (size_t)v;
    o[0] = g->px[v], o[1] = g->py[v], o[2] = g->pz[v];
    if (g->nx)
      n[0] = g->nx[v], n[1] = g->ny[v], n[2] = g->nz[v];
    else
      n[0] = n[1] = 0, n[2] = AFM_Q14_ONE;
  }
}

void afm_restore_outputs(afm_player *p) {
  uint32_t i;
  for (i = 0; i < p->restore_count; ++i) afm_neutral_outputs(p, p->restore[i].start, p->restore[i].end);
  p->restore_count = 0;
}
