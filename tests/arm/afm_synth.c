/* afm_synth: gives a neutral AFM synthetic morph targets and rigid parts.
 *
 *   afm_synth [--lift] IN.afm OUT.afm
 *
 * A host-side test helper (not part of the core). Where afm-import
 * --analytic makes plausible stand-in targets, this one aims at coverage of
 * the player's arithmetic for the ARM/x86 comparison and the fuzz seeds:
 * normal deltas on alternate targets, negative-side targets on every third
 * bidirectional FAP, and a left eye whose axes are not the identity.
 * Deterministic: the same input gives the same file.
 *
 * Morph targets, all on the skin part (smooth bumps around FDP vertices,
 * weight (1 - r^2/R^2)^2 within R = 0.4 ES0):
 *   - every translating FAP 3..68 whose FDP sits on the skin: reference 256,
 *     the bump moved 0.1 FAPU-distance along the FAP's direction; normal
 *     deltas on even FAPs; a negative-side target (reference -256, another
 *     shape) on every third bidirectional FAP; an in-between at 640 (the
 *     bump further along and turned) on every fourth FAP, and on every
 *     other of those a combination at 640 gated by FAP 3 at 512;
 *   - visemes 1..14 and expressions 1..6 (reference 63): mixes of bumps around
 *     the lips, mouth corners and eyebrows.
 * --lift: the targets move control points instead (formats/afm.md, LIFT):
 * control c samples skin vertex 2c, and skin vertex i is bound to controls
 * i/2, i/2 + 1 and i/2 + 5 (wrapped) with weights that vary from vertex to
 * vertex, all three nonzero on most. Not a plausible face: coverage of the
 * lift's arithmetic (no normal deltas then, as LIFT requires).
 * Rigid parts: both eyeballs (FAPs 23..28; the left eye's axes turned 5
 * degrees), the jaw (FAPs 3, 14, 15 on the lower teeth and tongue) and the
 * head (FAPs 48..50, every part), as formats/afm.md describes them.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm/format.h"
#include "afm/mpeg4.h"

#define MAX_TARGETS 192

typedef struct synth {
  const afm_doc *in;
  const afm_part *skin;
  double es0_q; /* ES0 in position quanta */
  afm_target targets[MAX_TARGETS];
  uint32_t target_count;
  double *weight; /* [skin vertices] scratch */
  double *acc[6]; /* [skin vertices] dx dy dz ndx ndy ndz */
} synth;

static void die(const char *what) {
  fprintf(stderr, "afm_synth: %s\n", what);
  exit(1);
}

static void *xcalloc(size_t n, size_t size) {
  void *p = calloc(n ? n : 1, size);
  if (!p) die("out of memory");
  return p;
}

/* The skin vertex of FDP group.index, or -1. */
static long fdp_vertex(const synth *s, int group, int index) {
  const afm_meta *m = &s->in->meta;
  uint32_t i;
  for (i = 0; i < m->fdp_count; ++i) {
    const afm_fdp_point *p = &m->fdps[i];
    if (p->group == group && p->index == index && p->vertex != AFM_NONE &&
        p->vertex >= s->skin->first_vertex &&
        p->vertex < s->skin->first_vertex + s->skin->vertex_count)
      return (long)p->vertex;
  }
  return -1;
}

static void clear(synth *s) {
  int k;
  for (k = 0; k < 6; ++k) memset(s->acc[k], 0, s->skin->vertex_count * sizeof(double));
}

/* Adds a bump around skin vertex `center`: displacement `d` (quanta) and
 * normal delta `n` (Q14) at the centre, falling to zero at `radius`. */
static void bump(synth *s, long center, double radius, int power, const double d[3],
                 const double n[3]) {
  const afm_geometry *g = &s->in->geometry;
  uint32_t i, first = s->skin->first_vertex;
  double cx = g->px[center], cy = g->py[center], cz = g->pz[center];
  for (i = 0; i < s->skin->vertex_count; ++i) {
    uint32_t v = first + i;
    double x = g->px[v] - cx, y = g->py[v] - cy, z = g->pz[v] - cz;
    double r2 = (x * x + y * y + z * z) / (radius * radius), w;
    int k;
    if (r2 >= 1) continue;
    w = (1 - r2) * (1 - r2);
    if (power == 3) w *= 1 - r2;
    for (k = 0; k < 3; ++k) {
      s->acc[k][i] += w * d[k];
      s->acc[3 + k][i] += w * n[k];
    }
  }
}

