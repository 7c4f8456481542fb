/* Bounds-checked cursors, arena and diagnostics (see afm_internal.h). */
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm_internal.h"

/* ---- arena ---------------------------------------------------------------- */

size_t afm_mul_size(size_t count, size_t elem) {
  if (elem != 0 && count > SIZE_MAX / elem) return SIZE_MAX;
  return count * elem;
}

void *afm_arena_take(afm_arena *arena, size_t size) {
  size_t start = (arena->used + 7u) & ~(size_t)7u;
  if (start < arena->used || size > SIZE_MAX - start) {
    arena->used = SIZE_MAX; /* overflow: no buffer can satisfy it */
    return NULL;
  }
  arena->used = start + size;
  if (!arena->base || arena->used > arena->size) return NULL;
  return arena->base + start;
}

/* ---- diagnostics ---------------------------------------------------------- */

void afm_fourcc_text(uint32_t kind, char out[5]) {
  int i;
  for (i = 0; i < 4; ++i) {
    unsigned c = (kind >> (8 * i)) & 0xFFu;
    out[i] = (c >= 0x20 && c < 0x7F) ? (char)c : '?';
  }
  out[4] = '\0';
}

static void diag_vset(afm_diag *diag, uint32_t chunk, uint64_t offset, const char *format,
                      va_list args) {
  char name[5];
  size_t n = 0;
  if (!diag || diag->message[0]) return; /* first message wins */
  diag->chunk = chunk;
  diag->offset = offset;
  if (chunk) {
    afm_fourcc_text(chunk, name);
    n = (size_t)snprintf(diag->message, sizeof diag->message, "%s: ", name);
  }
  vsnprintf(diag->message + n, sizeof diag->message - n, format, args);
}

void afm_diag_set(afm_diag *diag, uint32_t chunk, uint64_t offset, const char *format, ...) {
  va_list args;
  va_start(args, format);
  diag_vset(diag, chunk, offset, format, args);
  va_end(args);
}

afm_result afm_fail(afm_reader *r, afm_result result, const char *format, ...) {
  va_list args;
  if (r->error != AFM_OK) return r->error;
  r->error = result;
  va_start(args, format);
  diag_vset(r->diag, r->chunk, r->file_offset + r->pos, format, args);
  va_end(args);
  return result;
}

/* ---- float bit checks ------------------------------------------------------- */

static uint32_t f32_bits(float f) {
  uint32_t u;
  memcpy(&u, &f, sizeof u);
  return u;
}

int afm_f32_finite(float f) { return ((f32_bits(f) >> 23) & 0xFFu) != 0xFFu; }

int afm_f32_nonnegative(float f) {
  uint32_t u = f32_bits(f);
  return afm_f32_finite(f) && (!(u >> 31) || (u & 0x7FFFFFFFu) == 0);
}

int afm_f32_positive(float f) {
  uint32_t u = f32_bits(f);
  return afm_f32_finite(f) && !(u >> 31) && (u & 0x7FFFFFFFu) != 0;
}

/* ---- little-endian -------------------------------------------------------- */

uint16_t afm_load_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }

uint32_t afm_load_u32(const uint8_t *p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
         ((uint32_t)p[3] << 24);
}

void afm_store_u16(uint8_t *p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}

void afm_store_u32(uint8_t *p, uint32_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)((v >> 8) & 0xFFu);
  p[2] = (uint8_t)((v >> 16) & 0xFFu);
  p[3] = (uint8_t)(v >> 24);
}

/* ---- reader --------------------------------------------------------------- */

void afm_reader_init(afm_reader *r, const uint8_t *data, size_t size, uint64_t file_offset,
                     uint32_t chunk, afm_diag *diag) {
  r->data = data;
  r->size = size;
  r->pos = 0;
  r->file_offset = file_offset;
  r->chunk = chunk;
  r->diag = diag;
  r->error = AFM_OK;
}

size_t afm_remaining(const afm_reader *r) { return r->size - r->pos; }

