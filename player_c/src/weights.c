/* FAP state -> morph target weights (Q12). A FAP side with one target:
 * weight = value / reference. With in-betweens (targets at references
 * r1 < r2 < ... on one side, formats/afm.md): piecewise linear, the value
 * blends the two targets around it, and beyond the farthest the last
 * segment extrapolates. A combination target (since 1.4) takes the weight
 * of the FAP target it follows, capped by its gate FAP's value / gate
 * reference, and never below 0. */
#include "player_internal.h"

/* In 64 bits: -INT32_MIN does not fit 32. */
static int64_t magnitude(int32_t reference) { return reference < 0 ? -(int64_t)reference : reference; }

/* Inserts target `index` into the chain starting at *head, ordered by
 * |reference| (the parser rejects equal references on one side). */
static void add_to_chain(afm_player *p, int32_t *head, int32_t index) {
  const afm_target *targets = p->doc->targets;
  const int64_t r = magnitude(targets[index].reference);
  while (*head >= 0 && magnitude(targets[*head].reference) < r) head = &p->next_target[*head];
  p->next_target[index] = *head;
  *head = index;
}

static void add_lookup(int32_t *table, int32_t index) {
  if (*table < 0) *table = index; /* the first target of a kind wins */
}

void afm_weights_init(afm_player *p) {
  const afm_doc *doc = p->doc;
  uint32_t i, k;
  for (i = 0; i <= AFM_FAP_COUNT; ++i) p->fap_positive[i] = p->fap_negative[i] = -1;
  for (i = 0; i < AFM_VISEME_COUNT; ++i) p->viseme[i] = -1;
  for (i = 0; i < AFM_EXPRESSION_COUNT; ++i) p->expression[i] = -1;
  for (i = 0; i < doc->target_count; ++i) {
    const afm_target *t = &doc->targets[i];
    int32_t m = 0;
    p->next_target[i] = -1;
    if (t->kind == AFM_TARGET_FAP && t->number <= AFM_FAP_COUNT)
      add_to_chain(p, t->reference > 0 ? &p->fap_positive[t->number] : &p->fap_negative[t->number],
                   (int32_t)i);
    else if (t->kind == AFM_TARGET_VISEME && t->number < AFM_VISEME_COUNT)
      add_lookup(&p->viseme[t->number], (int32_t)i);
    else if (t->kind == AFM_TARGET_EXPRESSION && t->number < AFM_EXPRESSION_COUNT)
      add_lookup(&p->expression[t->number], (int32_t)i);
    else if (t->kind == AFM_TARGET_COMBINATION) {
      /* Not in any chain: next_target holds the FAP target it follows
       * (the reader checked that there is one). */
      uint32_t j;
      for (j = 0; j < doc->target_count; ++j)
        if (doc->targets[j].kind == AFM_TARGET_FAP && doc->targets[j].number == t->number &&
            doc->targets[j].reference == t->reference)
          p->next_target[i] = (int32_t)j;
    }
    for (k = 0; k < t->delta_count; ++k) {
      int32_t d[6];
      int c;
      d[0] = t->dx[k], d[1] = t->dy[k], d[2] = t->dz[k];
      d[3] = t->nx ? t->nx[k] : 0, d[4] = t->ny ? t->ny[k] : 0, d[5] = t->nz ? t->nz[k] : 0;
      for (c = 0; c < 6; ++c) {
        int32_t a = d[c] < 0 ? -d[c] : d[c];
        if (a > m) m = a;
      }
    }
    p->max_delta[i] = m;
  }
}

int32_t afm_lerp_value(int32_t a, int32_t b, afm_q16 t) {
  /* |b - a| < 2^32 and t <= 2^16: the product fits 49 bits. */
  return (int32_t)(a + afm_round_shift64(((int64_t)b - a) * t, 16));
}

/* Adds numerator / reference (Q12, rounded half away from zero) to a
 * target's weight. |numerator| < 2^32 and 4096 = 2^12: the product is below
 * 2^44. Each term is clamped to 2^24 (a weight of 4096, far past the Q12
 * range the kernel saturates to), so a sum of a few stays in 32 bits. */
static int32_t q12_ratio(int64_t numerator, int64_t reference) {
  int64_t num = numerator * AFM_Q12_ONE, den = reference, q;
  if (den < 0) num = -num, den = -den;
  q = (num >= 0 ? num + den / 2 : num - den / 2) / den; /* C99 division truncates */
  if (q > ((int64_t)1 << 24)) q = (int64_t)1 << 24;
  if (q < -((int64_t)1 << 24)) q = -((int64_t)1 << 24);
  return (int32_t)q;
}

