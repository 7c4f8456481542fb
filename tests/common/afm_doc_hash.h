/* A value-by-value hash of a decoded AFM document, shared by the ARM
 * bit-exactness driver (tests/arm/afm_hash.c) and the fuzz round trip
 * (fuzz/afm_fuzz.h).
 *
 * FNV-1a 64 over values rather than bytes: each step xors one value (a byte,
 * or a 16- or 32-bit integer zero-extended) into the state and multiplies by
 * the FNV prime. Values, not their bytes in memory, so the hash is the same
 * on every byte order and word size; a value is fed at its own width (an
 * int16 array hashes as 16-bit values, sign bits dropped by the cast). Every
 * array is read through its full length (ASan sees a count that does not
 * match its array). No floating-point arithmetic: a float is hashed by its
 * bits.
 *
 * C99, static inline functions in a header (no warning for the ones a user
 * leaves unused): each user is one translation unit. */
#ifndef AFM_TESTS_DOC_HASH_H
#define AFM_TESTS_DOC_HASH_H

#include <stdint.h>
#include <string.h>

#include "afm/format.h"

typedef struct hasher {
  uint64_t h;
} hasher;

#define HASH_STEP(h, v) ((h) = ((h) ^ (uint64_t)(v)) * 0x100000001b3u)

static inline void hash_init(hasher *s) { s->h = 0xcbf29ce484222325u; }

/* Byte data (strings, u8 arrays), one step per byte. */
static inline void hash_bytes(hasher *s, const void *data, size_t size) {
  const uint8_t *p = (const uint8_t *)data;
  uint64_t h = s->h;
  size_t i;
  for (i = 0; i < size; ++i) HASH_STEP(h, p[i]);
  s->h = h;
}

static inline void hash_u8(hasher *s, uint8_t v) { HASH_STEP(s->h, v); }
static inline void hash_u16(hasher *s, uint16_t v) { HASH_STEP(s->h, v); }
static inline void hash_u32(hasher *s, uint32_t v) { HASH_STEP(s->h, v); }
static inline void hash_i32(hasher *s, int32_t v) { HASH_STEP(s->h, (uint32_t)v); }

/* A float by its bits (IEEE-754 binary32 on every target). */
static inline void hash_f32(hasher *s, float v) {
  uint32_t u;
  memcpy(&u, &v, sizeof u);
  hash_u32(s, u);
}

/* Arrays: a presence value (NULL and empty differ), then the elements, each
 * cast to the unsigned type of its width. */
#define HASH_ARRAY(name, type, as)                                \
  static inline void name(hasher *s, const type *a, size_t n) {          \
    uint64_t h = s->h;                                            \
    size_t i;                                                     \
    HASH_STEP(h, a != NULL);                                      \
    if (a)                                                        \
      for (i = 0; i < n; ++i) HASH_STEP(h, (as)a[i]);             \
    s->h = h;                                                     \
  }
HASH_ARRAY(hash_u8s, uint8_t, uint8_t)
HASH_ARRAY(hash_i16s, int16_t, uint16_t)
HASH_ARRAY(hash_u16s, uint16_t, uint16_t)
HASH_ARRAY(hash_i32s, int32_t, uint32_t)
HASH_ARRAY(hash_u32s, uint32_t, uint32_t)
#undef HASH_ARRAY

static inline void hash_string(hasher *s, const char *text) {
  hash_u8s(s, (const uint8_t *)text, text ? strlen(text) + 1 : 0);
}

/* The hash as 16 hex digits, after a final avalanche (MurmurHash3's fmix64)
 * so that every input bit reaches every output bit; `out` holds 17 bytes. */
static inline const char *hash_hex(const hasher *s, char *out) {
  static const char digits[] = "0123456789abcdef";
  uint64_t h = s->h;
  int i;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdu;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53u;
  h ^= h >> 33;
  for (i = 0; i < 16; ++i) out[i] = digits[(h >> (60 - 4 * i)) & 0xF];
  out[16] = '\0';
  return out;
}

/* ---- the document ---------------------------------------------------------- */

