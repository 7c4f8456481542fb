/* Rigid parts: eyeballs, jaw and head turn about their pivots (RIGD chunk).
 *
 * Motion of a degree of freedom = sum of FAP value (its part beyond the
 * control's knot) x gain (Q16.16): AU for rotations, quanta for
 * translations. Rotation R = A^T Ry Rx Rz A with A the rigid's local axes as
 * rows (Q14) and the three axis rotations from integer sines; p' = R p + t
 * with t = pivot - R pivot + A^T translation.
 *
 * Ranges: init checks that axes are orthonormal within 2 % and pivots lie
 * within 2^24 quanta; translations are clamped to 2^24. Positions then stay
 * below 2^28 through the jaw or eyes and the head, so products of Q14 matrix
 * entries (|R| <= 1.02 * 2^14) with positions fit int64 easily and results
 * fit int32 without clamping. */
#include "player_internal.h"

/* c = a * b for 3x3 Q14 matrices (row-major): each entry sums three Q28
 * products below 2^30: int64, rounded back to Q14. */
static void mat3_mul(const int32_t *a, const int32_t *b, int32_t *c) {
  int i, j;
  for (i = 0; i < 3; ++i)
    for (j = 0; j < 3; ++j) {
      int64_t s = (int64_t)a[3 * i] * b[j] + (int64_t)a[3 * i + 1] * b[3 + j] +
                  (int64_t)a[3 * i + 2] * b[6 + j];
      c[3 * i + j] = (int32_t)afm_round_shift64(s, 14);
    }
}

/* Rotation about the x (0), y (1) or z (2) axis by angle (AU), Q14. */
static void axis_rotation(int axis, int32_t angle, int32_t *m) {
  int32_t s = afm_sin_au(angle), c = afm_cos_au(angle);
  int i;
  for (i = 0; i < 9; ++i) m[i] = (i % 4 == 0) ? AFM_Q14_ONE : 0;
  if (axis == 0) m[4] = c, m[5] = -s, m[7] = s, m[8] = c;
  if (axis == 1) m[0] = c, m[2] = s, m[6] = -s, m[8] = c;
  if (axis == 2) m[0] = c, m[1] = -s, m[3] = s, m[4] = c;
}

afm_result afm_rigids_check(const afm_doc *doc) {
  uint32_t i;
  for (i = 0; i < doc->rigid_count; ++i) {
    const int16_t *ax = doc->rigids[i].axes;
    int a, b;
    for (a = 0; a < 3; ++a)
      if (doc->rigids[i].pivot[a] > (1 << 24) || doc->rigids[i].pivot[a] < -(1 << 24))
        return AFM_ERR_RANGE;
    for (a = 0; a < 3; ++a)
      for (b = a; b < 3; ++b) {
        int64_t dot = (int64_t)ax[3 * a] * ax[3 * b] + (int64_t)ax[3 * a + 1] * ax[3 * b + 1] +
                      (int64_t)ax[3 * a + 2] * ax[3 * b + 2];
        int64_t want = a == b ? (int64_t)1 << 28 : 0, tol = ((int64_t)1 << 28) / 25;
        if (dot < want - tol || dot > want + tol) return AFM_ERR_RANGE;
      }
  }
  return AFM_OK;
}

/* Motion of each degree of freedom for states a..b at t. */
static void rigid_motion(const afm_rigid *r, const afm_fap_state *a, const afm_fap_state *b,
                         afm_q16 t, int32_t motion[6]) {
  int64_t m[6] = {0, 0, 0, 0, 0, 0};
  int k;
  for (k = 0; k < r->control_count; ++k) {
    const afm_control *c = &r->controls[k];
    int64_t v = afm_lerp_value(a->value[c->fap], b->value[c->fap], t);
    /* The value's part beyond the knot (formats/afm.md, RIGD). */
    if (c->knot > 0) v = v > c->knot ? v - c->knot : 0;
    if (c->knot < 0) v = v < c->knot ? v - c->knot : 0;
    /* |v| <= 2^31 + 2^15, |gain| <= 2^31: the product is below 2^63. */
    m[c->dof] += afm_round_shift64(v * c->gain_q16, 16);
  }
  /* Angles within 2^31 AU; translations within 2^24 quanta (80 m at 5 um). */
  for (k = 0; k < 6; ++k) {
    int64_t limit = k >= AFM_DOF_TRANSLATE_X ? ((int64_t)1 << 24) : 0x7FFFFFFF;
    motion[k] = (int32_t)(m[k] > limit ? limit : m[k] < -limit ? -limit : m[k]);
  }
}

static void rigid_transform(const afm_rigid *r, const int32_t motion[6], afm_rigid_transform *out) {
  int32_t A[9], At[9], L[9], tmp[9], rx[9], ry[9], rz[9], R[9];
  int i, k;
  for (i = 0; i < 9; ++i) A[i] = r->axes[i], At[i] = r->axes[(i % 3) * 3 + i / 3];
  axis_rotation(0, motion[AFM_DOF_ROTATE_X], rx);
  axis_rotation(1, motion[AFM_DOF_ROTATE_Y], ry);
  axis_rotation(2, motion[AFM_DOF_ROTATE_Z], rz);
  mat3_mul(rx, rz, tmp);
  mat3_mul(ry, tmp, L);
  mat3_mul(L, A, tmp);
  mat3_mul(At, tmp, R);
  for (i = 0; i < 3; ++i) {
    /* Pivot and translation within 2^24, |R| <= 1.02: below 2^26. */
    int64_t s = 0, rp = 0;
    for (k = 0; k < 3; ++k) {
      s += (int64_t)At[3 * i + k] * motion[AFM_DOF_TRANSLATE_X + k];
      rp += (int64_t)R[3 * i + k] * r->pivot[k];
    }
    out->translation[i] = (int32_t)(r->pivot[i] + afm_round_shift64(s, 14) - afm_round_shift64(rp, 14));
  }
  for (i = 0; i < 9; ++i) out->rotation[i] = (afm_q14)R[i];
}