/* True when `n` more bytes are there; else records a truncation error. */
static int need(afm_reader *r, size_t n, const char *field) {
  if (r->error != AFM_OK) return 0;
  if (n > afm_remaining(r)) {
    afm_fail(r, AFM_ERR_TRUNCATED, "%s: needs %lu bytes, %lu left", field, (unsigned long)n,
             (unsigned long)afm_remaining(r));
    return 0;
  }
  return 1;
}

uint8_t afm_read_u8(afm_reader *r, const char *field) {
  if (!need(r, 1, field)) return 0;
  return r->data[r->pos++];
}

uint16_t afm_read_u16(afm_reader *r, const char *field) {
  uint16_t v;
  if (!need(r, 2, field)) return 0;
  v = afm_load_u16(r->data + r->pos);
  r->pos += 2;
  return v;
}

uint32_t afm_read_u32(afm_reader *r, const char *field) {
  uint32_t v;
  if (!need(r, 4, field)) return 0;
  v = afm_load_u32(r->data + r->pos);
  r->pos += 4;
  return v;
}

int32_t afm_read_i32(afm_reader *r, const char *field) {
  uint32_t u = afm_read_u32(r, field);
  /* Two's complement without implementation-defined conversion. */
  return u <= 0x7FFFFFFFu ? (int32_t)u : -(int32_t)(~u) - 1;
}

float afm_read_f32(afm_reader *r, const char *field) {
  uint32_t u = afm_read_u32(r, field);
  float f;
  memcpy(&f, &u, sizeof f); /* bit copy: IEEE-754 binary32 on every target we support */
  return f;
}

void afm_read_pad4(afm_reader *r, const char *field) {
  while (r->error == AFM_OK && (r->pos & 3u) != 0) {
    if (!need(r, 1, field)) return;
    if (r->data[r->pos] != 0) {
      afm_fail(r, AFM_ERR_RANGE, "%s: padding byte is not zero", field);
      return;
    }
    r->pos++;
  }
}

const char *afm_read_string(afm_reader *r, afm_arena *arena, const char *field) {
  uint16_t len = afm_read_u16(r, field);
  char *out;
  if (!need(r, len, field)) return "";
  if (memchr(r->data + r->pos, 0, len)) {
    afm_fail(r, AFM_ERR_RANGE, "%s: string contains a NUL byte", field);
    return "";
  }
  out = (char *)afm_arena_take(arena, (size_t)len + 1);
  if (out) {
    memcpy(out, r->data + r->pos, len);
    out[len] = '\0';
  }
  r->pos += len;
  afm_read_pad4(r, field);
  return out ? out : "";
}

static void *read_array(afm_reader *r, afm_arena *arena, size_t count, size_t elem,
                        const char *field) {
  size_t bytes = afm_mul_size(count, elem);
  uint8_t *out;
  size_t i;
  if (!need(r, bytes, field)) return NULL;
  out = (uint8_t *)afm_arena_take(arena, bytes);
  if (out) {
    const uint8_t *p = r->data + r->pos;
    /* Assemble each element explicitly: correct on any host byte order. */
    if (elem == 1) {
      memcpy(out, p, bytes);
    } else if (elem == 2) {
      uint16_t *o = (uint16_t *)(void *)out;
      for (i = 0; i < count; ++i) o[i] = afm_load_u16(p + 2 * i);
    } else {
      uint32_t *o = (uint32_t *)(void *)out;
      for (i = 0; i < count; ++i) o[i] = afm_load_u32(p + 4 * i);
    }
  }
  r->pos += bytes;
  afm_read_pad4(r, field);
  return out;
}

int16_t *afm_read_i16_array(afm_reader *r, afm_arena *arena, size_t count, const char *field) {
  /* int16_t and uint16_t share representation; the bits are the value. */
  return (int16_t *)read_array(r, arena, count, 2, field);
}

uint16_t *afm_read_u16_array(afm_reader *r, afm_arena *arena, size_t count, const char *field) {
  return (uint16_t *)read_array(r, arena, count, 2, field);
}

