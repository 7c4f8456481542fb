/* Normals of moved vertices, recomputed from the blended positions.
 *
 * Why recompute rather than blend stored normal deltas (also supported,
 * AFM_PLAYER_NORMAL_DELTAS): recomputing is exact for any mix of targets,
 * while blended deltas drift from the true normal when targets combine or
 * extrapolate, and they cost 6 more bytes per stored delta. bench/
 * bench_player measures both (time), tests/player the accuracy.
 *
 * A vertex's normal is the area-weighted sum of its faces' normals over its
 * seam group: render vertices with the same position and normal in the
 * neutral mesh are one welded vertex split at a UV seam (the builder computed
 * their normals together), so they get one normal again.
 *
 * Stale vertices: the corners of every face with a moved corner (and their
 * seam copies). Each face around a stale vertex is computed once per pose
 * (face_stamp) and added to its stale corners. Widths: edges are int32
 * differences of positions below 2^28, so cross products need int64 and a
 * vertex's sum of a few dozen faces stays far below 2^63. */
#include "player_internal.h"

/* ---- seam groups and rings (built once) --------------------------------------- */

/* Order of vertices by (position, normal); ties are seam copies. */
static int vertex_less(const afm_geometry *g, uint32_t a, uint32_t b) {
  const int16_t *fields[6];
  int k;
  fields[0] = g->px, fields[1] = g->py, fields[2] = g->pz;
  fields[3] = g->nx, fields[4] = g->ny, fields[5] = g->nz;
  for (k = 0; k < 6; ++k) {
    if (!fields[k]) break;
    if (fields[k][a] != fields[k][b]) return fields[k][a] < fields[k][b];
  }
  return a < b;
}

static void sift_down(const afm_geometry *g, uint32_t *idx, uint32_t root, uint32_t end) {
  while (2 * root + 1 < end) {
    uint32_t child = 2 * root + 1, top = root, tmp;
    if (vertex_less(g, idx[top], idx[child])) top = child;
    if (child + 1 < end && vertex_less(g, idx[top], idx[child + 1])) top = child + 1;
    if (top == root) return;
    tmp = idx[root], idx[root] = idx[top], idx[top] = tmp;
    root = top;
  }
}

/* Heap sort: no allocation, no recursion, deterministic. */
static void sort_vertices(const afm_geometry *g, uint32_t *idx, uint32_t n) {
  uint32_t i, tmp;
  for (i = n / 2; i-- > 0;) sift_down(g, idx, i, n);
  for (i = n; i-- > 1;) {
    tmp = idx[0], idx[0] = idx[i], idx[i] = tmp;
    sift_down(g, idx, 0, i);
  }
}

static int same_vertex(const afm_geometry *g, uint32_t a, uint32_t b) {
  return g->px[a] == g->px[b] && g->py[a] == g->py[b] && g->pz[a] == g->pz[b] &&
         (!g->nx || (g->nx[a] == g->nx[b] && g->ny[a] == g->ny[b] && g->nz[a] == g->nz[b]));
}

/* Links seam copies into circular lists (twin_next), within each part.
 * ring_start serves as the sort's scratch, before build_rings fills it. */
static void build_twins(afm_player *p) {
  const afm_geometry *g = &p->doc->geometry;
  uint32_t v, part;
  for (v = 0; v < g->vertex_count; ++v) p->twin_next[v] = v;
  for (part = 0; part < g->part_count; ++part) {
    const afm_part *a = &g->parts[part];
    uint32_t *idx = p->ring_start, i, run = 0;
    for (i = 0; i < a->vertex_count; ++i) idx[i] = a->first_vertex + i;
    sort_vertices(g, idx, a->vertex_count);
    for (i = 1; i <= a->vertex_count; ++i) {
      if (i < a->vertex_count && same_vertex(g, idx[run], idx[i])) continue;
      if (i - run > 1) {
        uint32_t k;
        for (k = run; k + 1 < i; ++k) p->twin_next[idx[k]] = idx[k + 1];
        p->twin_next[idx[i - 1]] = idx[run];
      }
      run = i;
    }
  }
}

/* CSR of the triangles around each vertex: 3T entries. */
static void build_rings(afm_player *p) {
  const afm_geometry *g = &p->doc->geometry;
  uint32_t v, t;
  for (v = 0; v <= g->vertex_count; ++v) p->ring_start[v] = 0;
  for (t = 0; t < 3 * g->triangle_count; ++t) p->ring_start[g->triangles[t] + 1]++;
  for (v = 0; v < g->vertex_count; ++v) p->ring_start[v + 1] += p->ring_start[v];
  /* Fill with ring_start as a moving cursor, then shift it back. */
  for (t = 0; t < 3 * g->triangle_count; ++t) p->ring[p->ring_start[g->triangles[t]]++] = t / 3;
  for (v = g->vertex_count; v > 0; --v) p->ring_start[v] = p->ring_start[v - 1];
  p->ring_start[0] = 0;
}

