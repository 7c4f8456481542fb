/* META chunk: model name, units, generator, FAPU, FDP positions. */
#include <string.h>

#include "afm_internal.h"

enum { kFdpEntrySize = 20 };

afm_result afm_meta_decode(const uint8_t *raw, size_t size, uint64_t file_offset,
                           afm_arena *arena, afm_meta *meta, afm_diag *diag) {
  afm_reader r;
  uint32_t i;
  afm_fdp_point *fdps;
  float fapu[5];

  afm_reader_init(&r, raw, size, file_offset, AFM_CHUNK_META, diag);
  memset(meta, 0, sizeof *meta);
  meta->fdp_count = afm_read_u32(&r, "fdp_count");
  for (i = 0; i < 5; ++i) {
    fapu[i] = afm_read_f32(&r, "fapu");
    if (r.error == AFM_OK && !afm_f32_nonnegative(fapu[i]))
      return afm_fail(&r, AFM_ERR_RANGE, "fapu[%u] is negative or not finite", (unsigned)i);
  }
  meta->es0 = fapu[0];
  meta->irisd0 = fapu[1];
  meta->ens0 = fapu[2];
  meta->mns0 = fapu[3];
  meta->mw0 = fapu[4];
  meta->name = afm_read_string(&r, arena, "name");
  meta->units = afm_read_string(&r, arena, "units");
  meta->generator = afm_read_string(&r, arena, "generator");
  if (r.error != AFM_OK) return r.error;
  if (meta->fdp_count > afm_remaining(&r) / kFdpEntrySize)
    return afm_fail(&r, AFM_ERR_TRUNCATED, "fdp_count %lu: only %lu bytes left",
                    (unsigned long)meta->fdp_count, (unsigned long)afm_remaining(&r));
  fdps = (afm_fdp_point *)afm_arena_take(arena, afm_mul_size(meta->fdp_count, sizeof *fdps));
  for (i = 0; i < meta->fdp_count && r.error == AFM_OK; ++i) {
    afm_fdp_point p;
    int k;
    p.group = afm_read_u8(&r, "fdp.group");
    p.index = afm_read_u8(&r, "fdp.index");
    if (afm_read_u16(&r, "fdp.reserved") != 0)
      return afm_fail(&r, AFM_ERR_RANGE, "fdp %lu: reserved field is not zero", (unsigned long)i);
    p.vertex = afm_read_u32(&r, "fdp.vertex");
    for (k = 0; k < 3; ++k) {
      p.pos[k] = afm_read_f32(&r, "fdp.pos");
      if (r.error == AFM_OK && !afm_f32_finite(p.pos[k]))
        return afm_fail(&r, AFM_ERR_RANGE, "fdp %u.%u: position not finite", p.group, p.index);
    }
    if (r.error == AFM_OK && (p.group < 2 || p.group > 11 || p.index < 1 || p.index > 15))
      return afm_fail(&r, AFM_ERR_RANGE, "fdp %lu: %u.%u is not an FDP name", (unsigned long)i,
                      p.group, p.index);
    if (fdps) fdps[i] = p;
  }
  if (r.error != AFM_OK) return r.error;
  if (afm_remaining(&r) != 0)
    return afm_fail(&r, AFM_ERR_TRAILING_BYTES, "%lu bytes after the last FDP",
                    (unsigned long)afm_remaining(&r));
  meta->fdps = fdps;
  return AFM_OK;
}

afm_result afm_meta_encode(const afm_meta *meta, afm_writer *w) {
  uint32_t i;
  afm_write_u32(w, meta->fdp_count);
  afm_write_f32(w, meta->es0);
  afm_write_f32(w, meta->irisd0);
  afm_write_f32(w, meta->ens0);
  afm_write_f32(w, meta->mns0);
  afm_write_f32(w, meta->mw0);
  afm_write_string(w, meta->name ? meta->name : "");
  afm_write_string(w, meta->units ? meta->units : "");
  afm_write_string(w, meta->generator ? meta->generator : "");
  for (i = 0; i < meta->fdp_count; ++i) {
    const afm_fdp_point *p = &meta->fdps[i];
    afm_write_u8(w, p->group);
    afm_write_u8(w, p->index);
    afm_write_u16(w, 0);
    afm_write_u32(w, p->vertex);
    afm_write_f32(w, p->pos[0]);
    afm_write_f32(w, p->pos[1]);
    afm_write_f32(w, p->pos[2]);
  }
  return w->overflow ? AFM_ERR_BUFFER_TOO_SMALL : AFM_OK;
}

float afm_meta_fapu_x0(const afm_meta *meta, afm_fapu unit) {
  switch (unit) {
    case AFM_FAPU_IRISD: return meta->irisd0;
    case AFM_FAPU_ES: return meta->es0;
    case AFM_FAPU_ENS: return meta->ens0;
    case AFM_FAPU_MNS: return meta->mns0;
    case AFM_FAPU_MW: return meta->mw0;
    default: return 0;
  }
}
