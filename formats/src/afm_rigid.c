/* RIGD chunk: eyeballs, jaw and head as transforms about pivots. */
#include <string.h>

#include "afm_internal.h"

afm_result afm_rigids_decode(const uint8_t *raw, size_t size, uint64_t file_offset,
                             uint32_t part_count, afm_arena *arena, uint32_t *count_out,
                             afm_rigid **rigids_out, afm_diag *diag) {
  afm_reader r;
  afm_rigid *rigids;
  uint32_t count, i, j;
  unsigned seen = 0;

  afm_reader_init(&r, raw, size, file_offset, AFM_CHUNK_RIGD, diag);
  count = afm_read_u32(&r, "rigid_count");
  if (r.error != AFM_OK) return r.error;
  if (count > afm_remaining(&r) / 40)
    return afm_fail(&r, AFM_ERR_TRUNCATED, "rigid_count %lu cannot fit", (unsigned long)count);
  rigids = (afm_rigid *)afm_arena_take(arena, afm_mul_size(count, sizeof *rigids));
  for (i = 0; i < count; ++i) {
    afm_rigid g;
    uint16_t *parts;
    afm_control *controls;
    int k;
    memset(&g, 0, sizeof g);
    g.kind = afm_read_u8(&r, "rigid.kind");
    if (afm_read_u8(&r, "rigid.reserved") != 0 && r.error == AFM_OK)
      return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: reserved byte not zero", (unsigned long)i);
    g.part_count = afm_read_u16(&r, "rigid.part_count");
    g.control_count = afm_read_u16(&r, "rigid.control_count");
    if (afm_read_u16(&r, "rigid.reserved") != 0 && r.error == AFM_OK)
      return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: reserved field not zero", (unsigned long)i);
    for (k = 0; k < 3; ++k) g.pivot[k] = afm_read_i32(&r, "rigid.pivot");
    for (k = 0; k < 9; ++k) g.axes[k] = (int16_t)afm_read_u16(&r, "rigid.axes");
    if (afm_read_u16(&r, "rigid.pad") != 0 && r.error == AFM_OK)
      return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: padding not zero", (unsigned long)i);
    if (r.error != AFM_OK) return r.error;
    if (g.kind < AFM_RIGID_EYE_LEFT || g.kind > AFM_RIGID_HEAD)
      return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: kind %u unknown", (unsigned long)i,
                      (unsigned)g.kind);
    if (seen & (1u << g.kind))
      return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: kind %u appears twice", (unsigned long)i,
                      (unsigned)g.kind);
    seen |= 1u << g.kind;
    parts = afm_read_u16_array(&r, arena, g.part_count, "rigid.parts");
    if (r.error != AFM_OK) return r.error;
    if (parts) {
      for (k = 0; k < g.part_count; ++k) {
        if (parts[k] >= part_count)
          return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: part %u >= part_count %lu",
                          (unsigned long)i, (unsigned)parts[k], (unsigned long)part_count);
        for (j = 0; j < (uint32_t)k; ++j)
          if (parts[j] == parts[k])
            return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu: part %u listed twice",
                            (unsigned long)i, (unsigned)parts[k]);
      }
    }
    if (g.control_count > afm_remaining(&r) / 8)
      return afm_fail(&r, AFM_ERR_TRUNCATED, "rigid %lu: %u controls cannot fit",
                      (unsigned long)i, (unsigned)g.control_count);
    controls = (afm_control *)afm_arena_take(arena, afm_mul_size(g.control_count, sizeof *controls));
    for (k = 0; k < g.control_count; ++k) {
      afm_control c;
      c.fap = afm_read_u8(&r, "control.fap");
      c.dof = afm_read_u8(&r, "control.dof");
      c.knot = (int16_t)afm_read_u16(&r, "control.knot");
      c.gain_q16 = afm_read_i32(&r, "control.gain");
      if (r.error != AFM_OK) return r.error;
      if (c.fap < 3 || c.fap > 68 || c.dof > AFM_DOF_TRANSLATE_Z)
        return afm_fail(&r, AFM_ERR_RANGE, "rigid %lu control %d: FAP %u dof %u out of range",
                        (unsigned long)i, k, (unsigned)c.fap, (unsigned)c.dof);
      if (controls) controls[k] = c;
    }
    g.parts = parts;
    g.controls = controls;
    if (rigids) rigids[i] = g;
  }
  if (afm_remaining(&r) != 0)
    return afm_fail(&r, AFM_ERR_TRAILING_BYTES, "%lu bytes after the last rigid",
                    (unsigned long)afm_remaining(&r));
  *count_out = count;
  *rigids_out = rigids;
  return AFM_OK;
}

afm_result afm_rigids_encode(const afm_rigid *rigids, uint32_t count, afm_writer *w) {
  uint32_t i;
  int k;
  if (count && !rigids) return AFM_ERR_ARGUMENT;
  afm_write_u32(w, count);
  for (i = 0; i < count; ++i) {
    const afm_rigid *g = &rigids[i];
    if ((g->part_count && !g->parts) || (g->control_count && !g->controls))
      return AFM_ERR_ARGUMENT;
    afm_write_u8(w, g->kind);
    afm_write_u8(w, 0);
    afm_write_u16(w, g->part_count);
    afm_write_u16(w, g->control_count);
    afm_write_u16(w, 0);
    for (k = 0; k < 3; ++k) afm_write_i32(w, g->pivot[k]);
    for (k = 0; k < 9; ++k) afm_write_u16(w, (uint16_t)g->axes[k]);
    afm_write_u16(w, 0);
    afm_write_u16_array(w, g->parts, g->part_count);
    for (k = 0; k < g->control_count; ++k) {
      afm_write_u8(w, g->controls[k].fap);
      afm_write_u8(w, g->controls[k].dof);
      afm_write_u16(w, (uint16_t)g->controls[k].knot);
      afm_write_i32(w, g->controls[k].gain_q16);
    }
  }
  return w->overflow ? AFM_ERR_BUFFER_TOO_SMALL : AFM_OK;
}
