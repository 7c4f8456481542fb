/* Internal helpers of libafm_format: bounds-checked little-endian cursors and
 * a bump arena with a measuring mode. Not part of the public API. */
#ifndef AFM_INTERNAL_H
#define AFM_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "afm/format.h"

/* ---- arena ---------------------------------------------------------------
 * One code path both measures and decodes: with base == NULL the arena only
 * counts the bytes that a decode would take. Every block is 8-byte aligned. */
typedef struct afm_arena {
  uint8_t *base; /* NULL: measuring */
  size_t size;   /* capacity when decoding */
  size_t used;
} afm_arena;

/* Returns a block of `size` bytes, or NULL when measuring (or out of space,
 * which the caller sees as arena->used > arena->size). */
void *afm_arena_take(afm_arena *arena, size_t size);
/* Overflow-checked count * elem; SIZE_MAX on overflow (which then fails). */
size_t afm_mul_size(size_t count, size_t elem);

/* ---- reading -------------------------------------------------------------
 * A cursor over a chunk payload. Every read checks the remaining length first
 * and compares untrusted lengths against the trusted remainder. */
typedef struct afm_reader {
  const uint8_t *data;
  size_t size;
  size_t pos;
  uint64_t file_offset; /* of data[0] in the file, for messages */
  uint32_t chunk;       /* fourcc for messages */
  afm_diag *diag;
  afm_result error;     /* first error; reads after it return zeros */
} afm_reader;

void afm_reader_init(afm_reader *r, const uint8_t *data, size_t size, uint64_t file_offset,
                     uint32_t chunk, afm_diag *diag);
size_t afm_remaining(const afm_reader *r);
uint8_t afm_read_u8(afm_reader *r, const char *field);
uint16_t afm_read_u16(afm_reader *r, const char *field);
uint32_t afm_read_u32(afm_reader *r, const char *field);
int32_t afm_read_i32(afm_reader *r, const char *field);
float afm_read_f32(afm_reader *r, const char *field);
/* Skips to the next multiple of 4 from the payload start; padding must be 0. */
void afm_read_pad4(afm_reader *r, const char *field);
/* A u16-length-prefixed UTF-8 string (no NUL inside), copied NUL-terminated
 * into the arena. Returns "" when measuring or on error. */
const char *afm_read_string(afm_reader *r, afm_arena *arena, const char *field);
/* `count` little-endian 16-bit values into the arena (then pad4). */
int16_t *afm_read_i16_array(afm_reader *r, afm_arena *arena, size_t count, const char *field);
uint16_t *afm_read_u16_array(afm_reader *r, afm_arena *arena, size_t count, const char *field);
uint32_t *afm_read_u32_array(afm_reader *r, afm_arena *arena, size_t count, const char *field);
uint8_t *afm_read_u8_array(afm_reader *r, afm_arena *arena, size_t count, const char *field);
/* `count` runs (u32 start, u32 length) into the arena (NULL when measuring):
 * non-empty, ascending, disjoint, within [0, limit). `what` prefixes error
 * messages ("target 3 (FAP 12)"), `limit_name` names the limit; *total gets
 * the sum of the lengths. */
afm_run *afm_read_runs(afm_reader *r, afm_arena *arena, uint32_t count, uint32_t limit,
                       const char *what, const char *limit_name, uint64_t *total);
/* Records an error at the cursor (first one wins) and returns it. */
afm_result afm_fail(afm_reader *r, afm_result result, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Formats a message into diag (if any) with chunk and offset. */
void afm_diag_set(afm_diag *diag, uint32_t chunk, uint64_t offset, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* ---- writing -------------------------------------------------------------
 * A cursor into a buffer whose size was computed by the matching size pass;
 * running past the end is a bug, reported as AFM_ERR_BUFFER_TOO_SMALL. With
 * data == NULL it only counts. */
typedef struct afm_writer {
  uint8_t *data;
  size_t size;
  size_t pos;
  int overflow;
} afm_writer;

void afm_write_u8(afm_writer *w, uint8_t v);
void afm_write_u16(afm_writer *w, uint16_t v);
void afm_write_u32(afm_writer *w, uint32_t v);
void afm_write_i32(afm_writer *w, int32_t v);
void afm_write_f32(afm_writer *w, float v);
void afm_write_pad4(afm_writer *w);
void afm_write_string(afm_writer *w, const char *s);
void afm_write_i16_array(afm_writer *w, const int16_t *v, size_t count);
void afm_write_u16_array(afm_writer *w, const uint16_t *v, size_t count);
void afm_write_u32_array(afm_writer *w, const uint32_t *v, size_t count);
void afm_write_bytes(afm_writer *w, const uint8_t *v, size_t count);

/* Little-endian loads/stores used by the container. */
uint16_t afm_load_u16(const uint8_t *p);
uint32_t afm_load_u32(const uint8_t *p);
void afm_store_u16(uint8_t *p, uint16_t v);
void afm_store_u32(uint8_t *p, uint32_t v);

/* IEEE-754 binary32 checks on the bits alone: no floating-point arithmetic,
 * so a core built for a CPU without an FPU calls no soft-float helper. */
int afm_f32_finite(float f);
int afm_f32_nonnegative(float f); /* finite, +0 or positive (-0 counts as 0) */
int afm_f32_positive(float f);    /* finite and > 0 */

/* "GEOM" for a fourcc; non-printable bytes as '?'. */
void afm_fourcc_text(uint32_t kind, char out[5]);

/* ---- chunks not in the public header ------------------------------------ */
afm_result afm_meta_decode(const uint8_t *raw, size_t size, uint64_t file_offset,
                           afm_arena *arena, afm_meta *meta, afm_diag *diag);
afm_result afm_meta_encode(const afm_meta *meta, afm_writer *w);
afm_result afm_rigids_decode(const uint8_t *raw, size_t size, uint64_t file_offset,
                             uint32_t part_count, afm_arena *arena, uint32_t *count,
                             afm_rigid **rigids, afm_diag *diag);
afm_result afm_rigids_encode(const afm_rigid *rigids, uint32_t count, afm_writer *w);
afm_result afm_lift_decode(const uint8_t *raw, size_t size, uint64_t file_offset,
                           uint32_t vertex_count, afm_arena *arena, afm_lift **lift,
                           afm_diag *diag);
afm_result afm_lift_encode(const afm_lift *lift, afm_writer *w);
/* The cross-chunk rules of LIFT on decoded targets: no normal deltas, no
 * run over a bound vertex. */
afm_result afm_lift_check_targets(const afm_lift *lift, const afm_target *targets,
                                  uint32_t count, uint64_t file_offset, afm_diag *diag);

/* Decoders of the public chunk API, with the payload's file offset for
 * messages and a caller-provided arena. */
afm_result afm_geometry_decode_at(const uint8_t *raw, size_t size, uint64_t file_offset,
                                  afm_arena *arena, afm_geometry *geometry, afm_diag *diag);
afm_result afm_geometry_encode_to(const afm_geometry *geometry, afm_writer *w);
/* Runs index [0, vertex_count + control_count) (the caller checked the sum
 * fits 32 bits). */
afm_result afm_targets_decode_at(const uint8_t *raw, size_t size, uint64_t file_offset,
                                 uint32_t vertex_count, uint32_t control_count, afm_arena *arena,
                                 uint32_t *count, afm_target **targets, afm_diag *diag);
afm_result afm_targets_encode_to(const afm_target *targets, uint32_t count, afm_writer *w);

#endif /* AFM_INTERNAL_H */