void afm_normals_init(afm_player *p) {
  uint32_t i;
  build_twins(p);
  build_rings(p);
  for (i = 0; i < p->vertex_count; ++i) p->stale_flag[i] = 0;
  for (i = 0; i < p->triangle_count; ++i) p->face_stamp[i] = 0;
  p->stale_count = 0;
  p->pose_number = 0;
}

/* ---- per pose ------------------------------------------------------------------- */

/* First guesses of 2^30 / sqrt(s) for s in [i 2^24, (i + 1) 2^24), i = 64..255:
 * round(2^18 / sqrt(i + 0.5)). Integer constants: every target reads the
 * same bits. */
static const uint16_t kInverseSqrt[192] = {
    32641, 32391, 32146, 31907, 31673, 31445, 31221, 31002, 30787, 30577, 30371, 30169,
    29972, 29778, 29587, 29401, 29217, 29038, 28861, 28688, 28518, 28350, 28186, 28024,
    27866, 27709, 27556, 27405, 27256, 27110, 26966, 26825, 26686, 26548, 26413, 26280,
    26149, 26020, 25893, 25767, 25644, 25522, 25402, 25283, 25167, 25051, 24938, 24826,
    24715, 24606, 24498, 24392, 24287, 24184, 24081, 23980, 23881, 23782, 23685, 23589,
    23494, 23400, 23307, 23216, 23125, 23036, 22947, 22860, 22774, 22688, 22604, 22520,
    22437, 22356, 22275, 22195, 22116, 22037, 21960, 21883, 21808, 21732, 21658, 21585,
    21512, 21440, 21368, 21298, 21228, 21159, 21090, 21022, 20955, 20888, 20822, 20757,
    20692, 20628, 20564, 20501, 20439, 20377, 20316, 20255, 20195, 20135, 20076, 20017,
    19959, 19902, 19845, 19788, 19732, 19676, 19621, 19566, 19512, 19458, 19405, 19352,
    19299, 19247, 19196, 19144, 19093, 19043, 18993, 18943, 18894, 18845, 18797, 18749,
    18701, 18653, 18606, 18560, 18513, 18467, 18422, 18376, 18331, 18287, 18242, 18198,
    18155, 18111, 18068, 18025, 17983, 17941, 17899, 17857, 17816, 17775, 17734, 17694,
    17654, 17614, 17574, 17535, 17496, 17457, 17418, 17380, 17342, 17304, 17267, 17229,
    17192, 17155, 17119, 17082, 17046, 17010, 16974, 16939, 16904, 16869, 16834, 16799,
    16765, 16731, 16697, 16663, 16629, 16596, 16563, 16530, 16497, 16465, 16432, 16400,
};

/* Number of significant bits of v (0 for 0): binary search, 6 steps. */
static int bit_length64(uint64_t v) {
  int n = 0;
  if (v >> 32) v >>= 32, n += 32;
  if (v >> 16) v >>= 16, n += 16;
  if (v >> 8) v >>= 8, n += 8;
  if (v >> 4) v >>= 4, n += 4;
  if (v >> 2) v >>= 2, n += 2;
  if (v >> 1) v >>= 1, n += 1;
  return n + (int)v;
}

/* Unit vector of (x, y, z) in Q14; (0, 0, 1) for a zero vector.
 *  1. Scale by a power of two so the largest component c has 15 bits: the
 *     squared length s is in [2^28, 3 * 2^30).
 *  2. inv = 2^30 / sqrt(s) from the table (8 significant bits of s, within
 *     0.8 %) and two Newton steps y <- y (3 - s y^2 / 2^60) / 2, with
 *     s y^2 < 2^63 and y t < 2^48: multiplications and shifts only, no
 *     division, no loop.
 *  3. c * inv < 2^30, shifted by 16: c * 2^14 / sqrt(s).
 * Error: within 1.5 LSB of Q14 (simulated over 300,000 random vectors);
 * truncating to 15 bits turns the direction by at most 2^-14 rad. */
void afm_normalize_q14(int64_t x, int64_t y, int64_t z, afm_q14 out[3]) {
  uint64_t ax = (uint64_t)(x < 0 ? -x : x), ay = (uint64_t)(y < 0 ? -y : y),
           az = (uint64_t)(z < 0 ? -z : z);
  int shift = bit_length64(ax | ay | az) - 15, k, quarter = 0;
  int32_t c[3];
  uint64_t s, inv;
  if ((ax | ay | az) == 0) {
    out[0] = out[1] = 0;
    out[2] = AFM_Q14_ONE;
    return;
  }
  if (shift >= 0) {
    c[0] = (int32_t)(x >> shift), c[1] = (int32_t)(y >> shift), c[2] = (int32_t)(z >> shift);
  } else {
    c[0] = (int32_t)(x * ((int64_t)1 << -shift));
    c[1] = (int32_t)(y * ((int64_t)1 << -shift));
    c[2] = (int32_t)(z * ((int64_t)1 << -shift));
  }
  s = (uint64_t)((int64_t)c[0] * c[0] + (int64_t)c[1] * c[1] + (int64_t)c[2] * c[2]);
  if (s < ((uint64_t)1 << 30)) s <<= 2, quarter = 1; /* s in [2^30, 2^32) */
  inv = kInverseSqrt[(s >> 24) - 64];
  for (k = 0; k < 2; ++k) {
    uint64_t t = ((uint64_t)3 << 60) - s * inv * inv; /* about 2^61: positive */
    inv = (inv * (t >> 29)) >> 32;
  }
  if (quarter) inv <<= 1; /* sqrt(4 s) = 2 sqrt(s) */
  for (k = 0; k < 3; ++k) out[k] = (afm_q14)(((int64_t)c[k] * (int64_t)inv + 0x8000) >> 16);
}

