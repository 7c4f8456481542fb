/* FAP semantics: persistence, mirroring, and walking a stream in time. */
#include <string.h>

#include "afm/player.h"

/* Left/right pairs: (left, right). Each pair's positive directions mirror
 * each other (mpeg4-fap-table.csv), so a symmetric motion has equal values. */
static const uint8_t kLeftRight[][2] = {
    {6, 7},   {8, 9},   {10, 11}, {12, 13}, {19, 20}, {21, 22}, {23, 24}, {25, 26},
    {27, 28}, {29, 30}, {31, 32}, {33, 34}, {35, 36}, {37, 38}, {39, 40}, {41, 42},
    {53, 54}, {55, 56}, {57, 58}, {59, 60}, {61, 62}, {65, 66}, {67, 68}};

/* Inner/outer lip pairs: (inner, outer), same FDP positions on the two
 * contours and the same directions. */
static const uint8_t kInnerOuter[][2] = {{4, 51},  {5, 52},  {6, 53},  {7, 54},  {8, 55},
                                         {9, 56},  {10, 57}, {11, 58}, {12, 59}, {13, 60}};

void afm_fap_state_reset(afm_fap_state *state) { memset(state, 0, sizeof *state); }

static void mirror(afm_fap_state *s, uint8_t sent[AFM_FAP_COUNT + 1], const uint8_t (*pairs)[2],
                   size_t n) {
  size_t i;
  for (i = 0; i < n; ++i) {
    uint8_t a = pairs[i][0], b = pairs[i][1];
    if (sent[a] && !sent[b]) {
      s->value[b] = s->value[a];
      sent[b] = 1;
    } else if (sent[b] && !sent[a]) {
      s->value[a] = s->value[b];
      sent[a] = 1;
    }
  }
}

void afm_fap_state_apply(afm_fap_state *state, const afm_fap_frame *frame, uint32_t mirror_flags) {
  uint8_t sent[AFM_FAP_COUNT + 1];
  int f;
  memcpy(sent, frame->mask, sizeof sent);
  for (f = 3; f <= AFM_FAP_COUNT; ++f)
    if (sent[f]) state->value[f] = frame->value[f];
  if (sent[1]) state->viseme = frame->viseme;
  if (sent[2]) state->expression = frame->expression;
  /* Left/right first, so that a one-sided inner-lip FAP reaches all four. */
  if (mirror_flags & AFM_MIRROR_LEFT_RIGHT)
    mirror(state, sent, kLeftRight, sizeof kLeftRight / sizeof kLeftRight[0]);
  if (mirror_flags & AFM_MIRROR_INNER_OUTER)
    mirror(state, sent, kInnerOuter, sizeof kInnerOuter / sizeof kInnerOuter[0]);
}

/* ---- cursor ------------------------------------------------------------------ */

/* Microseconds from frame 0 to frame i: (n_i - n_0) * fps_den / fps_num
 * seconds, split into whole and fractional seconds so that no product
 * passes 64 bits. */
static uint64_t frame_time_us(const afm_fap_cursor *c, uint32_t i) {
  uint64_t ticks = (uint64_t)(c->frames[i].number - c->frames[0].number) * c->fps_den;
  return ticks / c->fps_num * 1000000u + ticks % c->fps_num * 1000000u / c->fps_num;
}

static void rewind_cursor(afm_fap_cursor *c) {
  afm_fap_state_reset(&c->before);
  afm_fap_state_apply(&c->before, &c->frames[0], c->mirror_flags);
  c->before_us = 0;
  c->next = 1;
  c->has_after = c->count > 1;
  if (c->has_after) {
    c->after = c->before;
    afm_fap_state_apply(&c->after, &c->frames[1], c->mirror_flags);
    c->after_us = frame_time_us(c, 1);
  }
}

afm_result afm_fap_cursor_init(afm_fap_cursor *c, const afm_fap_frame *frames, uint32_t count,
                               uint32_t fps_num, uint32_t fps_den, uint32_t mirror_flags) {
  uint32_t i;
  if (!c || !frames || count == 0 || fps_num == 0 || fps_den == 0) return AFM_ERR_ARGUMENT;
  for (i = 1; i < count; ++i)
    if (frames[i].number <= frames[i - 1].number) return AFM_ERR_ARGUMENT;
  memset(c, 0, sizeof *c);
  c->frames = frames;
  c->count = count;
  c->fps_num = fps_num;
  c->fps_den = fps_den;
  c->mirror_flags = mirror_flags;
  rewind_cursor(c);
  return AFM_OK;
}

afm_result afm_fap_cursor_seek(afm_fap_cursor *c, uint64_t time_us, const afm_fap_state **a,
                               const afm_fap_state **b, afm_q16 *t) {
  if (!c || !c->frames || !a || !b || !t) return AFM_ERR_ARGUMENT;
  if (time_us < c->before_us) rewind_cursor(c);
  /* Apply every frame up to the time: none is skipped. */
  while (c->has_after && c->after_us <= time_us) {
    c->before = c->after;
    c->before_us = c->after_us;
    c->next++;
    c->has_after = c->next < c->count;
    if (c->has_after) {
      afm_fap_state_apply(&c->after, &c->frames[c->next], c->mirror_flags);
      c->after_us = frame_time_us(c, c->next);
    }
  }
  *a = &c->before;
  if (!c->has_after) {
    *b = &c->before;
    *t = 0;
    return AFM_OK;
  }
  *b = &c->after;
  /* (time - before) < (after - before): the quotient is in [0, 65536). */
  *t = (afm_q16)(((time_us - c->before_us) << 16) / (c->after_us - c->before_us));
  return AFM_OK;
}

uint64_t afm_fap_cursor_duration_us(const afm_fap_cursor *c) {
  return c && c->count ? frame_time_us(c, c->count - 1) : 0;
}
