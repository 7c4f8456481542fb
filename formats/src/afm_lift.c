/* LIFT chunk: control points and the vertices bound to them (formats/afm.md),
 * and the expansion of a target to every vertex. */
#include <string.h>

#include "afm_internal.h"

afm_result afm_lift_decode(const uint8_t *raw, size_t size, uint64_t file_offset,
                           uint32_t vertex_count, afm_arena *arena, afm_lift **lift_out,
                           afm_diag *diag) {
  afm_reader r;
  afm_lift l, *out;
  afm_run *runs;
  uint32_t k;
  uint64_t total = 0;

  memset(&l, 0, sizeof l);
  afm_reader_init(&r, raw, size, file_offset, AFM_CHUNK_LIFT, diag);
  l.control_count = afm_read_u32(&r, "control_count");
  l.run_count = afm_read_u32(&r, "run_count");
  l.bound_count = afm_read_u32(&r, "bound_count");
  if (r.error != AFM_OK) return r.error;
  if (l.control_count == 0) return afm_fail(&r, AFM_ERR_RANGE, "control_count is 0");
  if (l.control_count > 0xFFFFFFFFu - vertex_count)
    return afm_fail(&r, AFM_ERR_RANGE, "control_count %lu: vertices and controls pass 2^32",
                    (unsigned long)l.control_count);
  /* 8 bytes per run, 16 per bound vertex: compare against the remainder. */
  if (l.run_count > afm_remaining(&r) / 8 || l.bound_count > afm_remaining(&r) / 16)
    return afm_fail(&r, AFM_ERR_TRUNCATED, "%lu runs and %lu bound vertices cannot fit",
                    (unsigned long)l.run_count, (unsigned long)l.bound_count);
  out = (afm_lift *)afm_arena_take(arena, sizeof *out);
  runs = afm_read_runs(&r, arena, l.run_count, vertex_count, "bound vertices", "vertex_count", &total);
  if (r.error != AFM_OK) return r.error;
  if (total != l.bound_count)
    return afm_fail(&r, AFM_ERR_RANGE, "runs cover %lu vertices, bound_count is %lu",
                    (unsigned long)total, (unsigned long)l.bound_count);
  l.runs = runs;
  l.c0 = afm_read_u32_array(&r, arena, l.bound_count, "c0");
  l.c1 = afm_read_u32_array(&r, arena, l.bound_count, "c1");
  l.c2 = afm_read_u32_array(&r, arena, l.bound_count, "c2");
  l.w1 = afm_read_u16_array(&r, arena, l.bound_count, "w1");
  l.w2 = afm_read_u16_array(&r, arena, l.bound_count, "w2");
  if (r.error != AFM_OK) return r.error;
  /* Values exist only when decoding (not when measuring). */
  if (l.c0 && l.c1 && l.c2 && l.w1 && l.w2) {
    for (k = 0; k < l.bound_count; ++k) {
      if (l.c0[k] >= l.control_count || l.c1[k] >= l.control_count ||
          l.c2[k] >= l.control_count)
        return afm_fail(&r, AFM_ERR_RANGE, "bound vertex %lu: control %lu, %lu or %lu >= %lu",
                        (unsigned long)k, (unsigned long)l.c0[k], (unsigned long)l.c1[k],
                        (unsigned long)l.c2[k], (unsigned long)l.control_count);
      if ((uint32_t)l.w1[k] + l.w2[k] > 32768u)
        return afm_fail(&r, AFM_ERR_RANGE, "bound vertex %lu: weights %u + %u pass 32768",
                        (unsigned long)k, (unsigned)l.w1[k], (unsigned)l.w2[k]);
    }
  }
  if (afm_remaining(&r) != 0)
    return afm_fail(&r, AFM_ERR_TRAILING_BYTES, "%lu bytes after the weights",
                    (unsigned long)afm_remaining(&r));
  if (out) *out = l;
  *lift_out = out;
  return AFM_OK;
}

