/* afm_hash: the player core's output as hashes, one line per frame.
 *
 *   afm_hash FACE.afm [STREAM.fap ...]
 *
 * The target-side driver of the ARM test (tests/cli/test_arm.sh): built from
 * the core sources alone (formats/src, player_c/src) for the host and for
 * ARMv5TE soft-float, at several optimisation levels. Every build must print
 * the same lines, so every hash is over values fed one by one at their own
 * width (never over memory): the output does not depend on byte order, word
 * size, struct layout or pointers.
 *
 * Output (pose=HASH nd=HASH: the default player's outputs and those of the
 * one with AFM_PLAYER_NORMAL_DELTAS):
 *   afm NAME V=... T=... parts=... targets=... rigids=... doc=HASH   the document
 *   pose init HASH nd=HASH                   the players as init leaves them
 *   pose neutral pose=HASH nd=HASH           the neutral state posed
 *   fap FILE: version ... frames=... stats ... HASH          one per stream
 *   frame I NUMBER fap=HASH state=HASH pose=HASH nd=HASH     one per stream frame
 *   render K TIME_US t=T pose=HASH nd=HASH   the stream at 30 fps, states blended
 *   error ...                                a refused file
 * Lines starting with '#' are facts that differ between builds (buffer sizes
 * that hold pointers); the comparison ignores them.
 *
 * Exit status: 0 when every file was hashed or refused cleanly, 1 when the
 * driver's own cross-checks fail (the incremental FAP reader disagreeing with
 * the whole-buffer one), 2 on bad usage or an unreadable file.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm/format.h"
#include "afm/fap_stream.h"
#include "afm/player.h"
#include "../common/afm_doc_hash.h"

/* ---- files ------------------------------------------------------------------ */

static uint8_t *read_file(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  uint8_t *data = NULL;
  size_t used = 0, capacity = 0;
  if (!f) return NULL;
  for (;;) {
    size_t n;
    if (used == capacity) {
      size_t grown = capacity ? 2 * capacity : 65536;
      uint8_t *p = (uint8_t *)realloc(data, grown);
      if (!p) break;
      data = p;
      capacity = grown;
    }
    n = fread(data + used, 1, capacity - used, f);
    used += n;
    if (n == 0) {
      if (ferror(f)) break;
      fclose(f);
      *size = used;
      return data ? data : (uint8_t *)malloc(1);
    }
  }
  free(data);
  fclose(f);
  return NULL;
}