static int16_t to_i16(double v) {
  double r = floor(v + 0.5);
  if (r > 32767) r = 32767;
  if (r < -32767) r = -32767;
  return (int16_t)r;
}

/* Turns the accumulated bumps into target (kind, number, reference). */
static void emit(synth *s, int kind, int number, int32_t reference, int normals) {
  uint32_t i, n = 0, runs = 0, first = s->skin->first_vertex, V = s->skin->vertex_count;
  afm_target *t;
  afm_run *run;
  int16_t *arrays[6];
  int k;
  if (s->target_count == MAX_TARGETS) die("too many targets");
  for (i = 0; i < V; ++i) {
    int moved = 0;
    for (k = 0; k < 3; ++k) moved |= to_i16(s->acc[k][i]) != 0;
    s->weight[i] = moved;
    if (moved) {
      ++n;
      if (i == 0 || !s->weight[i - 1]) ++runs;
    }
  }
  if (n == 0) return;
  t = &s->targets[s->target_count++];
  memset(t, 0, sizeof *t);
  t->kind = (uint8_t)kind;
  t->number = (uint8_t)number;
  t->flags = normals ? AFM_TARGET_NORMALS : 0;
  t->reference = reference;
  t->run_count = runs;
  t->delta_count = n;
  run = (afm_run *)xcalloc(runs, sizeof *run);
  for (k = 0; k < 6; ++k) arrays[k] = (int16_t *)xcalloc(n, sizeof(int16_t));
  runs = 0;
  n = 0;
  for (i = 0; i < V; ++i) {
    if (!s->weight[i]) continue;
    if (i == 0 || !s->weight[i - 1]) {
      run[runs].start = first + i;
      run[runs].length = 0;
      ++runs;
    }
    run[runs - 1].length++;
    for (k = 0; k < 6; ++k) arrays[k][n] = to_i16(s->acc[k][i]);
    ++n;
  }
  t->runs = run;
  t->dx = arrays[0];
  t->dy = arrays[1];
  t->dz = arrays[2];
  if (normals) {
    t->nx = arrays[3];
    t->ny = arrays[4];
    t->nz = arrays[5];
  } else {
    for (k = 3; k < 6; ++k) free(arrays[k]);
  }
}

static void fap_targets(synth *s) {
  int f;
  for (f = 3; f <= AFM_FAP_COUNT; ++f) {
    const afm_fap_info *info = afm_fap(f);
    long c;
    double d[3], n[3], amp;
    int k;
    if (!info || info->motion != AFM_MOTION_TRANSLATE) continue;
    c = fdp_vertex(s, info->fdp_group, info->fdp_index);
    if (c < 0) continue;
    /* 256 FAP units = 0.25 FAPU distance; the bump moves 0.1 of it. */
    amp = 0.1 * afm_meta_fapu_x0(&s->in->meta, info->unit) / s->in->geometry.step;
    for (k = 0; k < 3; ++k) {
      d[k] = amp * info->direction[k];
      n[k] = -3000.0 * info->direction[k];
    }
    clear(s);
    bump(s, c, 0.4 * s->es0_q, 2, d, n);
    emit(s, AFM_TARGET_FAP, f, 256, f % 2 == 0);
    if (info->bidirectional && f % 3 == 0) {
      for (k = 0; k < 3; ++k) {
        d[k] = 0.7 * amp * info->direction[(k + 1) % 3] - 0.5 * amp * info->direction[k];
        n[k] = 2000.0 * info->direction[(k + 2) % 3];
      }
      clear(s);
      bump(s, c, 0.3 * s->es0_q, 3, d, n);
      emit(s, AFM_TARGET_FAP, f, -256, f % 2 == 1);
    }
    if (f % 4 == 0) {
      /* An in-between past the first (version 1.2): the bump further
       * along and turned, as a lid over an eyeball turns. */
      for (k = 0; k < 3; ++k) {
        d[k] = 2.5 * amp * info->direction[k] + 0.6 * amp * info->direction[(k + 2) % 3];
        n[k] = -1500.0 * info->direction[(k + 1) % 3];
      }
      clear(s);
      bump(s, c, 0.4 * s->es0_q, 2, d, n);
      emit(s, AFM_TARGET_FAP, f, 640, f % 8 == 0);
      if (f % 8 == 4 && s->targets[s->target_count - 1].number == f) {
        /* A combination on it (version 1.4), gated by the jaw's opening
         * (FAP 3 at 512): the bump across, with normal deltas. */
        for (k = 0; k < 3; ++k) {
          d[k] = -0.8 * amp * info->direction[(k + 1) % 3];
          n[k] = 1200.0 * info->direction[k];
        }
        clear(s);
        bump(s, c, 0.3 * s->es0_q, 2, d, n);
        emit(s, AFM_TARGET_COMBINATION, f, 640, 1);
        if (s->targets[s->target_count - 1].kind == AFM_TARGET_COMBINATION) {
          s->targets[s->target_count - 1].gate = 3;
          s->targets[s->target_count - 1].gate_reference = 512;
        }
      }
    }
  }
}

