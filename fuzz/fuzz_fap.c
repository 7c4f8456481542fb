/* libFuzzer target: the FAP stream reader (player_c/src/fap_stream.c).
 *
 * Input: one byte B, then (B & 15) chunk-size bytes, then the stream text.
 * Bit 4 of B sets AFM_FAP_V20_DIVIDE_BY_20. Seeds (fuzz/run.sh) are real .fap
 * files behind a zero byte.
 *
 * Checks, beyond what ASan and UBSan see:
 *   - afm_fap_parse counting (frames NULL) and filling agree on the result,
 *     the frame count and the error line;
 *   - with room for only half the frames it fails with
 *     AFM_ERR_BUFFER_TOO_SMALL, the count needed, and the same first frames;
 *   - the incremental reader, fed in chunks whose sizes come from the input
 *     (1..256 bytes, cycling; 1, 2, 3, ... when there are none), delivers the
 *     same frames, header, stats, result and error line as afm_fap_parse;
 *   - the frames go through afm_fap_state_apply and an
 *     afm_fap_cursor, seeking forwards and back.
 * A disagreement aborts with a message. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm/fap_stream.h"
#include "afm/player.h"

#define MAX_FRAMES 65536u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fail(const char *what) {
  fprintf(stderr, "fuzz_fap: %s\n", what);
  abort();
}

static int same_frame(const afm_fap_frame *a, const afm_fap_frame *b) {
  int k;
  if (a->number != b->number || a->line != b->line) return 0;
  for (k = 0; k <= AFM_FAP_COUNT; ++k)
    if (a->mask[k] != b->mask[k] || a->value[k] != b->value[k]) return 0;
  return a->viseme.select1 == b->viseme.select1 && a->viseme.select2 == b->viseme.select2 &&
         a->viseme.blend == b->viseme.blend && a->viseme.def == b->viseme.def &&
         a->expression.select1 == b->expression.select1 &&
         a->expression.intensity1 == b->expression.intensity1 &&
         a->expression.select2 == b->expression.select2 &&
         a->expression.intensity2 == b->expression.intensity2 &&
         a->expression.init_face == b->expression.init_face &&
         a->expression.def == b->expression.def;
}

static int same_header(const afm_fap_header *a, const afm_fap_header *b) {
  return a->version_major == b->version_major && a->version_minor == b->version_minor &&
         strcmp(a->name, b->name) == 0 && a->fps_num == b->fps_num &&
         a->fps_den == b->fps_den && a->frame_count == b->frame_count;
}

static int same_stats(const afm_fap_stats *a, const afm_fap_stats *b) {
  return a->frames == b->frames && a->clamped == b->clamped && a->rounded == b->rounded &&
         a->comment_lines == b->comment_lines && a->masks_69 == b->masks_69 &&
         a->single_visemes == b->single_visemes && a->skipped_values == b->skipped_values;
}

static void play(const afm_fap_frame *frames, uint32_t count, const afm_fap_header *h,
                 const uint8_t *sched, size_t n) {
  afm_fap_state state;
  afm_fap_cursor cursor;
  uint32_t i;
  uint64_t sink = 0;
  afm_fap_state_reset(&state);
  for (i = 0; i < count; ++i) {
    afm_fap_state_apply(&state, &frames[i], n ? sched[0] & 3u : 0u);
    sink += (uint32_t)state.value[3 + i % (AFM_FAP_COUNT - 2)];
  }
  if (count && h->fps_num && h->fps_den &&
      afm_fap_cursor_init(&cursor, frames, count, h->fps_num, h->fps_den, 0) == AFM_OK) {
    uint64_t d = afm_fap_cursor_duration_us(&cursor);
    uint64_t times[6];
    int k;
    times[0] = 0;
    times[1] = d / 3;
    times[2] = d + 1;
    times[3] = d / 2; /* back: rewinds and replays */
    times[4] = n > 1 ? (uint64_t)sched[1] * 40000u : 7;
    times[5] = (uint64_t)-1 / 2;
    for (k = 0; k < 6; ++k) {
      const afm_fap_state *a = NULL, *b = NULL;
      afm_q16 t = 0;
      if (afm_fap_cursor_seek(&cursor, times[k], &a, &b, &t) != AFM_OK) continue;
      if (!a) fail("afm_fap_cursor_seek gave no state");
      if (t < 0 || t > 65536) fail("afm_fap_cursor_seek: blend factor out of [0, 1]");
      sink += (uint32_t)a->value[3] + (b ? (uint32_t)b->value[68] : 0u);
    }
  }
  if (sink == 1) fputs("", stderr); /* keeps the reads */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  afm_fap_reader_options options;
  afm_fap_header h1, h2;
  afm_fap_stats s1, s2;
  afm_diag d1, d2;
  const uint8_t *sched, *text;
  size_t n, text_size;
  uint32_t count = 0, count2 = 0, got = 0;
  afm_result r1, r2;
  afm_fap_frame *frames;
  afm_fap_reader *reader;
  afm_fap_frame frame;
  int has_frame = 0;

  if (size < 1) return 0;
  n = data[0] & 15u;
  if (n > size - 1) n = size - 1;
  sched = data + 1;
  text = data + 1 + n;
  text_size = size - 1 - n;
  memset(&options, 0, sizeof options);
  if (data[0] & 16u) options.flags = AFM_FAP_V20_DIVIDE_BY_20;

  memset(&h1, 0, sizeof h1);
  memset(&d1, 0, sizeof d1);
  r1 = afm_fap_parse(text, text_size, &options, NULL, 0, &count, &h1, &s1, &d1);
  if (count > MAX_FRAMES) return 0;
  frames = (afm_fap_frame *)malloc((count ? count : 1) * sizeof *frames);
  if (!frames) return 0;
  memset(&h2, 0, sizeof h2);
  memset(&d2, 0, sizeof d2);
  r2 = afm_fap_parse(text, text_size, &options, frames, count, &count2, &h2, &s2, &d2);
  if (r1 != r2 || count != count2 || d1.line != d2.line)
    fail("afm_fap_parse: counting and reading disagree");
  if (!same_header(&h1, &h2) || !same_stats(&s1, &s2))
    fail("afm_fap_parse: counting and reading give other headers or stats");

  if (r1 == AFM_OK && count >= 2) {
    uint32_t half = count / 2, need = 0, i;
    afm_fap_frame *part = (afm_fap_frame *)malloc(half * sizeof *part);
    if (part) {
      afm_result r = afm_fap_parse(text, text_size, &options, part, half, &need, NULL, NULL, NULL);
      if (r != AFM_ERR_BUFFER_TOO_SMALL || need != count)
        fail("afm_fap_parse with too few frames: not AFM_ERR_BUFFER_TOO_SMALL with the count");
      for (i = 0; i < half; ++i)
        if (!same_frame(&part[i], &frames[i])) fail("afm_fap_parse with too few frames: other frames");
      free(part);
    }
  }

  /* The incremental reader. */
  reader = (afm_fap_reader *)malloc(sizeof *reader);
  if (!reader) {
    free(frames);
    return 0;
  }
  memset(&d2, 0, sizeof d2);
  afm_fap_reader_init(reader, &options, &d2);
  {
    size_t pos = 0, k = 0;
    afm_result r = AFM_OK;
    while (r == AFM_OK && pos < text_size) {
      size_t chunk = n ? (size_t)sched[k % n] + 1 : k % 17 + 1;
      size_t off = 0;
      ++k;
      if (chunk > text_size - pos) chunk = text_size - pos;
      while (r == AFM_OK && off < chunk) {
        size_t consumed = 0;
        r = afm_fap_reader_feed(reader, text + pos + off, chunk - off, &consumed, &frame, &has_frame);
        if (consumed > chunk - off) fail("afm_fap_reader_feed consumed more than it was given");
        if (r != AFM_OK) break;
        if (has_frame) {
          if (got >= count2 || !same_frame(&frame, &frames[got]))
            fail("the incremental reader delivers another frame than afm_fap_parse");
          ++got;
        } else if (consumed != chunk - off) {
          fail("afm_fap_reader_feed stopped early without a frame");
        }
        off += consumed;
      }
      pos += chunk;
    }
    while (r == AFM_OK) {
      r = afm_fap_reader_finish(reader, &frame, &has_frame);
      if (r != AFM_OK || !has_frame) break;
      if (got >= count2 || !same_frame(&frame, &frames[got]))
        fail("the incremental reader delivers another frame than afm_fap_parse (at the end)");
      ++got;
    }
    if (r != r1) fail("the incremental reader and afm_fap_parse give other results");
    if (r != AFM_OK && d2.line != d1.line)
      fail("the incremental reader and afm_fap_parse name other error lines");
    if (got != count2) fail("the incremental reader delivers another number of frames");
    if (r == AFM_OK) {
      size_t taken = 0;
      const afm_fap_header *h = afm_fap_reader_header(reader);
      if (!h || !same_header(h, &h1)) fail("the incremental reader reads another header");
      if (!same_stats(afm_fap_reader_stats(reader), &s1))
        fail("the incremental reader counts other stats");
      if (afm_fap_reader_feed(reader, text, text_size, &taken, &frame, &has_frame) != AFM_ERR_STATE)
        fail("feeding a finished reader is not AFM_ERR_STATE");
    }
  }
  if (r1 == AFM_OK) play(frames, count, &h1, sched, n);
  free(reader);
  free(frames);
  return 0;
}