/* Moves the rigid's parts: p' = R p + t, n' = R n. */
static void apply(afm_player *p, const afm_rigid *r, const afm_rigid_transform *x) {
  const afm_geometry *g = &p->doc->geometry;
  const afm_q14 *R = x->rotation;
  const int64_t r0 = R[0], r1 = R[1], r2 = R[2], r3 = R[3], r4 = R[4], r5 = R[5], r6 = R[6],
                r7 = R[7], r8 = R[8];
  const int64_t t0 = x->translation[0], t1 = x->translation[1], t2 = x->translation[2];
  uint32_t part, v;
  for (part = 0; part < r->part_count; ++part) {
    const afm_part *a = &g->parts[r->parts[part]];
    for (v = a->first_vertex; v < a->first_vertex + a->vertex_count; ++v) {
      int32_t *q = p->positions + 3 * (size_t)v;
      afm_q14 *n = p->normals + 3 * (size_t)v;
      const int64_t q0 = q[0], q1 = q[1], q2 = q[2];
      const int32_t n0 = n[0], n1 = n[1], n2 = n[2];
      /* |q| < 2^28 and |R| < 2^15: products < 2^43, results in int32. */
      q[0] = (int32_t)(t0 + afm_round_shift64(r0 * q0 + r1 * q1 + r2 * q2, 14));
      q[1] = (int32_t)(t1 + afm_round_shift64(r3 * q0 + r4 * q1 + r5 * q2, 14));
      q[2] = (int32_t)(t2 + afm_round_shift64(r6 * q0 + r7 * q1 + r8 * q2, 14));
      /* |n| <= 1.02 * 2^14 and rows of length <= 1.02: within int16. */
      n[0] = (afm_q14)afm_round_shift32(R[0] * n0 + R[1] * n1 + R[2] * n2, 14);
      n[1] = (afm_q14)afm_round_shift32(R[3] * n0 + R[4] * n1 + R[5] * n2, 14);
      n[2] = (afm_q14)afm_round_shift32(R[6] * n0 + R[7] * n1 + R[8] * n2, 14);
    }
    afm_add_restore_span(p, a->first_vertex, a->first_vertex + a->vertex_count);
  }
}

/* The rigid's transform for states a..b at t; returns 0 (and the exact
 * identity) when no degree of freedom moves. */
static int rigid_pose(const afm_rigid *r, const afm_fap_state *a, const afm_fap_state *b,
                      afm_q16 t, afm_rigid_transform *x) {
  int32_t motion[6];
  int k;
  rigid_motion(r, a, b, t, motion);
  if (!motion[0] && !motion[1] && !motion[2] && !motion[3] && !motion[4] && !motion[5]) {
    for (k = 0; k < 9; ++k) x->rotation[k] = (afm_q14)((k % 4 == 0) ? AFM_Q14_ONE : 0);
    x->translation[0] = x->translation[1] = x->translation[2] = 0;
    return 0;
  }
  rigid_transform(r, motion, x);
  return 1;
}

afm_result afm_rigid_pose(const afm_rigid *rigid, const afm_fap_state *a, const afm_fap_state *b,
                          afm_q16 t, afm_rigid_transform *out) {
  static const afm_fap_state kNeutral; /* zero-initialised constant, not mutable state */
  if (!rigid || !out || t < 0 || t > AFM_Q16_ONE) return AFM_ERR_ARGUMENT;
  if (!a) a = &kNeutral;
  if (!b) b = a, t = 0;
  rigid_pose(rigid, a, b, t, out);
  return AFM_OK;
}

void afm_rigids_apply(afm_player *p, const afm_fap_state *a, const afm_fap_state *b, afm_q16 t) {
  const afm_doc *doc = p->doc;
  uint32_t r;
  int pass, k;
  for (k = 0; k < 9; ++k) p->head.rotation[k] = (afm_q14)((k % 4 == 0) ? AFM_Q14_ONE : 0);
  p->head.translation[0] = p->head.translation[1] = p->head.translation[2] = 0;
  /* Jaw and eyes, then the head. */
  for (pass = 0; pass < 2; ++pass)
    for (r = 0; r < doc->rigid_count; ++r) {
      const afm_rigid *rg = &doc->rigids[r];
      afm_rigid_transform x;
      if ((rg->kind == AFM_RIGID_HEAD) != (pass == 1)) continue;
      if (!rigid_pose(rg, a, b, t, &x)) continue;
      if (rg->kind == AFM_RIGID_HEAD) {
        p->head = x;
        if (p->flags & AFM_PLAYER_HEAD_MATRIX) continue;
      }
      apply(p, rg, &x);
    }
}