afm_result afm_lift_encode(const afm_lift *l, afm_writer *w) {
  uint32_t k;
  size_t n;
  if (!l || (l->run_count && !l->runs)) return AFM_ERR_ARGUMENT;
  n = l->bound_count;
  if (n && (!l->c0 || !l->c1 || !l->c2 || !l->w1 || !l->w2)) return AFM_ERR_ARGUMENT;
  afm_write_u32(w, l->control_count);
  afm_write_u32(w, l->run_count);
  afm_write_u32(w, l->bound_count);
  for (k = 0; k < l->run_count; ++k) {
    afm_write_u32(w, l->runs[k].start);
    afm_write_u32(w, l->runs[k].length);
  }
  afm_write_u32_array(w, l->c0, n);
  afm_write_u32_array(w, l->c1, n);
  afm_write_u32_array(w, l->c2, n);
  afm_write_u16_array(w, l->w1, n);
  afm_write_u16_array(w, l->w2, n);
  return w->overflow ? AFM_ERR_BUFFER_TOO_SMALL : AFM_OK;
}

/* Whether any run of `t` covers a vertex of the lift's runs (both ascending
 * and disjoint: one merge walk). */
static int covers_bound(const afm_target *t, const afm_lift *l) {
  uint32_t i = 0, j = 0;
  while (i < t->run_count && j < l->run_count) {
    const afm_run a = t->runs[i], b = l->runs[j];
    if ((uint64_t)a.start + a.length <= b.start) {
      ++i;
    } else if ((uint64_t)b.start + b.length <= a.start) {
      ++j;
    } else {
      return 1;
    }
  }
  return 0;
}

afm_result afm_lift_check_targets(const afm_lift *l, const afm_target *targets, uint32_t count,
                                  uint64_t file_offset, afm_diag *diag) {
  uint32_t i;
  if (!l || !targets) return AFM_OK;
  for (i = 0; i < count; ++i) {
    if (targets[i].flags & AFM_TARGET_NORMALS) {
      afm_diag_set(diag, AFM_CHUNK_MTGT, file_offset,
                   "target %lu has normal deltas; a file with LIFT has none", (unsigned long)i);
      return AFM_ERR_RANGE;
    }
    if (targets[i].runs && covers_bound(&targets[i], l)) {
      afm_diag_set(diag, AFM_CHUNK_MTGT, file_offset,
                   "target %lu moves a vertex bound to control points (LIFT)", (unsigned long)i);
      return AFM_ERR_RANGE;
    }
  }
  return AFM_OK;
}

uint64_t afm_doc_entry_count(const afm_doc *doc) {
  if (!doc) return 0;
  return (uint64_t)doc->geometry.vertex_count + (doc->lift ? doc->lift->control_count : 0);
}

afm_result afm_target_expand(const afm_doc *doc, const afm_target *t, int32_t *out) {
  const uint64_t E = afm_doc_entry_count(doc);
  const afm_lift *l = doc ? doc->lift : NULL;
  uint32_t r, i, k = 0;
  if (!doc || !t || !out) return AFM_ERR_ARGUMENT;
  memset(out, 0, afm_mul_size(3 * (size_t)E, sizeof *out));
  for (r = 0; r < t->run_count; ++r)
    for (i = 0; i < t->runs[r].length; ++i, ++k) {
      const size_t e = (size_t)t->runs[r].start + i;
      if (e >= E) return AFM_ERR_RANGE; /* a doc the reader would refuse */
      /* |d| < 2^15: d * 2^15 fits. */
      out[3 * e] = (int32_t)t->dx[k] * 32768;
      out[3 * e + 1] = (int32_t)t->dy[k] * 32768;
      out[3 * e + 2] = (int32_t)t->dz[k] * 32768;
    }
  if (l) {
    /* Each bound vertex gathers its controls' deltas from out[3V...]: three
     * products of a Q15 weight (the three sum to 2^15) by an int16, so the
     * sum stays below 2^30 in magnitude and is exact. */
    const int32_t *ctrl = out + 3 * (size_t)doc->geometry.vertex_count;
    uint32_t b = 0;
    for (r = 0; r < l->run_count; ++r)
      for (i = 0; i < l->runs[r].length; ++i, ++b) {
        const size_t v = (size_t)l->runs[r].start + i;
        const int32_t w1 = l->w1[b], w2 = l->w2[b], w0 = 32768 - w1 - w2;
        const int32_t *a = ctrl + 3 * (size_t)l->c0[b], *c1 = ctrl + 3 * (size_t)l->c1[b],
                      *c2 = ctrl + 3 * (size_t)l->c2[b];
        int j;
        /* Controls hold d * 32768 exactly: the division is exact. */
        for (j = 0; j < 3; ++j)
          out[3 * v + j] = w0 * (a[j] / 32768) + w1 * (c1[j] / 32768) + w2 * (c2[j] / 32768);
      }
  }
  return AFM_OK;
}