static void add_bump(synth *s, int group, int index, double scale, double dx, double dy,
                     double dz) {
  long c = fdp_vertex(s, group, index);
  double d[3], n[3];
  if (c < 0) return;
  d[0] = dx * scale;
  d[1] = dy * scale;
  d[2] = dz * scale;
  n[0] = -dx * 1500;
  n[1] = dz * 1500;
  n[2] = dy * 1500;
  bump(s, c, 0.35 * s->es0_q, 2, d, n);
}

static void high_level_targets(synth *s) {
  double unit = 0.05 * s->es0_q; /* about 3 mm on the reference head */
  int k;
  for (k = 1; k < AFM_VISEME_COUNT; ++k) {
    double open = (k % 5) + 1, wide = (double)((k * 7) % 5) - 2;
    clear(s);
    add_bump(s, 8, 2, unit, 0, -0.4 * open, 0.1 * k);  /* lower lip */
    add_bump(s, 8, 1, unit, 0, 0.1 * open, -0.05 * k); /* upper lip */
    add_bump(s, 8, 3, unit, 0.3 * wide, 0, 0);         /* mouth corners */
    add_bump(s, 8, 4, unit, -0.3 * wide, 0, 0);
    emit(s, AFM_TARGET_VISEME, k, 63, k % 2 == 1);
  }
  for (k = 1; k < AFM_EXPRESSION_COUNT; ++k) {
    double brow = (double)((k * 3) % 7) - 3, smile = (double)((k * 5) % 7) - 3;
    clear(s);
    add_bump(s, 4, 1, unit, 0, 0.5 * brow, 0); /* eyebrows */
    add_bump(s, 4, 2, unit, 0, 0.5 * brow, 0);
    add_bump(s, 8, 3, unit, 0.2 * smile, 0.4 * smile, 0);
    add_bump(s, 8, 4, unit, -0.2 * smile, 0.4 * smile, 0);
    emit(s, AFM_TARGET_EXPRESSION, k, 63, k % 3 != 0);
  }
}

/* ---- rigid parts ------------------------------------------------------------ */

static int part_of_kind(const afm_geometry *g, int kind) {
  uint32_t p;
  for (p = 0; p < g->part_count; ++p)
    if (g->parts[p].kind == kind) return (int)p;
  return -1;
}

static void centroid(const afm_geometry *g, int part, int32_t out[3]) {
  const afm_part *p = &g->parts[part];
  double sum[3] = {0, 0, 0};
  uint32_t i;
  for (i = 0; i < p->vertex_count; ++i) {
    sum[0] += g->px[p->first_vertex + i];
    sum[1] += g->py[p->first_vertex + i];
    sum[2] += g->pz[p->first_vertex + i];
  }
  for (i = 0; i < 3; ++i) out[i] = (int32_t)floor(sum[i] / (p->vertex_count ? p->vertex_count : 1) + 0.5);
}

