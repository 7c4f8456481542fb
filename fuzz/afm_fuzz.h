/* What fuzz_afm.c and fuzz_afm_draco.c share: one input through the AFM
 * reader, with or without the Draco codec.
 *
 * For each input, and again for a copy whose CRCs are recomputed (so that
 * mutations get past the container checks into the chunk decoders):
 *   - afm_container_open and every chunk entry;
 *   - afm_doc_measure, then afm_doc_read into a buffer of exactly the
 *     measured size (ASan sees any write past it), and once into a smaller
 *     one, which must fail with AFM_ERR_BUFFER_TOO_SMALL;
 *   - every array of an accepted document is read end to end (ASan sees any
 *     count that does not match its array);
 *   - an accepted document is written back (raw profile) and read again: the
 *     writer must accept what the reader accepted, and the two documents
 *     must be equal (a reader/writer disagreement aborts);
 *   - a player is built on it and posed with FAP
 *     values taken from the input.
 * Static functions in a header: each target is one translation unit. */
#ifndef AFM_FUZZ_H
#define AFM_FUZZ_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm/format.h"
#include "afm/player.h"
#include "../tests/common/afm_doc_hash.h"

#define FUZZ_MAX_DOC_BYTES ((size_t)256 << 20) /* larger documents are measured only */