static void mark_stale(afm_player *p, uint32_t v) {
  uint32_t w = v;
  do {
    if (!p->stale_flag[w]) {
      p->stale_flag[w] = 1;
      p->stale[p->stale_count++] = w;
      p->normal_sum[3 * (size_t)w] = p->normal_sum[3 * (size_t)w + 1] = p->normal_sum[3 * (size_t)w + 2] = 0;
    }
    w = p->twin_next[w];
  } while (w != v);
}

void afm_normals_restore(afm_player *p) {
  const afm_geometry *g = &p->doc->geometry;
  uint32_t i;
  for (i = 0; i < p->stale_count; ++i) {
    uint32_t v = p->stale[i];
    afm_q14 *n = p->normals + 3 * (size_t)v;
    if (g->nx)
      n[0] = g->nx[v], n[1] = g->ny[v], n[2] = g->nz[v];
    else
      n[0] = n[1] = 0, n[2] = AFM_Q14_ONE;
    p->stale_flag[v] = 0;
  }
  p->stale_count = 0;
}

void afm_normals_recompute(afm_player *p) {
  const uint32_t *tri = p->doc->geometry.triangles;
  uint32_t i, k, v, marked, added;
  p->pose_number += 2;
  if (p->pose_number < 2) { /* the stamp wrapped: forget old stamps */
    for (i = 0; i < p->triangle_count; ++i) p->face_stamp[i] = 0;
    p->pose_number = 2;
  }
  marked = p->pose_number - 1;
  added = p->pose_number;
  /* Stale: the corners of every face with a moved corner, each face once
   * (stamp 2n - 1: "corners marked"; 2n: "normal added"). */
  for (i = 0; i < p->dirty_count; ++i)
    for (v = p->dirty[i].start; v < p->dirty[i].end && v < p->vertex_count; ++v) /* not controls */
      for (k = p->ring_start[v]; k < p->ring_start[v + 1]; ++k) {
        uint32_t f = p->ring[k];
        const uint32_t *t = tri + 3 * (size_t)f;
        if (p->face_stamp[f] == marked) continue;
        p->face_stamp[f] = marked;
        mark_stale(p, t[0]);
        mark_stale(p, t[1]);
        mark_stale(p, t[2]);
      }
  /* Every face around a stale vertex, once, added to its stale corners. */
  for (i = 0; i < p->stale_count; ++i) {
    uint32_t s = p->stale[i];
    for (k = p->ring_start[s]; k < p->ring_start[s + 1]; ++k) {
      uint32_t f = p->ring[k];
      const uint32_t *t = tri + 3 * (size_t)f;
      const int32_t *a, *b, *c;
      int64_t e1[3], e2[3], n[3];
      int j;
      if (p->face_stamp[f] == added) continue;
      p->face_stamp[f] = added;
      a = p->positions + 3 * (size_t)t[0];
      b = p->positions + 3 * (size_t)t[1];
      c = p->positions + 3 * (size_t)t[2];
      for (j = 0; j < 3; ++j) e1[j] = (int64_t)b[j] - a[j], e2[j] = (int64_t)c[j] - a[j];
      n[0] = e1[1] * e2[2] - e1[2] * e2[1];
      n[1] = e1[2] * e2[0] - e1[0] * e2[2];
      n[2] = e1[0] * e2[1] - e1[1] * e2[0];
      for (j = 0; j < 3; ++j) {
        int64_t *sum;
        if (!p->stale_flag[t[j]]) continue;
        sum = p->normal_sum + 3 * (size_t)t[j];
        sum[0] += n[0], sum[1] += n[1], sum[2] += n[2];
      }
    }
  }
  /* Each stale vertex: the sum over its seam group, normalised. */
  for (i = 0; i < p->stale_count; ++i) {
    uint32_t s = p->stale[i], u = p->twin_next[s];
    int64_t n[3];
    n[0] = p->normal_sum[3 * (size_t)s], n[1] = p->normal_sum[3 * (size_t)s + 1],
    n[2] = p->normal_sum[3 * (size_t)s + 2];
    for (; u != s; u = p->twin_next[u]) {
      n[0] += p->normal_sum[3 * (size_t)u];
      n[1] += p->normal_sum[3 * (size_t)u + 1];
      n[2] += p->normal_sum[3 * (size_t)u + 2];
    }
    afm_normalize_q14(n[0], n[1], n[2], p->normals + 3 * (size_t)s);
  }
}