static inline void hash_meta(hasher *s, const afm_meta *m) {
  uint32_t i;
  hash_string(s, m->name);
  hash_string(s, m->units);
  hash_string(s, m->generator);
  hash_f32(s, m->es0);
  hash_f32(s, m->irisd0);
  hash_f32(s, m->ens0);
  hash_f32(s, m->mns0);
  hash_f32(s, m->mw0);
  hash_u32(s, m->fdp_count);
  for (i = 0; i < m->fdp_count; ++i) {
    const afm_fdp_point *p = &m->fdps[i];
    hash_u8(s, p->group);
    hash_u8(s, p->index);
    hash_u32(s, p->vertex);
    hash_f32(s, p->pos[0]);
    hash_f32(s, p->pos[1]);
    hash_f32(s, p->pos[2]);
  }
}

static inline void hash_geometry(hasher *s, const afm_geometry *g) {
  uint32_t i;
  size_t V = g->vertex_count;
  hash_u32(s, g->vertex_count);
  hash_u32(s, g->triangle_count);
  hash_u32(s, g->part_count);
  hash_u32(s, g->attributes);
  for (i = 0; i < 3; ++i) hash_f32(s, g->origin[i]);
  hash_f32(s, g->step);
  for (i = 0; i < 2; ++i) hash_f32(s, g->uv_origin[i]);
  for (i = 0; i < 2; ++i) hash_f32(s, g->uv_step[i]);
  for (i = 0; i < g->part_count; ++i) {
    const afm_part *p = &g->parts[i];
    hash_string(s, p->name);
    hash_string(s, p->texture);
    hash_u8(s, p->kind);
    hash_bytes(s, p->diffuse, 4);
    hash_u32(s, p->first_vertex);
    hash_u32(s, p->vertex_count);
    hash_u32(s, p->first_triangle);
    hash_u32(s, p->triangle_count);
  }
  hash_i16s(s, g->px, V);
  hash_i16s(s, g->py, V);
  hash_i16s(s, g->pz, V);
  hash_i16s(s, g->nx, V);
  hash_i16s(s, g->ny, V);
  hash_i16s(s, g->nz, V);
  hash_u16s(s, g->u, V);
  hash_u16s(s, g->v, V);
  hash_u8s(s, g->rgba, 4 * V);
  hash_u32s(s, g->triangles, 3 * (size_t)g->triangle_count);
}

static inline void hash_target(hasher *s, const afm_target *t) {
  uint32_t i;
  hash_u8(s, t->kind);
  hash_u8(s, t->number);
  hash_u8(s, t->flags);
  hash_i32(s, t->reference);
  hash_u32(s, t->run_count);
  for (i = 0; i < t->run_count; ++i) {
    hash_u32(s, t->runs[i].start);
    hash_u32(s, t->runs[i].length);
  }
  hash_u32(s, t->delta_count);
  hash_i16s(s, t->dx, t->delta_count);
  hash_i16s(s, t->dy, t->delta_count);
  hash_i16s(s, t->dz, t->delta_count);
  hash_i16s(s, t->nx, t->delta_count);
  hash_i16s(s, t->ny, t->delta_count);
  hash_i16s(s, t->nz, t->delta_count);
}

static inline void hash_rigid(hasher *s, const afm_rigid *r) {
  uint32_t i;
  hash_u8(s, r->kind);
  hash_i32s(s, r->pivot, 3);
  hash_i16s(s, r->axes, 9);
  hash_u16(s, r->part_count);
  hash_u16s(s, r->parts, r->part_count);
  hash_u16(s, r->control_count);
  for (i = 0; i < r->control_count; ++i) {
    hash_u8(s, r->controls[i].fap);
    hash_u8(s, r->controls[i].dof);
    hash_i32(s, r->controls[i].gain_q16);
    /* Hashed where set, so that documents without knots (before 1.3) keep
     * their golden hashes. */
    if (r->controls[i].knot) hash_u16(s, (uint16_t)r->controls[i].knot);
  }
}

/* Everything the document holds, except `skipped_chunks` (a fact about the
 * file it came from, which a rewrite drops). */
static inline void hash_doc(hasher *s, const afm_doc *doc) {
  uint32_t i;
  hash_meta(s, &doc->meta);
  hash_geometry(s, &doc->geometry);
  hash_u32(s, doc->target_count);
  for (i = 0; i < doc->target_count; ++i) hash_target(s, &doc->targets[i]);
  hash_u32(s, doc->rigid_count);
  for (i = 0; i < doc->rigid_count; ++i) hash_rigid(s, &doc->rigids[i]);
}

#endif /* AFM_TESTS_DOC_HASH_H */