static void fuzz_fail(const char *what, const char *detail) {
  fprintf(stderr, "fuzz: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
  abort();
}

static uint64_t fuzz_hash_doc(const afm_doc *doc) {
  hasher s;
  hash_init(&s);
  hash_doc(&s, doc);
  return s.h;
}

/* A player on the document, posed neutral and then with FAP values, visemes
 * and expressions taken from the input. */
static void fuzz_player(const afm_doc *doc, const uint8_t *data, size_t size) {
  afm_player_options options;
  afm_player *player = NULL;
  afm_fap_state neutral, state;
  size_t bytes = 0, V = doc->geometry.vertex_count, i;
  void *buffer;
  uint64_t sink = 0;
  int f;
  memset(&options, 0, sizeof options);
  if (size && (data[size - 1] & 1)) options.flags = AFM_PLAYER_NORMAL_DELTAS;
  if (afm_player_measure(doc, &options, &bytes) != AFM_OK) return;
  if (bytes > FUZZ_MAX_DOC_BYTES) return;
  buffer = malloc(bytes ? bytes : 1);
  if (!buffer) return;
  if (afm_player_init(doc, &options, buffer, bytes, &player) == AFM_OK) {
    afm_fap_state_reset(&neutral);
    afm_fap_state_reset(&state);
    for (f = 3; f <= AFM_FAP_COUNT; ++f) {
      const uint8_t *p = size >= 2 ? data + (f * 7919u) % (size - 1) : NULL;
      int32_t lo = 0, hi = 0;
      int32_t v = p ? (int32_t)(int16_t)(p[0] | (p[1] << 8)) : 0;
      afm_fap_value_range(f, &lo, &hi);
      state.value[f] = v < lo ? lo : v > hi ? hi : v;
    }
    if (size) {
      state.viseme.select1 = (uint8_t)(data[0] % AFM_VISEME_COUNT);
      state.viseme.select2 = (uint8_t)(data[size / 2] % AFM_VISEME_COUNT);
      state.viseme.blend = (uint8_t)(data[size / 3] % 64);
      state.expression.select1 = (uint8_t)(data[size / 4] % AFM_EXPRESSION_COUNT);
      state.expression.intensity1 = (uint8_t)(data[size / 5] % 64);
      state.expression.select2 = (uint8_t)(data[size / 6] % AFM_EXPRESSION_COUNT);
      state.expression.intensity2 = (uint8_t)(data[size / 7] % 64);
    }
    if (afm_player_pose(player, &neutral, NULL, 0) == AFM_OK &&
        afm_player_pose(player, &neutral, &state, 40000) == AFM_OK &&
        afm_player_pose(player, &state, NULL, 0) == AFM_OK) {
      const int32_t *pos = afm_player_positions(player);
      const afm_q14 *nrm = afm_player_normals(player);
      for (i = 0; i < 3 * V; ++i) sink += (uint32_t)pos[i] + (uint16_t)nrm[i];
      for (i = 0; i < doc->target_count; ++i) sink += (uint16_t)afm_player_weights(player)[i];
    }
  }
  free(buffer);
  if (sink == 1) fputs("", stderr); /* keeps the reads */
}

/* One document through measure, read, the too-small read, the round trip. */
static void fuzz_read(const uint8_t *data, size_t size, const afm_chunk_codec *draco) {
  afm_read_options ro;
  afm_diag diag;
  afm_container c;
  afm_doc *doc = NULL, *again = NULL;
  size_t bytes = 0, bytes2 = 0;
  void *buffer;
  uint32_t i;

  memset(&diag, 0, sizeof diag);
  if (afm_container_open(data, size, &c, &diag) == AFM_OK) {
    for (i = 0; i < c.chunk_count; ++i) {
      afm_chunk_info info;
      if (afm_container_chunk(&c, i, &info) != AFM_OK) fuzz_fail("afm_container_chunk failed", NULL);
      if (info.length && (info.data < data || info.data + info.length > data + size))
        fuzz_fail("a chunk lies outside the file", NULL);
    }
  }

  memset(&ro, 0, sizeof ro);
  ro.draco = draco;
  ro.diag = &diag;
  if (afm_doc_measure(data, size, &ro, &bytes) != AFM_OK) return;
  if (bytes > FUZZ_MAX_DOC_BYTES) return;
  if (bytes >= 16) {
    void *small = malloc(bytes / 2);
    if (small) {
      afm_result r = afm_doc_read(data, size, &ro, small, bytes / 2, &doc);
      if (r == AFM_OK) fuzz_fail("afm_doc_read accepted a buffer half the measured size", NULL);
      free(small);
    }
  }
  buffer = malloc(bytes ? bytes : 1);
  if (!buffer) return;
  if (afm_doc_read(data, size, &ro, buffer, bytes, &doc) == AFM_OK) {
    afm_write_options wo;
    uint8_t *out = NULL;
    size_t out_size = 0;
    uint64_t h = fuzz_hash_doc(doc);
    afm_result r;
    memset(&wo, 0, sizeof wo);
    wo.diag = &diag;
    r = afm_doc_write(doc, &wo, &out, &out_size);
    if (r != AFM_OK) fuzz_fail("afm_doc_write refuses a document afm_doc_read accepted", diag.message);
    ro.draco = NULL;
    r = afm_doc_measure(out, out_size, &ro, &bytes2);
    if (r == AFM_OK) {
      void *buffer2 = malloc(bytes2 ? bytes2 : 1);
      if (!buffer2) fuzz_fail("out of memory", NULL);
      r = afm_doc_read(out, out_size, &ro, buffer2, bytes2, &again);
      if (r == AFM_OK && fuzz_hash_doc(again) != h)
        fuzz_fail("read -> write -> read changes the document", NULL);
      free(buffer2);
    }
    if (r != AFM_OK) fuzz_fail("afm_doc_read refuses what afm_doc_write wrote", diag.message);
    afm_free(NULL, out);
    fuzz_player(doc, data, size);
  }
  free(buffer);
}

/* A copy of `data` with the chunk CRCs and the header CRC recomputed (as far
 * as the table lies inside the data); NULL when there is nothing to fix. */
static uint8_t *fuzz_fix_crcs(const uint8_t *data, size_t size) {
  uint8_t *copy;
  uint32_t n, i, crc;
  size_t header;
  if (size < 20 || memcmp(data, "\x89" "AFM\r\n\x1a\n", 8) != 0) return NULL;
  n = (uint32_t)data[12] | (uint32_t)data[13] << 8 | (uint32_t)data[14] << 16 |
      (uint32_t)data[15] << 24;
  if (n > (size - 20) / 20) return NULL;
  header = 16 + 20 * (size_t)n;
  copy = (uint8_t *)malloc(size);
  if (!copy) return NULL;
  memcpy(copy, data, size);
  for (i = 0; i < n; ++i) {
    uint8_t *e = copy + 16 + 20 * (size_t)i;
    uint32_t off = (uint32_t)e[8] | (uint32_t)e[9] << 8 | (uint32_t)e[10] << 16 | (uint32_t)e[11] << 24;
    uint32_t len = (uint32_t)e[12] | (uint32_t)e[13] << 8 | (uint32_t)e[14] << 16 |
                   (uint32_t)e[15] << 24;
    if (off > size || len > size - off) continue;
    crc = afm_crc32(copy + off, len);
    e[16] = (uint8_t)crc;
    e[17] = (uint8_t)(crc >> 8);
    e[18] = (uint8_t)(crc >> 16);
    e[19] = (uint8_t)(crc >> 24);
  }
  crc = afm_crc32(copy, header);
  copy[header] = (uint8_t)crc;
  copy[header + 1] = (uint8_t)(crc >> 8);
  copy[header + 2] = (uint8_t)(crc >> 16);
  copy[header + 3] = (uint8_t)(crc >> 24);
  if (memcmp(copy, data, size) == 0) {
    free(copy);
    return NULL;
  }
  return copy;
}

static void fuzz_afm_input(const uint8_t *data, size_t size, const afm_chunk_codec *draco) {
  uint8_t *fixed;
  fuzz_read(data, size, draco);
  fixed = fuzz_fix_crcs(data, size);
  if (fixed) {
    fuzz_read(fixed, size, draco);
    free(fixed);
  }
}

#endif /* AFM_FUZZ_H */