static int32_t q16(double v) { return (int32_t)floor(v * 65536.0 + 0.5); }

static void identity_axes(int16_t axes[9]) {
  int k;
  for (k = 0; k < 9; ++k) axes[k] = (int16_t)(k % 4 == 0 ? 16384 : 0);
}

static uint32_t make_rigids(const afm_doc *in, afm_rigid *out) {
  const afm_geometry *g = &in->geometry;
  const afm_meta *m = &in->meta;
  double step = g->step;
  uint32_t n = 0, p;
  int eye;
  for (eye = 0; eye < 2; ++eye) {
    int part = part_of_kind(g, eye ? AFM_PART_EYE_RIGHT : AFM_PART_EYE_LEFT);
    afm_control *c;
    uint16_t *parts;
    afm_rigid *r;
    if (part < 0) continue;
    r = &out[n++];
    memset(r, 0, sizeof *r);
    r->kind = (uint8_t)(eye ? AFM_RIGID_EYE_RIGHT : AFM_RIGID_EYE_LEFT);
    centroid(g, part, r->pivot);
    identity_axes(r->axes);
    if (!eye) { /* turned 5 degrees about y */
      r->axes[0] = (int16_t)floor(16384 * cos(0.0872665) + 0.5);
      r->axes[2] = (int16_t)floor(-16384 * sin(0.0872665) + 0.5);
      r->axes[6] = (int16_t)floor(16384 * sin(0.0872665) + 0.5);
      r->axes[8] = r->axes[0];
    }
    parts = (uint16_t *)xcalloc(1, sizeof *parts);
    parts[0] = (uint16_t)part;
    r->parts = parts;
    r->part_count = 1;
    c = (afm_control *)xcalloc(3, sizeof *c);
    c[0].fap = (uint8_t)(23 + eye);
    c[0].dof = AFM_DOF_ROTATE_Y;
    c[0].gain_q16 = q16(1.0);
    c[1].fap = (uint8_t)(25 + eye);
    c[1].dof = AFM_DOF_ROTATE_X;
    c[1].gain_q16 = q16(1.0);
    c[2].fap = (uint8_t)(27 + eye);
    c[2].dof = AFM_DOF_TRANSLATE_Z;
    c[2].gain_q16 = q16(m->es0 / 1024.0 / step);
    r->controls = c;
    r->control_count = 3;
  }
  {
    int lower = part_of_kind(g, AFM_PART_TEETH_LOWER), tongue = part_of_kind(g, AFM_PART_TONGUE);
    if (lower >= 0) {
      afm_rigid *r = &out[n++];
      uint16_t *parts = (uint16_t *)xcalloc(2, sizeof *parts);
      afm_control *c = (afm_control *)xcalloc(5, sizeof *c);
      double radius = 1.4 * m->es0 / step; /* pivot to chin, in quanta */
      memset(r, 0, sizeof *r);
      r->kind = AFM_RIGID_JAW;
      centroid(g, lower, r->pivot);
      r->pivot[1] += (int32_t)(0.3 * m->es0 / step);
      r->pivot[2] -= (int32_t)radius;
      identity_axes(r->axes);
      parts[0] = (uint16_t)lower;
      r->part_count = 1;
      if (tongue >= 0) parts[r->part_count++] = (uint16_t)tongue;
      r->parts = parts;
      /* open_jaw: 1024 MNS units open the chin by MNS0 */
      c[0].fap = 3;
      c[0].dof = AFM_DOF_ROTATE_X;
      c[0].gain_q16 = q16(m->mns0 / step / radius * 1e5 / 1024.0);
      c[1].fap = 14;
      c[1].dof = AFM_DOF_TRANSLATE_Z;
      c[1].gain_q16 = q16(m->mns0 / 1024.0 / step);
      c[2].fap = 15;
      c[2].dof = AFM_DOF_TRANSLATE_X;
      c[2].gain_q16 = q16(-m->mw0 / 1024.0 / step);
      /* Knots (AFM 1.3): the opening 20 % steeper past 400, the shift
       * 30 % less steep past -300. */
      c[3] = c[0];
      c[3].gain_q16 = q16(0.2 * m->mns0 / step / radius * 1e5 / 1024.0);
      c[3].knot = 400;
      c[4] = c[2];
      c[4].gain_q16 = q16(0.3 * m->mw0 / 1024.0 / step);
      c[4].knot = -300;
      r->controls = c;
      r->control_count = 5;
    }
  }
  {
    afm_rigid *r = &out[n++];
    uint16_t *parts = (uint16_t *)xcalloc(g->part_count, sizeof *parts);
    afm_control *c = (afm_control *)xcalloc(3, sizeof *c);
    int skin = part_of_kind(g, AFM_PART_SKIN);
    memset(r, 0, sizeof *r);
    r->kind = AFM_RIGID_HEAD;
    centroid(g, skin >= 0 ? skin : 0, r->pivot);
    r->pivot[1] -= (int32_t)(2.0 * m->es0 / step); /* about the top of the spine */
    identity_axes(r->axes);
    for (p = 0; p < g->part_count; ++p) parts[p] = (uint16_t)p;
    r->parts = parts;
    r->part_count = (uint16_t)g->part_count;
    for (p = 0; p < 3; ++p) {
      c[p].fap = (uint8_t)(48 + p);
      c[p].dof = (uint8_t)(AFM_DOF_ROTATE_X + p);
      c[p].gain_q16 = q16(1.0);
    }
    r->controls = c;
    r->control_count = 3;
  }
  return n;
}