static void add_weight(int32_t *w, int32_t target, int64_t numerator, int64_t reference) {
  if (target < 0 || numerator == 0 || reference == 0) return;
  w[target] += q12_ratio(numerator, reference);
}

/* Q12 weights of one state, summed into w[targets]. */
static void state_weights(const afm_player *p, const afm_fap_state *s, int32_t *w) {
  const afm_doc *doc = p->doc;
  int f;
  for (f = 3; f <= AFM_FAP_COUNT; ++f) {
    int32_t v = s->value[f], t;
    if (v == 0) continue;
    /* A negative value takes the FAP's negative-side targets when there
     * are some, else extrapolates the positive side's first segment. */
    t = v < 0 && p->fap_negative[f] >= 0 ? p->fap_negative[f] : p->fap_positive[f];
    if (t < 0) continue;
    {
      /* The segment around v: from the previous reference (0 and no
       * target at first) to the first reference at or past v, or the last
       * segment beyond the farthest. References and values are int32, so
       * the differences fit 33 bits and add_weight's bounds hold. */
      int32_t prev = -1;
      int64_t r0 = 0, r1 = doc->targets[t].reference;
      const int64_t along = r1 > 0 ? v : -(int64_t)v; /* v along the side's sense */
      while (p->next_target[t] >= 0 && along > magnitude(doc->targets[t].reference)) {
        prev = t, r0 = r1;
        t = p->next_target[t];
        r1 = doc->targets[t].reference;
      }
      add_weight(w, t, v - r0, r1 - r0);
      if (prev >= 0) add_weight(w, prev, r1 - v, r1 - r0);
    }
  }
  if (s->viseme.select1 < AFM_VISEME_COUNT)
    add_weight(w, p->viseme[s->viseme.select1], s->viseme.blend, 63);
  if (s->viseme.select2 < AFM_VISEME_COUNT)
    add_weight(w, p->viseme[s->viseme.select2], 63 - s->viseme.blend, 63);
  if (s->expression.select1 < AFM_EXPRESSION_COUNT)
    add_weight(w, p->expression[s->expression.select1], s->expression.intensity1, 63);
  if (s->expression.select2 < AFM_EXPRESSION_COUNT)
    add_weight(w, p->expression[s->expression.select2], s->expression.intensity2, 63);
  {
    /* Combinations, after every FAP target's weight: the followed one's
     * (a chain weight, |w| <= 2^25 from add_weight's clamp) capped by the
     * gate's own Q12 ratio; both in 32 bits, min and max exact. */
    uint32_t i;
    for (i = 0; i < doc->target_count; ++i) {
      const afm_target *t = &doc->targets[i];
      int32_t follow = p->next_target[i], gate, c;
      if (t->kind != AFM_TARGET_COMBINATION) continue;
      if (follow < 0 || t->gate > AFM_FAP_COUNT || t->gate_reference == 0) continue; /* not from the reader */
      gate = s->value[t->gate] ? q12_ratio(s->value[t->gate], t->gate_reference) : 0;
      c = w[follow] < gate ? w[follow] : gate;
      if (c > 0) w[i] += c;
    }
  }
}

int64_t afm_pose_weights(afm_player *p, const afm_fap_state *a, const afm_fap_state *b, afm_q16 t) {
  int32_t *wa = p->weight_scratch, *wb = p->weight_scratch + p->target_count;
  int64_t bound = 0;
  uint32_t i;
  for (i = 0; i < 2 * p->target_count; ++i) wa[i] = 0;
  state_weights(p, a, wa);
  if (t) state_weights(p, b, wb);
  for (i = 0; i < p->target_count; ++i) {
    int32_t w = t ? afm_lerp_value(wa[i], wb[i], t) : wa[i];
    int32_t c = afm_saturate16(w); /* weights within [-8, 8) */
    if (c != w) p->info.clamped_weights++;
    p->weights[i] = (afm_q12)c;
    if (c) {
      p->info.active_targets++;
      p->info.updates += p->doc->targets[i].delta_count;
      bound += (int64_t)(c < 0 ? -c : c) * p->max_delta[i];
    }
  }
  return bound;
}