uint32_t *afm_read_u32_array(afm_reader *r, afm_arena *arena, size_t count, const char *field) {
  return (uint32_t *)read_array(r, arena, count, 4, field);
}

uint8_t *afm_read_u8_array(afm_reader *r, afm_arena *arena, size_t count, const char *field) {
  return (uint8_t *)read_array(r, arena, count, 1, field);
}

afm_run *afm_read_runs(afm_reader *r, afm_arena *arena, uint32_t count, uint32_t limit,
                       const char *what, const char *limit_name, uint64_t *total) {
  afm_run *runs = (afm_run *)afm_arena_take(arena, afm_mul_size(count, sizeof *runs));
  uint32_t k, end = 0;
  *total = 0;
  for (k = 0; k < count; ++k) {
    afm_run run;
    run.start = afm_read_u32(r, "run.start");
    run.length = afm_read_u32(r, "run.length");
    if (r->error != AFM_OK) return NULL;
    if (run.length == 0 || (k > 0 && run.start < end) || run.start > limit ||
        run.length > limit - run.start) {
      afm_fail(r, AFM_ERR_RANGE,
               "%s: run %lu [%lu, +%lu) is empty, overlaps the previous run or passes %s %lu", what,
               (unsigned long)k, (unsigned long)run.start, (unsigned long)run.length, limit_name,
               (unsigned long)limit);
      return NULL;
    }
    end = run.start + run.length;
    *total += run.length;
    if (runs) runs[k] = run;
  }
  return runs;
}

/* ---- writer --------------------------------------------------------------- */

static uint8_t *room(afm_writer *w, size_t n) {
  uint8_t *p;
  if (w->overflow) return NULL;
  if (!w->data) {
    w->pos += n;
    return NULL;
  }
  if (n > w->size - w->pos) {
    w->overflow = 1;
    return NULL;
  }
  p = w->data + w->pos;
  w->pos += n;
  return p;
}

void afm_write_u8(afm_writer *w, uint8_t v) {
  uint8_t *p = room(w, 1);
  if (p) p[0] = v;
}

void afm_write_u16(afm_writer *w, uint16_t v) {
  uint8_t *p = room(w, 2);
  if (p) afm_store_u16(p, v);
}

void afm_write_u32(afm_writer *w, uint32_t v) {
  uint8_t *p = room(w, 4);
  if (p) afm_store_u32(p, v);
}

void afm_write_i32(afm_writer *w, int32_t v) { afm_write_u32(w, (uint32_t)v); }

void afm_write_f32(afm_writer *w, float v) {
  uint32_t u;
  memcpy(&u, &v, sizeof u);
  afm_write_u32(w, u);
}

void afm_write_pad4(afm_writer *w) {
  while ((w->pos & 3u) != 0 && !w->overflow) afm_write_u8(w, 0);
}

void afm_write_string(afm_writer *w, const char *s) {
  size_t len = s ? strlen(s) : 0;
  if (len > 0xFFFFu) len = 0xFFFFu; /* callers validate; never write past the u16 */
  afm_write_u16(w, (uint16_t)len);
  afm_write_bytes(w, (const uint8_t *)s, len);
  afm_write_pad4(w);
}

void afm_write_i16_array(afm_writer *w, const int16_t *v, size_t count) {
  size_t i;
  for (i = 0; i < count; ++i) afm_write_u16(w, (uint16_t)v[i]);
  afm_write_pad4(w);
}

void afm_write_u16_array(afm_writer *w, const uint16_t *v, size_t count) {
  size_t i;
  for (i = 0; i < count; ++i) afm_write_u16(w, v[i]);
  afm_write_pad4(w);
}

void afm_write_u32_array(afm_writer *w, const uint32_t *v, size_t count) {
  size_t i;
  for (i = 0; i < count; ++i) afm_write_u32(w, v[i]);
}

void afm_write_bytes(afm_writer *w, const uint8_t *v, size_t count) {
  uint8_t *p = room(w, count);
  if (p && count) memcpy(p, v, count);
}
