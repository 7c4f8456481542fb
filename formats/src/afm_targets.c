/* MTGT chunk: sparse quantised morph targets (formats/afm.md). */
#include <stdio.h>
#include <string.h>

#include "afm_internal.h"

static int number_valid(uint8_t kind, uint8_t number) {
  switch (kind) {
    case AFM_TARGET_FAP: return number >= 3 && number <= 68;
    case AFM_TARGET_VISEME: return number >= 1 && number <= 14;
    case AFM_TARGET_EXPRESSION: return number >= 1 && number <= 6;
    case AFM_TARGET_COMBINATION: return number >= 3 && number <= 68;
    default: return 0;
  }
}

static const char *kind_text(uint8_t kind) {
  switch (kind) {
    case AFM_TARGET_FAP: return "FAP";
    case AFM_TARGET_VISEME: return "viseme";
    case AFM_TARGET_EXPRESSION: return "expression";
    case AFM_TARGET_COMBINATION: return "combination of FAP";
    default: return "?";
  }
}

afm_result afm_targets_decode_at(const uint8_t *raw, size_t size, uint64_t file_offset,
                                 uint32_t vertex_count, uint32_t control_count, afm_arena *arena,
                                 uint32_t *count_out,
                                 afm_target **targets_out, afm_diag *diag) {
  afm_reader r;
  afm_target *targets;
  uint32_t count, i, j;

  afm_reader_init(&r, raw, size, file_offset, AFM_CHUNK_MTGT, diag);
  count = afm_read_u32(&r, "target_count");
  if (r.error != AFM_OK) return r.error;
  if (count > afm_remaining(&r) / 16)
    return afm_fail(&r, AFM_ERR_TRUNCATED, "target_count %lu cannot fit in %lu bytes",
                    (unsigned long)count, (unsigned long)afm_remaining(&r));
  targets = (afm_target *)afm_arena_take(arena, afm_mul_size(count, sizeof *targets));
  for (i = 0; i < count; ++i) {
    afm_target t;
    afm_run *runs;
    uint64_t total = 0;
    memset(&t, 0, sizeof t);
    t.kind = afm_read_u8(&r, "target.kind");
    t.number = afm_read_u8(&r, "target.number");
    t.flags = afm_read_u8(&r, "target.flags");
    if (afm_read_u8(&r, "target.reserved") != 0 && r.error == AFM_OK)
      return afm_fail(&r, AFM_ERR_RANGE, "target %lu: reserved byte not zero", (unsigned long)i);
    t.reference = afm_read_i32(&r, "target.reference");
    t.run_count = afm_read_u32(&r, "target.run_count");
    t.delta_count = afm_read_u32(&r, "target.delta_count");
    if (r.error != AFM_OK) return r.error;
    if (!number_valid(t.kind, t.number))
      return afm_fail(&r, AFM_ERR_RANGE, "target %lu: %s %u is not a valid target",
                      (unsigned long)i, kind_text(t.kind), (unsigned)t.number);
    if (t.flags & ~(uint8_t)AFM_TARGET_NORMALS)
      return afm_fail(&r, AFM_ERR_RANGE, "target %lu: unknown flags 0x%x", (unsigned long)i,
                      (unsigned)t.flags);
    if (t.kind == AFM_TARGET_COMBINATION) {
      /* The gate (since 1.4): u8 gate, u8 0, u16 0, i32 gate_reference. */
      uint32_t reserved;
      t.gate = afm_read_u8(&r, "target.gate");
      reserved = afm_read_u8(&r, "target.gate_reserved");
      reserved |= afm_read_u16(&r, "target.gate_reserved");
      t.gate_reference = afm_read_i32(&r, "target.gate_reference");
      if (r.error != AFM_OK) return r.error;
      if (reserved != 0)
        return afm_fail(&r, AFM_ERR_RANGE, "target %lu: gate's reserved bytes not zero", (unsigned long)i);
      if (t.gate < 3 || t.gate > 68 || t.gate == t.number || t.gate_reference == 0)
        return afm_fail(&r, AFM_ERR_RANGE, "target %lu (combination of FAP %u): gate FAP %u at %ld",
                        (unsigned long)i, (unsigned)t.number, (unsigned)t.gate, (long)t.gate_reference);
    }
    if (t.reference == 0 || (t.kind != AFM_TARGET_FAP && t.kind != AFM_TARGET_COMBINATION && t.reference < 0))
      return afm_fail(&r, AFM_ERR_RANGE, "target %lu (%s %u): reference value %ld",
                      (unsigned long)i, kind_text(t.kind), (unsigned)t.number, (long)t.reference);
    /* A FAP side may have several targets (in-betweens, version 1.2), each
     * at its own reference; a viseme or an expression has one. */
    for (j = 0; targets && j < i; ++j)
      if (targets[j].kind == t.kind && targets[j].number == t.number &&
          ((t.kind != AFM_TARGET_FAP && t.kind != AFM_TARGET_COMBINATION) ||
           targets[j].reference == t.reference))
        return afm_fail(&r, AFM_ERR_RANGE, "target %lu: %s %u (reference %ld) appears twice",
                        (unsigned long)i, kind_text(t.kind), (unsigned)t.number,
                        (long)t.reference);
    if (t.run_count > afm_remaining(&r) / 8 || t.delta_count > afm_remaining(&r) / 6)
      return afm_fail(&r, AFM_ERR_TRUNCATED, "target %lu: %lu runs and %lu deltas cannot fit",
                      (unsigned long)i, (unsigned long)t.run_count,
                      (unsigned long)t.delta_count);
    {
      char what[48];
      sprintf(what, "target %lu (%s %u)", (unsigned long)i, kind_text(t.kind), (unsigned)t.number);
      runs = afm_read_runs(&r, arena, t.run_count, vertex_count + control_count, what,
                           control_count ? "vertex_count + control_count" : "vertex_count", &total);
      if (r.error != AFM_OK) return r.error;
    }
    if (total != t.delta_count)
      return afm_fail(&r, AFM_ERR_RANGE, "target %lu: runs cover %lu vertices, delta_count is %lu",
                      (unsigned long)i, (unsigned long)total, (unsigned long)t.delta_count);
    t.runs = runs;
    t.dx = afm_read_i16_array(&r, arena, t.delta_count, "deltas.x");
    t.dy = afm_read_i16_array(&r, arena, t.delta_count, "deltas.y");
    t.dz = afm_read_i16_array(&r, arena, t.delta_count, "deltas.z");
    if (t.flags & AFM_TARGET_NORMALS) {
      t.nx = afm_read_i16_array(&r, arena, t.delta_count, "normal_deltas.x");
      t.ny = afm_read_i16_array(&r, arena, t.delta_count, "normal_deltas.y");
      t.nz = afm_read_i16_array(&r, arena, t.delta_count, "normal_deltas.z");
    }
    if (r.error != AFM_OK) return r.error;
    if (targets) targets[i] = t;
  }
  if (afm_remaining(&r) != 0)
    return afm_fail(&r, AFM_ERR_TRAILING_BYTES, "%lu bytes after the last target",
                    (unsigned long)afm_remaining(&r));
  /* A combination follows the FAP target at its number and reference. On
   * the measuring pass (no targets kept) this check waits for the read. */
  for (i = 0; targets && i < count; ++i) {
    int found = 0;
    if (targets[i].kind != AFM_TARGET_COMBINATION) continue;
    for (j = 0; j < count && !found; ++j)
      found = targets[j].kind == AFM_TARGET_FAP && targets[j].number == targets[i].number &&
              targets[j].reference == targets[i].reference;
    if (!found)
      return afm_fail(&r, AFM_ERR_RANGE,
                      "target %lu (combination of FAP %u at %ld): no FAP target at that reference",
                      (unsigned long)i, (unsigned)targets[i].number, (long)targets[i].reference);
  }
  *count_out = count;
  *targets_out = targets;
  return AFM_OK;
}