static const char *base_name(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

/* ---- the player's outputs ------------------------------------------------ */

/* Everything a pose produces, as printed hex. */
static const char *pose_hex(const afm_player *player, const afm_doc *doc, char *hex) {
  size_t V = doc->geometry.vertex_count;
  const afm_pose_info *info = afm_player_info(player);
  hasher s;
  hash_init(&s);
  hash_i32s(&s, afm_player_positions(player), 3 * V);
  hash_i16s(&s, afm_player_normals(player), 3 * V);
  hash_i16s(&s, afm_player_weights(player), doc->target_count);
  hash_u32(&s, info->active_targets);
  hash_u32(&s, info->updates);
  hash_u32(&s, info->clamped_weights);
  hash_u32(&s, info->weight_shift);
  return hash_hex(&s, hex);
}

/* Two players: the default (normals recomputed) and AFM_PLAYER_NORMAL_DELTAS. */
typedef struct players {
  afm_player *plain, *deltas;
  void *buffers[2];
} players;

static int players_init(players *p, const afm_doc *doc) {
  afm_player_options options[2];
  afm_player **out[2];
  int k;
  memset(p, 0, sizeof *p);
  memset(options, 0, sizeof options);
  options[1].flags = AFM_PLAYER_NORMAL_DELTAS;
  out[0] = &p->plain;
  out[1] = &p->deltas;
  for (k = 0; k < 2; ++k) {
    size_t bytes = 0;
    afm_result r = afm_player_measure(doc, &options[k], &bytes);
    if (r == AFM_OK) {
      p->buffers[k] = malloc(bytes ? bytes : 1);
      r = p->buffers[k] ? afm_player_init(doc, &options[k], p->buffers[k], bytes, out[k])
                        : AFM_ERR_OUT_OF_MEMORY;
    }
    if (r != AFM_OK) {
      printf("error player init (%s): %s\n", k ? "normal deltas" : "default",
             afm_result_string(r));
      return 0;
    }
    printf("# ram player%s=%lu\n", k ? "_normal_deltas" : "", (unsigned long)bytes);
  }
  return 1;
}

static void players_free(players *p) {
  free(p->buffers[0]);
  free(p->buffers[1]);
}

/* Poses both players; appends " pose=H nd=H" to the current line. */
static int pose_line(players *p, const afm_doc *doc, const afm_fap_state *a,
                     const afm_fap_state *b, afm_q16 t) {
  char hex[17];
  afm_result r = afm_player_pose(p->plain, a, b, t);
  if (r == AFM_OK) {
    printf(" pose=%s", pose_hex(p->plain, doc, hex));
    r = afm_player_pose(p->deltas, a, b, t);
  }
  if (r == AFM_OK) printf(" nd=%s", pose_hex(p->deltas, doc, hex));
  if (r != AFM_OK) printf(" pose-error=%s", afm_result_string(r));
  return r == AFM_OK;
}

/* ---- FAP streams ------------------------------------------------------------ */

static void hash_frame(hasher *s, const afm_fap_frame *f) {
  int k;
  hash_u32(s, f->number);
  hash_u32(s, f->line);
  for (k = 1; k <= AFM_FAP_COUNT; ++k) hash_u8(s, f->mask[k]);
  for (k = 3; k <= AFM_FAP_COUNT; ++k) hash_i32(s, f->value[k]);
  if (f->mask[1]) {
    hash_u8(s, f->viseme.select1);
    hash_u8(s, f->viseme.select2);
    hash_u8(s, f->viseme.blend);
    hash_u8(s, f->viseme.def);
  }
  if (f->mask[2]) {
    hash_u8(s, f->expression.select1);
    hash_u8(s, f->expression.intensity1);
    hash_u8(s, f->expression.select2);
    hash_u8(s, f->expression.intensity2);
    hash_u8(s, f->expression.init_face);
    hash_u8(s, f->expression.def);
  }
}

/* What the player keeps of the stream after a frame. */
static void hash_state(hasher *s, const afm_fap_state *state) {
  hash_i32s(s, state->value, AFM_FAP_COUNT + 1);
  hash_u8(s, state->viseme.select1);
  hash_u8(s, state->viseme.select2);
  hash_u8(s, state->viseme.blend);
  hash_u8(s, state->expression.select1);
  hash_u8(s, state->expression.intensity1);
  hash_u8(s, state->expression.select2);
  hash_u8(s, state->expression.intensity2);
}

static uint64_t frame_hash(const afm_fap_frame *f) {
  hasher s;
  hash_init(&s);
  hash_frame(&s, f);
  return s.h;
}

static void hash_fap_header(hasher *s, const afm_fap_header *h) {
  hash_u8(s, h->version_major);
  hash_u8(s, h->version_minor);
  hash_bytes(s, h->name, strlen(h->name) + 1);
  hash_u32(s, h->fps_num);
  hash_u32(s, h->fps_den);
  hash_u32(s, h->frame_count);
}

/* The incremental reader, fed in chunks of 1, 2, 3, 5, 8, ... 233 bytes
 * (cycling), must deliver the frames, stats and result the whole-buffer
 * parse did (on a refused file: the same result and error line). Returns 1
 * when it does. */
static int check_incremental(const uint8_t *data, size_t size, const afm_fap_frame *frames,
                             uint32_t count, afm_result expected, uint32_t expected_line,
                             const afm_fap_stats *stats) {
  static const size_t chunks[] = {1, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144, 233};
  afm_fap_reader *reader = (afm_fap_reader *)malloc(sizeof *reader);
  afm_fap_frame frame;
  afm_diag diag;
  size_t pos = 0, k = 0;
  uint32_t got = 0;
  afm_result r = AFM_OK;
  int has_frame = 0, ok = 1;
  if (!reader) return 0;
  memset(&diag, 0, sizeof diag);
  afm_fap_reader_init(reader, NULL, &diag);
  while (r == AFM_OK && pos < size) {
    size_t n = chunks[k++ % (sizeof chunks / sizeof chunks[0])];
    size_t offset = 0;
    if (n > size - pos) n = size - pos;
    /* A frame ends the call early: feed the rest of the chunk again. */
    while (r == AFM_OK && offset < n) {
      size_t consumed = 0;
      r = afm_fap_reader_feed(reader, data + pos + offset, n - offset, &consumed, &frame,
                              &has_frame);
      if (r != AFM_OK) break;
      if (has_frame) {
        if (expected == AFM_OK && (got >= count || frame_hash(&frame) != frame_hash(&frames[got])))
          ok = 0;
        ++got;
      } else if (consumed == 0) {
        ok = 0; /* no progress and no frame */
        break;
      }
      offset += consumed;
    }
    if (!ok) break;
    pos += n;
  }
  while (ok && r == AFM_OK) {
    r = afm_fap_reader_finish(reader, &frame, &has_frame);
    if (r != AFM_OK || !has_frame) break;
    if (expected == AFM_OK && (got >= count || frame_hash(&frame) != frame_hash(&frames[got])))
      ok = 0;
    ++got;
  }
  if (ok && (r != expected || (r == AFM_OK && got != count))) ok = 0;
  if (ok && r != AFM_OK && diag.line != expected_line) ok = 0;
  if (ok && r == AFM_OK && memcmp(afm_fap_reader_stats(reader), stats, sizeof *stats) != 0)
    ok = 0;
  free(reader);
  return ok;
}

static int play_stream(const char *path, const afm_doc *doc, players *p) {
  size_t size = 0;
  uint8_t *data = read_file(path, &size);
  afm_fap_frame *frames = NULL;
  afm_fap_header header;
  afm_fap_stats stats;
  afm_diag diag;
  uint32_t count = 0, i;
  afm_result r;
  hasher all;
  char hex[17];
  int ok = 1;
  if (!data) {
    fprintf(stderr, "afm_hash: cannot read %s\n", path);
    return 2;
  }
  memset(&header, 0, sizeof header);
  memset(&stats, 0, sizeof stats);
  memset(&diag, 0, sizeof diag);
  r = afm_fap_parse(data, size, NULL, NULL, 0, &count, NULL, NULL, &diag);
  if (r == AFM_OK) {
    frames = (afm_fap_frame *)malloc((count ? count : 1) * sizeof *frames);
    if (!frames) {
      free(data);
      fprintf(stderr, "afm_hash: out of memory\n");
      return 2;
    }
    memset(&diag, 0, sizeof diag);
    r = afm_fap_parse(data, size, NULL, frames, count, &count, &header, &stats, &diag);
  }
  if (!check_incremental(data, size, frames, r == AFM_OK ? count : 0, r, diag.line, &stats)) {
    printf("error %s: the incremental reader disagrees with afm_fap_parse\n", base_name(path));
    ok = 0;
  }
  if (r != AFM_OK) {
    printf("error %s: %s, line %lu: %s\n", base_name(path), afm_result_string(r),
           (unsigned long)diag.line, diag.message);
    free(frames);
    free(data);
    return ok ? 0 : 1;
  }
  printf("# ram %s: file=%lu frames=%lu (%lu x %lu) reader=%lu\n", base_name(path),
         (unsigned long)size, (unsigned long)(count * sizeof *frames), (unsigned long)count,
         (unsigned long)sizeof *frames, (unsigned long)sizeof(afm_fap_reader));

  hash_init(&all);
  hash_fap_header(&all, &header);
  for (i = 0; i < count; ++i) hash_frame(&all, &frames[i]);
  printf("fap %s: version %u.%u fps %lu/%lu frames=%lu (header %lu) clamped=%lu rounded=%lu "
         "comments=%lu masks69=%lu single_visemes=%lu skipped=%lu %s\n",
         base_name(path), (unsigned)header.version_major, (unsigned)header.version_minor,
         (unsigned long)header.fps_num, (unsigned long)header.fps_den, (unsigned long)count,
         (unsigned long)header.frame_count, (unsigned long)stats.clamped,
         (unsigned long)stats.rounded, (unsigned long)stats.comment_lines,
         (unsigned long)stats.masks_69, (unsigned long)stats.single_visemes,
         (unsigned long)stats.skipped_values, hash_hex(&all, hex));

  {
    afm_fap_state state;
    afm_fap_cursor cursor;
    afm_fap_state_reset(&state);
    for (i = 0; i < count; ++i) {
      hasher s;
      hash_init(&s);
      hash_frame(&s, &frames[i]);
      printf("frame %lu %lu fap=%s", (unsigned long)i, (unsigned long)frames[i].number,
             hash_hex(&s, hex));
      /* ---- per-frame player output: the state after this frame, posed ---- */
      afm_fap_state_apply(&state, &frames[i], 0);
      hash_init(&s);
      hash_state(&s, &state);
      printf(" state=%s", hash_hex(&s, hex));
      if (!pose_line(p, doc, &state, NULL, 0)) ok = 0;
      printf("\n");
    }
    /* ---- the stream played in time: 30 renders a second, states blended ---- */
    if (count > 0 && header.fps_num > 0 && header.fps_den > 0) {
      r = afm_fap_cursor_init(&cursor, frames, count, header.fps_num, header.fps_den, 0);
      if (r == AFM_OK) {
        uint64_t duration = afm_fap_cursor_duration_us(&cursor), k;
        for (k = 0; r == AFM_OK; ++k) {
          uint64_t t_us = k * 1000000u / 30u;
          const afm_fap_state *a = NULL, *b = NULL;
          afm_q16 t = 0;
          if (t_us > duration + 1000000u / 30u) break; /* one render past the end */
          r = afm_fap_cursor_seek(&cursor, t_us, &a, &b, &t);
          if (r != AFM_OK) break;
          printf("render %lu %lu t=%ld", (unsigned long)k, (unsigned long)t_us, (long)t);
          if (!pose_line(p, doc, a, b, t)) ok = 0;
          printf("\n");
        }
      }
      if (r != AFM_OK) {
        printf("error %s: cursor: %s\n", base_name(path), afm_result_string(r));
        ok = 0;
      }
    }
  }
  free(frames);
  free(data);
  return ok ? 0 : 1;
}

/* ---- main ------------------------------------------------------------------- */

int main(int argc, char **argv) {
  size_t size = 0, bytes = 0;
  uint8_t *data;
  void *buffer;
  afm_doc *doc = NULL;
  afm_read_options ro;
  afm_diag diag;
  afm_result r;
  hasher s;
  char hex[17];
  int i, status = 0;
  players p;

  if (argc < 2 || argv[1][0] == '-') {
    fprintf(stderr, "usage: afm_hash FACE.afm [STREAM.fap ...]\n");
    return 2;
  }
  data = read_file(argv[1], &size);
  if (!data) {
    fprintf(stderr, "afm_hash: cannot read %s\n", argv[1]);
    return 2;
  }
  memset(&ro, 0, sizeof ro);
  memset(&diag, 0, sizeof diag);
  ro.diag = &diag;
  r = afm_doc_measure(data, size, &ro, &bytes);
  if (r != AFM_OK) {
    printf("error %s: %s: %s\n", base_name(argv[1]), afm_result_string(r), diag.message);
    free(data);
    return 0;
  }
  buffer = malloc(bytes ? bytes : 1);
  if (!buffer) {
    fprintf(stderr, "afm_hash: out of memory\n");
    free(data);
    return 2;
  }
  r = afm_doc_read(data, size, &ro, buffer, bytes, &doc);
  if (r != AFM_OK) {
    printf("error %s: %s: %s\n", base_name(argv[1]), afm_result_string(r), diag.message);
    free(buffer);
    free(data);
    return 0;
  }
  free(data); /* nothing in the document points into the file */
  printf("# ram afm %s: file=%lu doc=%lu\n", base_name(argv[1]), (unsigned long)size,
         (unsigned long)bytes);
  hash_init(&s);
  hash_doc(&s, doc);
  hash_u32(&s, doc->skipped_chunks);
  printf("afm %s V=%lu T=%lu parts=%lu targets=%lu rigids=%lu doc=%s\n", base_name(argv[1]),
         (unsigned long)doc->geometry.vertex_count, (unsigned long)doc->geometry.triangle_count,
         (unsigned long)doc->geometry.part_count, (unsigned long)doc->target_count,
         (unsigned long)doc->rigid_count, hash_hex(&s, hex));

  if (!players_init(&p, doc)) {
    players_free(&p);
    free(buffer);
    return 1;
  }
  {
    afm_fap_state neutral;
    /* As init leaves them, then the neutral state posed. */
    printf("pose init %s", pose_hex(p.plain, doc, hex));
    printf(" nd=%s\n", pose_hex(p.deltas, doc, hex));
    afm_fap_state_reset(&neutral);
    printf("pose neutral");
    if (!pose_line(&p, doc, &neutral, NULL, 0)) status = 1;
    printf("\n");
  }

  for (i = 2; i < argc; ++i) {
    int st = play_stream(argv[i], doc, &p);
    if (st > status) status = st;
  }
  players_free(&p);
  free(buffer);
  return status;
}