/* --lift: every target's skin deltas become deltas of C = ceil(skin / 2)
 * control points (see the header comment). */
static void lift_targets(synth *s, afm_lift *lift, afm_run *lift_run, uint32_t *c[3], uint16_t *w[2]) {
  const uint32_t V = s->in->geometry.vertex_count, first = s->skin->first_vertex, n = s->skin->vertex_count;
  const uint32_t C = (n + 1) / 2;
  int16_t *dense = (int16_t *)xcalloc(3 * (size_t)n, sizeof *dense);
  uint32_t t, i, r, k;
  for (k = 0; k < 3; ++k) c[k] = (uint32_t *)xcalloc(n, sizeof(uint32_t));
  for (k = 0; k < 2; ++k) w[k] = (uint16_t *)xcalloc(n, sizeof(uint16_t));
  for (i = 0; i < n; ++i) {
    uint32_t a = (uint32_t)(((uint64_t)i * 2654435761u) >> 8) % 12288u, b = (i * 40503u) % 12288u;
    c[0][i] = i / 2;
    c[1][i] = (i / 2 + 1) % C;
    c[2][i] = (i / 2 + 5) % C;
    w[0][i] = (uint16_t)(i % 2 ? a + 8192 : a); /* w1 + w2 <= 32766: w0 > 0 */
    w[1][i] = (uint16_t)b;
  }
  for (t = 0; t < s->target_count; ++t) {
    afm_target *tg = &s->targets[t];
    int16_t *d[3];
    memset(dense, 0, 3 * (size_t)n * sizeof *dense);
    for (r = 0, k = 0; r < tg->run_count; ++r)
      for (i = 0; i < tg->runs[r].length; ++i, ++k) {
        const uint32_t v = tg->runs[r].start + i - first;
        dense[3 * v] = tg->dx[k], dense[3 * v + 1] = tg->dy[k], dense[3 * v + 2] = tg->dz[k];
      }
    for (k = 0; k < 3; ++k) d[k] = (int16_t *)xcalloc(C, sizeof(int16_t));
    for (i = 0; i < C; ++i)
      for (k = 0; k < 3; ++k) d[k][i] = dense[3 * (size_t)(2 * i) + k];
    free((void *)tg->runs);
    free((void *)tg->dx), free((void *)tg->dy), free((void *)tg->dz);
    free((void *)tg->nx), free((void *)tg->ny), free((void *)tg->nz);
    tg->flags = 0;
    tg->nx = tg->ny = tg->nz = NULL;
    tg->run_count = 1;
    tg->runs = (afm_run *)xcalloc(1, sizeof(afm_run));
    ((afm_run *)tg->runs)->start = V;
    ((afm_run *)tg->runs)->length = C;
    tg->delta_count = C;
    tg->dx = d[0], tg->dy = d[1], tg->dz = d[2];
  }
  free(dense);
  lift_run->start = first;
  lift_run->length = n;
  memset(lift, 0, sizeof *lift);
  lift->control_count = C;
  lift->run_count = 1;
  lift->runs = lift_run;
  lift->bound_count = n;
  lift->c0 = c[0], lift->c1 = c[1], lift->c2 = c[2];
  lift->w1 = w[0], lift->w2 = w[1];
}