afm_result afm_targets_decode(const uint8_t *raw, size_t size, uint32_t vertex_count,
                              void *buffer, size_t buffer_size, size_t *bytes,
                              uint32_t *target_count, afm_target **targets, afm_diag *diag) {
  afm_arena arena;
  uint32_t n = 0;
  afm_target *t = NULL;
  afm_result res;
  if (!raw || (!buffer && buffer_size)) return AFM_ERR_ARGUMENT;
  arena.base = (uint8_t *)buffer;
  arena.size = buffer_size;
  arena.used = 0;
  res = afm_targets_decode_at(raw, size, 0, vertex_count, 0, &arena, &n, &t, diag);
  if (bytes) *bytes = arena.used;
  if (target_count) *target_count = n;
  if (targets) *targets = t;
  if (res == AFM_OK && buffer && arena.used > buffer_size) return AFM_ERR_BUFFER_TOO_SMALL;
  return res;
}

afm_result afm_targets_encode_to(const afm_target *targets, uint32_t count, afm_writer *w) {
  uint32_t i, k;
  if (count && !targets) return AFM_ERR_ARGUMENT;
  afm_write_u32(w, count);
  for (i = 0; i < count; ++i) {
    const afm_target *t = &targets[i];
    size_t n = t->delta_count;
    if ((t->run_count && !t->runs) || (n && (!t->dx || !t->dy || !t->dz)) ||
        ((t->flags & AFM_TARGET_NORMALS) && n && (!t->nx || !t->ny || !t->nz)))
      return AFM_ERR_ARGUMENT;
    afm_write_u8(w, t->kind);
    afm_write_u8(w, t->number);
    afm_write_u8(w, t->flags);
    afm_write_u8(w, 0);
    afm_write_i32(w, t->reference);
    afm_write_u32(w, t->run_count);
    afm_write_u32(w, t->delta_count);
    if (t->kind == AFM_TARGET_COMBINATION) {
      afm_write_u8(w, t->gate);
      afm_write_u8(w, 0);
      afm_write_u16(w, 0);
      afm_write_i32(w, t->gate_reference);
    }
    for (k = 0; k < t->run_count; ++k) {
      afm_write_u32(w, t->runs[k].start);
      afm_write_u32(w, t->runs[k].length);
    }
    afm_write_i16_array(w, t->dx, n);
    afm_write_i16_array(w, t->dy, n);
    afm_write_i16_array(w, t->dz, n);
    if (t->flags & AFM_TARGET_NORMALS) {
      afm_write_i16_array(w, t->nx, n);
      afm_write_i16_array(w, t->ny, n);
      afm_write_i16_array(w, t->nz, n);
    }
  }
  return w->overflow ? AFM_ERR_BUFFER_TOO_SMALL : AFM_OK;
}

afm_result afm_targets_encoded_size(const afm_target *targets, uint32_t count, size_t *size) {
  afm_writer w = {NULL, 0, 0, 0};
  afm_result r;
  if (!size) return AFM_ERR_ARGUMENT;
  r = afm_targets_encode_to(targets, count, &w);
  *size = w.pos;
  return r;
}

afm_result afm_targets_encode(const afm_target *targets, uint32_t count, uint8_t *out,
                              size_t size) {
  afm_writer w;
  if (!out) return AFM_ERR_ARGUMENT;
  w.data = out;
  w.size = size;
  w.pos = 0;
  w.overflow = 0;
  return afm_targets_encode_to(targets, count, &w);
}