int main(int argc, char **argv) {
  uint8_t *data, *out;
  size_t size, out_size;
  afm_doc *in, doc;
  afm_diag diag;
  afm_read_options ro;
  afm_write_options wo;
  afm_rigid rigids[4];
  afm_result r;
  synth s;
  afm_lift lift;
  afm_run lift_run;
  uint32_t *lift_c[3] = {NULL, NULL, NULL};
  uint16_t *lift_w[2] = {NULL, NULL};
  int skin, k, with_lift = argc == 4 && strcmp(argv[1], "--lift") == 0;
  if (with_lift) --argc, ++argv;
  if (argc != 3) {
    fprintf(stderr, "usage: afm_synth [--lift] IN.afm OUT.afm\n");
    return 2;
  }
  memset(&diag, 0, sizeof diag);
  memset(&ro, 0, sizeof ro);
  ro.diag = &diag;
  if (afm_file_read(argv[1], NULL, &data, &size) != AFM_OK) die("cannot read the input");
  r = afm_doc_read_alloc(data, size, &ro, NULL, &in);
  if (r != AFM_OK) {
    fprintf(stderr, "afm_synth: %s: %s: %s\n", argv[1], afm_result_string(r), diag.message);
    return 1;
  }
  skin = part_of_kind(&in->geometry, AFM_PART_SKIN);
  if (skin < 0 || in->meta.es0 <= 0) die("the input has no skin part or no ES0");
  memset(&s, 0, sizeof s);
  s.in = in;
  s.skin = &in->geometry.parts[skin];
  s.es0_q = in->meta.es0 / in->geometry.step;
  s.weight = (double *)xcalloc(s.skin->vertex_count, sizeof(double));
  for (k = 0; k < 6; ++k) s.acc[k] = (double *)xcalloc(s.skin->vertex_count, sizeof(double));
  fap_targets(&s);
  high_level_targets(&s);

  doc = *in;
  doc.target_count = s.target_count;
  doc.targets = s.targets;
  doc.rigid_count = make_rigids(in, rigids);
  doc.rigids = rigids;
  if (with_lift) {
    lift_targets(&s, &lift, &lift_run, lift_c, lift_w);
    doc.lift = &lift;
  }
  memset(&wo, 0, sizeof wo);
  wo.diag = &diag;
  r = afm_doc_write(&doc, &wo, &out, &out_size);
  if (r != AFM_OK) {
    fprintf(stderr, "afm_synth: writing: %s: %s\n", afm_result_string(r), diag.message);
    return 1;
  }
  if (afm_file_write_atomic(argv[2], out, out_size) != AFM_OK) die("cannot write the output");
  printf("afm_synth: %s: %lu targets, %lu rigid parts, %lu bytes\n", argv[2],
         (unsigned long)s.target_count, (unsigned long)doc.rigid_count, (unsigned long)out_size);
  for (k = 0; k < (int)s.target_count; ++k) {
    afm_target *t = &s.targets[k];
    free((void *)t->runs);
    free((void *)t->dx);
    free((void *)t->dy);
    free((void *)t->dz);
    free((void *)t->nx);
    free((void *)t->ny);
    free((void *)t->nz);
  }
  for (k = 0; k < (int)doc.rigid_count; ++k) {
    free((void *)rigids[k].parts);
    free((void *)rigids[k].controls);
  }
  for (k = 0; k < 6; ++k) free(s.acc[k]);
  for (k = 0; k < 3; ++k) free(lift_c[k]);
  for (k = 0; k < 2; ++k) free(lift_w[k]);
  free(s.weight);
  afm_free(NULL, out);
  afm_free(NULL, in);
  afm_free(NULL, data);
  return 0;
}
