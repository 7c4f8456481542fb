/* afm-play: play a FAP stream on an AFM, print a line (or hash) per frame. */
#define _POSIX_C_SOURCE 199309L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "afm/draco.h"
#include "afm/fap_stream.h"
#include "afm/format.h"
#include "afm/mpeg4.h"
#include "afm/player.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: afm-play MODEL.afm STREAM.fap [options]\n"
          "\n"
          "Plays an MPEG-4 FAP stream on an Animatable Face Model with the fixed-point\n"
          "player and prints one line per frame: frame, time, active morph targets,\n"
          "vertex-target updates and a hash of the pose.\n"
          "\n"
          "  --fps N          render at N frames per second (default: the stream's own\n"
          "                   rate); in-between poses are interpolated, no frame's values\n"
          "                   are dropped\n"
          "  --obj DIR        write each rendered frame as DIR/frame_NNNNN.obj (model\n"
          "                   units, normals, texture coordinates, one group per part)\n"
          "  --stats          time per frame (min, median, max) and memory used\n"
          "  --mirror LIST    copy one-sided FAPs to the other side: lr (left/right),\n"
          "                   io (inner/outer lip) or lr,io; off by default\n"
          "  --normal-deltas  blend the AFM's stored normal deltas instead of\n"
          "                   recomputing normals\n"
          "  --fdp-motion     after playing, each FDP group's motion against the stream's\n"
          "                   MPEG-4 prescription (see below)\n"
          "  --folds          count the skin triangles each frame turns over (see below)\n"
          "  --quiet          no per-frame lines, only the summary\n"
          "  --help           this text\n"
          "\n"
          "The hash is FNV-1a 64 over each vertex's x y z (int32 quanta) and normal\n"
          "(Q14), little-endian: the same on every platform for the same input.\n"
          "\n"
          "--fdp-motion: in every frame, each FDP that a distance FAP names should move\n"
          "by the sum over those FAPs of value x FAPU along the FAP's direction (the\n"
          "MPEG-4 rule). Where that prescription is at least MNS0 / 20 long, the FDP's\n"
          "played motion (the head's rotation left out) is compared with it: per FDP\n"
          "group, then per FDP (with the FAPs that name it), the median share of the\n"
          "prescription reached along it, the median distance from it relative to its\n"
          "length, and the 90th percentile share (100 %% is exact; above it, the face\n"
          "overshoots the stream). Motion that no FAP of an FDP prescribes counts as\n"
          "played: the jaw's opening (FAP 3 names only the chin, 2.1) carries the lower\n"
          "lip's FDPs forward as the jaw glides, though not down (the jaw does not open\n"
          "the mouth).\n"
          "\n"
          "--folds: in every frame, the skin's triangles (parts of kind skin) whose\n"
          "normal points against their rest normal, the head's rotation left out;\n"
          "slivers under a thousandth of the skin's mean rest area are not counted, as\n"
          "in afm-build's report. A triangle counts only when it stays turned with its\n"
          "corners moved by up to a position quantum (the normal's component along\n"
          "the rest normal below minus a quantum times its perimeter, the first-order\n"
          "bound of that move): within a quantum of edge-on, the stored positions do\n"
          "not tell which way it faces. Each frame line gets 'turned N' before its\n"
          "hash, and the summary says how many frames turn any, and the most one frame\n"
          "turns, with that frame's nonzero FAP values.\n"
          "\n"
          "Exit status: 0 on success, 1 on bad input (the message names the file and\n"
          "line or field), 2 on bad usage.\n");
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static uint64_t pose_hash(const afm_player *p, uint32_t vertices) {
  const int32_t *x = afm_player_positions(p);
  const afm_q14 *n = afm_player_normals(p);
  uint64_t h = 1469598103934665603ull;
  size_t i;
  int k;
  for (i = 0; i < 3 * (size_t)vertices; ++i) {
    uint32_t u = (uint32_t)x[i];
    uint16_t m = (uint16_t)n[i];
    uint8_t b[6];
    b[0] = (uint8_t)u, b[1] = (uint8_t)(u >> 8), b[2] = (uint8_t)(u >> 16), b[3] = (uint8_t)(u >> 24);
    b[4] = (uint8_t)m, b[5] = (uint8_t)(m >> 8);
    for (k = 0; k < 6; ++k) h = (h ^ b[k]) * 1099511628211ull;
  }
  return h;
}

/* A growing text buffer for OBJ output. */
typedef struct text {
  char *data;
  size_t size, capacity;
  int failed;
} text;

static void put(text *t, const char *format, ...) {
  va_list args;
  int n;
  if (t->failed) return;
  for (;;) {
    va_start(args, format);
    n = vsnprintf(t->data + t->size, t->capacity - t->size, format, args);
    va_end(args);
    if (n < 0) {
      t->failed = 1;
      return;
    }
    if ((size_t)n < t->capacity - t->size) {
      t->size += (size_t)n;
      return;
    } else {
      size_t cap = t->capacity * 2 + (size_t)n + 1024;
      char *d = (char *)realloc(t->data, cap);
      if (!d) {
        t->failed = 1;
        return;
      }
      t->data = d;
      t->capacity = cap;
    }
  }
}

static int write_obj(const char *dir, uint32_t index, const afm_doc *doc, const afm_player *p) {
  const afm_geometry *g = &doc->geometry;
  const int32_t *x = afm_player_positions(p);
  const afm_q14 *n = afm_player_normals(p);
  char path[4096];
  text t = {NULL, 0, 0, 0};
  uint32_t v, part, tri;
  afm_result r;
  snprintf(path, sizeof path, "%s/frame_%05lu.obj", dir, (unsigned long)index);
  t.capacity = 64;
  t.data = (char *)malloc(t.capacity);
  if (!t.data) return 0;
  put(&t, "# afm-play frame %lu of %s\n", (unsigned long)index, doc->meta.name);
  for (v = 0; v < g->vertex_count; ++v)
    put(&t, "v %.7g %.7g %.7g\n", (double)g->origin[0] + (double)x[3 * v] * (double)g->step,
        (double)g->origin[1] + (double)x[3 * v + 1] * (double)g->step,
        (double)g->origin[2] + (double)x[3 * v + 2] * (double)g->step);
  for (v = 0; v < g->vertex_count; ++v)
    put(&t, "vn %.5f %.5f %.5f\n", n[3 * v] / 16384.0, n[3 * v + 1] / 16384.0, n[3 * v + 2] / 16384.0);
  if (g->u)
    for (v = 0; v < g->vertex_count; ++v)
      put(&t, "vt %.6f %.6f\n", (double)g->uv_origin[0] + g->u[v] * (double)g->uv_step[0],
          (double)g->uv_origin[1] + g->v[v] * (double)g->uv_step[1]);
  for (part = 0; part < g->part_count; ++part) {
    const afm_part *a = &g->parts[part];
    put(&t, "o %s\n", a->name);
    for (tri = a->first_triangle; tri < a->first_triangle + a->triangle_count; ++tri) {
      unsigned long i0 = (unsigned long)g->triangles[3 * tri] + 1;
      unsigned long i1 = (unsigned long)g->triangles[3 * tri + 1] + 1;
      unsigned long i2 = (unsigned long)g->triangles[3 * tri + 2] + 1;
      if (g->u)
        put(&t, "f %lu/%lu/%lu %lu/%lu/%lu %lu/%lu/%lu\n", i0, i0, i0, i1, i1, i1, i2, i2, i2);
      else
        put(&t, "f %lu//%lu %lu//%lu %lu//%lu\n", i0, i0, i1, i1, i2, i2);
    }
  }
  r = t.failed ? AFM_ERR_OUT_OF_MEMORY : afm_file_write_atomic(path, (const uint8_t *)t.data, t.size);
  free(t.data);
  if (r != AFM_OK) {
    fprintf(stderr, "afm-play: %s: cannot write: %s\n", path, strerror(errno));
    return 0;
  }
  return 1;
}

/* --fdp-motion (see usage): samples per FDP that a distance FAP names; a
 * group's figures are those of its FDPs' samples together. */
typedef struct fdp_motion {
  uint32_t point[AFM_FAP_COUNT + 1]; /* per FAP 3..68: its FDP's index in meta.fdps, or AFM_NONE */
  uint32_t *slot;                    /* per index into meta.fdps: its samples' slot, or AFM_NONE */
  uint32_t *count, frames;           /* per slot: samples taken, of room for `frames` */
  double *share, *error;             /* at [slot * frames]: along share and relative distance */
  double *gather;                    /* room for the largest group's shares, then its distances */
  size_t most;                       /* that room: the largest group's samples (groups 1..11) */
} fdp_motion;

/* Which FDP each distance FAP names (the first point of that id on a
 * vertex), and room for `frames` samples of each of them. */
static int fdp_motion_init(fdp_motion *fm, const afm_doc *doc, uint32_t frames) {
  uint32_t f, i, slots = 0;
  size_t per_group[12] = {0};
  memset(fm, 0, sizeof *fm);
  for (f = 0; f <= AFM_FAP_COUNT; ++f) fm->point[f] = AFM_NONE;
  for (f = 3; f <= AFM_FAP_COUNT; ++f) {
    const afm_fap_info *info = afm_fap((int)f);
    if (!info || info->motion != AFM_MOTION_TRANSLATE || afm_meta_fapu_x0(&doc->meta, info->unit) <= 0) continue;
    for (i = 0; i < doc->meta.fdp_count && fm->point[f] == AFM_NONE; ++i) {
      const afm_fdp_point *p = &doc->meta.fdps[i];
      if (p->group == info->fdp_group && p->index == info->fdp_index && p->vertex != AFM_NONE) fm->point[f] = i;
    }
  }
  if (!doc->meta.fdp_count) return 1;
  fm->frames = frames;
  fm->slot = (uint32_t *)malloc(doc->meta.fdp_count * sizeof(uint32_t));
  if (!fm->slot) return 0;
  for (i = 0; i < doc->meta.fdp_count; ++i) {
    const uint8_t group = doc->meta.fdps[i].group;
    fm->slot[i] = AFM_NONE;
    if (group > 11) continue;
    for (f = 3; f <= AFM_FAP_COUNT && fm->slot[i] == AFM_NONE; ++f)
      if (fm->point[f] == i) fm->slot[i] = slots++;
    if (fm->slot[i] != AFM_NONE && (per_group[group] += frames) > fm->most) fm->most = per_group[group];
  }
  if (!slots) return 1;
  fm->count = (uint32_t *)calloc(slots, sizeof(uint32_t));
  fm->share = (double *)malloc((size_t)slots * frames * sizeof(double));
  fm->error = (double *)malloc((size_t)slots * frames * sizeof(double));
  fm->gather = (double *)malloc(2 * fm->most * sizeof(double));
  return fm->count && fm->share && fm->error && fm->gather;
}

static void fdp_motion_free(fdp_motion *fm) {
  free(fm->slot), free(fm->count), free(fm->share), free(fm->error), free(fm->gather);
}

/* One pose: the values of states a and b blended by t (Q16), the player's
 * vertices without the head's motion. */
static void fdp_motion_add(fdp_motion *fm, const afm_doc *doc, const afm_player *p, const afm_fap_state *a,
                           const afm_fap_state *b, afm_q16 t) {
  const afm_geometry *geo = &doc->geometry;
  const int32_t *x = afm_player_positions(p);
  const double limit = doc->meta.mns0 / 20.0;
  uint32_t i, f;
  if (!fm->count) return;
  for (i = 0; i < doc->meta.fdp_count; ++i) {
    const afm_fdp_point *pt = &doc->meta.fdps[i];
    const uint32_t slot = fm->slot[i];
    double want[3] = {0, 0, 0}, got[3], len = 0, along = 0, off = 0;
    size_t at;
    int k;
    if (slot == AFM_NONE || fm->count[slot] >= fm->frames) continue;
    for (f = 3; f <= AFM_FAP_COUNT; ++f) {
      const afm_fap_info *info;
      double v, unit;
      if (fm->point[f] != i) continue;
      info = afm_fap((int)f);
      v = a->value[f] + (double)(b->value[f] - a->value[f]) * t / 65536.0;
      unit = afm_meta_fapu_x0(&doc->meta, info->unit) / 1024.0;
      for (k = 0; k < 3; ++k) want[k] += v * unit * info->direction[k];
    }
    for (k = 0; k < 3; ++k) len += want[k] * want[k];
    len = sqrt(len);
    if (!(len >= limit) || limit <= 0) continue;
    got[0] = (double)(x[3 * pt->vertex] - geo->px[pt->vertex]) * geo->step;
    got[1] = (double)(x[3 * pt->vertex + 1] - geo->py[pt->vertex]) * geo->step;
    got[2] = (double)(x[3 * pt->vertex + 2] - geo->pz[pt->vertex]) * geo->step;
    for (k = 0; k < 3; ++k) along += got[k] * want[k] / len, off += (got[k] - want[k]) * (got[k] - want[k]);
    at = (size_t)slot * fm->frames + fm->count[slot]++;
    fm->share[at] = along / len;
    fm->error[at] = sqrt(off) / len;
  }
}

static int compare_double(const void *a, const void *b);

/* One table row's three figures from n samples (sorted here). */
static void print_figures(double *share, double *error, size_t n) {
  qsort(share, n, sizeof(double), compare_double);
  qsort(error, n, sizeof(double), compare_double);
  printf("%8lu  %15.1f %%  %14.1f %%  %16.1f %%\n", (unsigned long)n, 100 * share[n / 2], 100 * error[n / 2],
         100 * share[n * 9 / 10]);
}

static void fdp_motion_print(fdp_motion *fm, const afm_doc *doc) {
  static const char *names[12] = {"",      "",     "inner lip, chin, jaw", "eyes",  "brows", "cheeks",
                                  "tongue", "head", "outer lip",            "nose",  "ears",  "hair"};
  const afm_fdp_info *table = afm_fdp_table();
  uint32_t g, i, j, f;
  printf("FDP motion against the stream's prescription (where it is at least MNS0 / 20):\n");
  printf("  group                    samples  reached (median)  off by (median)  reached (90th pct)\n");
  if (!fm->count) return;
  for (g = 1; g < 12; ++g) {
    size_t n = 0;
    for (i = 0; i < doc->meta.fdp_count; ++i) {
      const uint32_t slot = fm->slot[i];
      if (slot == AFM_NONE || doc->meta.fdps[i].group != g) continue;
      memcpy(fm->gather + n, fm->share + (size_t)slot * fm->frames, fm->count[slot] * sizeof(double));
      memcpy(fm->gather + fm->most + n, fm->error + (size_t)slot * fm->frames, fm->count[slot] * sizeof(double));
      n += fm->count[slot];
    }
    if (!n) continue;
    printf("  %2u %-21s ", (unsigned)g, names[g]);
    print_figures(fm->gather, fm->gather + fm->most, n);
  }
  /* The same per FDP, in the standard's order, with the FAPs that name it:
   * which point of a group misses, and whose motion it is. */
  printf("  FDP    FAPs             samples  reached (median)  off by (median)  reached (90th pct)\n");
  for (i = 0; i < AFM_FDP_COUNT; ++i) {
    char id[16], faps[64];
    size_t used = 0;
    uint32_t slot = AFM_NONE;
    /* The point of this id that the FAPs name (the first on a vertex). */
    for (j = 0; j < doc->meta.fdp_count; ++j)
      if (doc->meta.fdps[j].group == table[i].group && doc->meta.fdps[j].index == table[i].index &&
          (slot = fm->slot[j]) != AFM_NONE)
        break;
    if (slot == AFM_NONE || !fm->count[slot]) continue;
    faps[0] = 0;
    for (f = 3; f <= AFM_FAP_COUNT; ++f)
      if (fm->point[f] == j && used + 5 < sizeof faps)
        used += (size_t)snprintf(faps + used, sizeof faps - used, "%s%lu", used ? " " : "", (unsigned long)f);
    snprintf(id, sizeof id, "%u.%u", (unsigned)table[i].group, (unsigned)table[i].index);
    printf("  %-6s %-15s ", id, faps);
    print_figures(fm->share + (size_t)slot * fm->frames, fm->error + (size_t)slot * fm->frames, fm->count[slot]);
  }
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* --folds (see usage): the skin triangles counted and their rest normals. */
typedef struct folds {
  uint32_t *triangle;      /* indices into geometry.triangles */
  double *normal;          /* [3 x count] rest normals, unit length */
  uint32_t count;          /* skin triangles counted (slivers left out) */
  uint32_t frames;         /* frames turning any */
  uint32_t most, most_frame; /* the most one frame turns, and that frame */
  afm_fap_state most_state; /* the values there */
} folds;

/* Triangle tri's normal (twice its area) at positions x (the rest positions
 * when x is null), in quanta; returns its perimeter, in quanta. */
static double triangle_normal(const afm_geometry *g, const int32_t *x, uint32_t tri, double n[3]) {
  double p[3][3], u[3], v[3], perimeter = 0;
  int c, k;
  for (c = 0; c < 3; ++c) {
    const uint32_t i = g->triangles[3 * tri + (uint32_t)c];
    for (k = 0; k < 3; ++k)
      p[c][k] = x ? (double)x[3 * i + (uint32_t)k] : (double)(k == 0 ? g->px[i] : k == 1 ? g->py[i] : g->pz[i]);
  }
  for (c = 0; c < 3; ++c) {
    double e = 0;
    for (k = 0; k < 3; ++k) e += (p[(c + 1) % 3][k] - p[c][k]) * (p[(c + 1) % 3][k] - p[c][k]);
    perimeter += sqrt(e);
  }
  for (k = 0; k < 3; ++k) u[k] = p[1][k] - p[0][k], v[k] = p[2][k] - p[0][k];
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
  return perimeter;
}

/* The skin's triangles with their unit rest normals, slivers under a
 * thousandth of the mean left out: every skin triangle first, then the
 * slivers dropped in place. */
static int folds_init(folds *fo, const afm_doc *doc) {
  const afm_geometry *g = &doc->geometry;
  uint32_t part, tri, i, total = 0;
  double sum = 0;
  memset(fo, 0, sizeof *fo);
  for (part = 0; part < g->part_count; ++part)
    if (g->parts[part].kind == AFM_PART_SKIN) total += g->parts[part].triangle_count;
  fo->triangle = (uint32_t *)malloc((total ? total : 1) * sizeof *fo->triangle);
  fo->normal = (double *)malloc((total ? total : 1) * 3 * sizeof *fo->normal);
  if (!fo->triangle || !fo->normal) return 0;
  for (part = 0; part < g->part_count; ++part) {
    const afm_part *a = &g->parts[part];
    if (a->kind != AFM_PART_SKIN) continue;
    for (tri = a->first_triangle; tri < a->first_triangle + a->triangle_count; ++tri) {
      double *n = fo->normal + 3 * fo->count;
      triangle_normal(g, NULL, tri, n);
      sum += sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      fo->triangle[fo->count++] = tri;
    }
  }
  for (i = 0, fo->count = 0; i < total; ++i) {
    const double *n = fo->normal + 3 * i;
    const double length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    double *unit = fo->normal + 3 * fo->count;
    if (!(length > 1e-3 * sum / total)) continue;
    fo->triangle[fo->count] = fo->triangle[i];
    unit[0] = n[0] / length, unit[1] = n[1] / length, unit[2] = n[2] / length;
    ++fo->count;
  }
  return 1;
}

static void folds_free(folds *fo) {
  free(fo->triangle);
  free(fo->normal);
}

/* Frame `frame`'s pose (positions without the head's motion, values a and b
 * blended by t): the count of turned triangles, also kept in the summary. */
static uint32_t folds_add(folds *fo, const afm_doc *doc, const afm_player *p, uint32_t frame,
                          const afm_fap_state *a, const afm_fap_state *b, afm_q16 t) {
  const int32_t *x = afm_player_positions(p);
  uint32_t i, turned = 0, f;
  double n[3];
  for (i = 0; i < fo->count; ++i) {
    const double *n0 = fo->normal + 3 * i;
    /* Moving corner c by d changes n by d x (its opposite edge): by at most
     * a quantum times the perimeter for moves up to a quantum (first order). */
    const double perimeter = triangle_normal(&doc->geometry, x, fo->triangle[i], n);
    turned += n0[0] * n[0] + n0[1] * n[1] + n0[2] * n[2] < -perimeter;
  }
  if (turned) ++fo->frames;
  if (turned > fo->most) {
    fo->most = turned;
    fo->most_frame = frame;
    fo->most_state = *a;
    for (f = 0; f <= AFM_FAP_COUNT; ++f)
      fo->most_state.value[f] = a->value[f] + (int32_t)floor(((double)b->value[f] - a->value[f]) * t / 65536.0 + 0.5);
  }
  return turned;
}

static void folds_print(const folds *fo, uint32_t frames) {
  uint32_t f;
  printf("turned skin triangles: %lu of %lu frames turn any", (unsigned long)fo->frames, (unsigned long)frames);
  if (!fo->most) {
    printf(" (%lu triangles counted)\n", (unsigned long)fo->count);
    return;
  }
  printf("; most %lu (of %lu counted) at frame %lu, where the FAPs are:", (unsigned long)fo->most,
         (unsigned long)fo->count, (unsigned long)fo->most_frame);
  for (f = 1; f <= AFM_FAP_COUNT; ++f)
    if (fo->most_state.value[f]) printf(" %lu=%ld", (unsigned long)f, (long)fo->most_state.value[f]);
  if (fo->most_state.viseme.select1 || fo->most_state.viseme.select2)
    printf(" viseme %u/%u blend %u", fo->most_state.viseme.select1, fo->most_state.viseme.select2,
           fo->most_state.viseme.blend);
  if (fo->most_state.expression.select1 || fo->most_state.expression.select2)
    printf(" expression %u at %u, %u at %u", fo->most_state.expression.select1, fo->most_state.expression.intensity1,
           fo->most_state.expression.select2, fo->most_state.expression.intensity2);
  printf("\n");
}

int main(int argc, char **argv) {
  const char *model_path = NULL, *stream_path = NULL, *obj_dir = NULL;
  unsigned long fps = 0;
  int stats = 0, quiet = 0, motion = 0, folding = 0, i;
  uint32_t mirror = 0, frame_count = 0, rendered = 0, k;
  afm_player_options po;
  uint8_t *model_data = NULL, *stream_data = NULL;
  size_t model_size = 0, stream_size = 0, doc_bytes = 0, player_bytes = 0;
  afm_doc *doc = NULL;
  afm_fap_frame *frames = NULL;
  afm_fap_header header;
  afm_fap_stats fap_stats;
  afm_fap_cursor cursor;
  afm_player *player = NULL, *still = NULL;
  void *player_memory = NULL, *still_memory = NULL;
  fdp_motion fm;
  folds fo;
  double *times = NULL;
  afm_diag diag;
  afm_read_options ro;
  afm_result r;
  uint64_t duration_us, t_us;
  int status = 1;

  memset(&po, 0, sizeof po);
  for (i = 1; i < argc; ++i) {
    const char *a = argv[i];
    if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
      usage(stdout);
      return 0;
    } else if (!strcmp(a, "--fps") && i + 1 < argc) {
      char *end;
      fps = strtoul(argv[++i], &end, 10);
      if (*end || fps == 0 || fps > 10000) {
        fprintf(stderr, "afm-play: --fps '%s': a whole number from 1 to 10000\n", argv[i]);
        return 2;
      }
    } else if (!strcmp(a, "--obj") && i + 1 < argc) {
      obj_dir = argv[++i];
    } else if (!strcmp(a, "--mirror") && i + 1 < argc) {
      const char *m = argv[++i];
      if (!strcmp(m, "lr")) mirror = AFM_MIRROR_LEFT_RIGHT;
      else if (!strcmp(m, "io")) mirror = AFM_MIRROR_INNER_OUTER;
      else if (!strcmp(m, "lr,io") || !strcmp(m, "io,lr")) mirror = AFM_MIRROR_LEFT_RIGHT | AFM_MIRROR_INNER_OUTER;
      else {
        fprintf(stderr, "afm-play: --mirror '%s': use lr, io or lr,io\n", m);
        return 2;
      }
    } else if (!strcmp(a, "--stats")) {
      stats = 1;
    } else if (!strcmp(a, "--fdp-motion")) {
      motion = 1;
    } else if (!strcmp(a, "--folds")) {
      folding = 1;
    } else if (!strcmp(a, "--quiet")) {
      quiet = 1;
    } else if (!strcmp(a, "--normal-deltas")) {
      po.flags |= AFM_PLAYER_NORMAL_DELTAS;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "afm-play: unknown or incomplete option '%s' (see --help)\n", a);
      return 2;
    } else if (!model_path) {
      model_path = a;
    } else if (!stream_path) {
      stream_path = a;
    } else {
      fprintf(stderr, "afm-play: too many arguments (see --help)\n");
      return 2;
    }
  }
  if (!model_path || !stream_path) {
    usage(stderr);
    return 2;
  }

  memset(&fm, 0, sizeof fm);
  memset(&fo, 0, sizeof fo);
  memset(&diag, 0, sizeof diag);
  if (afm_file_read(model_path, NULL, &model_data, &model_size) != AFM_OK) {
    fprintf(stderr, "afm-play: %s: cannot read: %s\n", model_path, strerror(errno));
    goto done;
  }
  ro.draco = afm_draco_codec();
  ro.diag = &diag;
  r = afm_doc_measure(model_data, model_size, &ro, &doc_bytes);
  if (r == AFM_OK) r = afm_doc_read_alloc(model_data, model_size, &ro, NULL, &doc);
  if (r != AFM_OK) {
    fprintf(stderr, "afm-play: %s: %s\n", model_path, diag.message[0] ? diag.message : afm_result_string(r));
    goto done;
  }
  if (afm_file_read(stream_path, NULL, &stream_data, &stream_size) != AFM_OK) {
    fprintf(stderr, "afm-play: %s: cannot read: %s\n", stream_path, strerror(errno));
    goto done;
  }
  memset(&diag, 0, sizeof diag);
  r = afm_fap_parse(stream_data, stream_size, NULL, NULL, 0, &frame_count, NULL, NULL, &diag);
  if (r == AFM_OK && frame_count == 0) {
    fprintf(stderr, "afm-play: %s: the stream has no frames\n", stream_path);
    goto done;
  }
  if (r == AFM_OK) {
    frames = (afm_fap_frame *)malloc(frame_count * sizeof *frames);
    if (!frames) r = AFM_ERR_OUT_OF_MEMORY;
  }
  if (r == AFM_OK)
    r = afm_fap_parse(stream_data, stream_size, NULL, frames, frame_count, &frame_count, &header,
                      &fap_stats, &diag);
  if (r != AFM_OK) {
    if (diag.line)
      fprintf(stderr, "afm-play: %s:%lu: %s\n", stream_path, (unsigned long)diag.line, diag.message);
    else
      fprintf(stderr, "afm-play: %s: %s\n", stream_path, diag.message[0] ? diag.message : afm_result_string(r));
    goto done;
  }

  r = afm_player_measure(doc, &po, &player_bytes);
  if (r == AFM_OK) {
    player_memory = malloc(player_bytes);
    if (!player_memory) r = AFM_ERR_OUT_OF_MEMORY;
  }
  if (r == AFM_OK) r = afm_player_init(doc, &po, player_memory, player_bytes, &player);
  if (r == AFM_OK && (motion || folding)) {
    /* The FDPs' motion and the folds are measured in the head's frame: a
       second player that leaves the head's rigid motion out. */
    afm_player_options head = po;
    size_t bytes = 0;
    head.flags |= AFM_PLAYER_HEAD_MATRIX;
    r = afm_player_measure(doc, &head, &bytes);
    if (r == AFM_OK) {
      still_memory = malloc(bytes);
      if (!still_memory) r = AFM_ERR_OUT_OF_MEMORY;
    }
    if (r == AFM_OK) r = afm_player_init(doc, &head, still_memory, bytes, &still);
  }
  if (r == AFM_OK) r = afm_fap_cursor_init(&cursor, frames, frame_count, header.fps_num, header.fps_den, mirror);
  if (r != AFM_OK) {
    fprintf(stderr, "afm-play: %s: cannot play: %s%s\n", model_path, afm_result_string(r),
            (po.flags & AFM_PLAYER_NORMAL_DELTAS) && r == AFM_ERR_ARGUMENT ? " (the AFM has no normals)" : "");
    goto done;
  }

  duration_us = afm_fap_cursor_duration_us(&cursor);
  if (!quiet)
    printf("%s: %lu frames at %lu/%lu fps (%.3f s) on %s (%lu vertices, %lu targets)\n", stream_path,
           (unsigned long)frame_count, (unsigned long)header.fps_num, (unsigned long)header.fps_den,
           (double)duration_us * 1e-6, model_path, (unsigned long)doc->geometry.vertex_count,
           (unsigned long)doc->target_count);
  {
    /* Render times: the stream's own frames, or a resampled clock. */
    uint32_t total = fps ? (uint32_t)(duration_us * fps / 1000000u) + 1 : frame_count;
    times = (double *)malloc(total * sizeof *times);
    if (!times || (motion && !fdp_motion_init(&fm, doc, total)) || (folding && !folds_init(&fo, doc))) {
      fprintf(stderr, "afm-play: out of memory\n");
      goto done;
    }
    for (k = 0; k < total; ++k) {
      const afm_fap_state *a, *b;
      afm_q16 t;
      const afm_pose_info *info;
      uint32_t turned = 0;
      double t0;
      t_us = fps ? (uint64_t)k * 1000000u / fps : 0;
      if (!fps) {
        /* Frame k's own time: seek to it exactly. */
        t_us = (uint64_t)(frames[k].number - frames[0].number) * header.fps_den * 1000000u / header.fps_num;
      }
      afm_fap_cursor_seek(&cursor, t_us, &a, &b, &t);
      t0 = now_seconds();
      r = afm_player_pose(player, a, b, t);
      times[k] = now_seconds() - t0;
      if (r != AFM_OK) {
        fprintf(stderr, "afm-play: frame %lu: %s\n", (unsigned long)k, afm_result_string(r));
        goto done;
      }
      info = afm_player_info(player);
      if (still) {
        r = afm_player_pose(still, a, b, t);
        if (r != AFM_OK) {
          fprintf(stderr, "afm-play: frame %lu: %s\n", (unsigned long)k, afm_result_string(r));
          goto done;
        }
        if (motion) fdp_motion_add(&fm, doc, still, a, b, t);
        if (folding) turned = folds_add(&fo, doc, still, k, a, b, t);
      }
      if (!quiet) {
        printf("frame %5lu  t %8.3f s  targets %3lu  updates %7lu  ", (unsigned long)k, (double)t_us * 1e-6,
               (unsigned long)info->active_targets, (unsigned long)info->updates);
        if (folding) printf("turned %4lu  ", (unsigned long)turned);
        printf("hash %016llx\n", (unsigned long long)pose_hash(player, doc->geometry.vertex_count));
      }
      if (obj_dir && !write_obj(obj_dir, k, doc, player)) goto done;
      ++rendered;
    }
  }
  if (stats && rendered) {
    double sum = 0;
    qsort(times, rendered, sizeof *times, compare_double);
    for (k = 0; k < rendered; ++k) sum += times[k];
    printf("time per frame: min %.1f us, median %.1f us, mean %.1f us, max %.1f us (%lu frames)\n",
           times[0] * 1e6, times[rendered / 2] * 1e6, sum / rendered * 1e6, times[rendered - 1] * 1e6,
           (unsigned long)rendered);
    printf("memory: model %lu bytes (decoded AFM), player %lu bytes, stream %lu bytes (%lu frames "
           "of %lu bytes); nothing allocated per frame\n",
           (unsigned long)doc_bytes, (unsigned long)player_bytes,
           (unsigned long)(frame_count * sizeof *frames), (unsigned long)frame_count,
           (unsigned long)sizeof *frames);
    printf("stream: %lu values clamped, %lu with fractions rounded\n", (unsigned long)fap_stats.clamped,
           (unsigned long)fap_stats.rounded);
  }
  if (motion) fdp_motion_print(&fm, doc);
  if (folding) folds_print(&fo, rendered);
  status = 0;
done:
  fdp_motion_free(&fm);
  folds_free(&fo);
  free(times);
  free(still_memory);
  free(player_memory);
  free(frames);
  free(stream_data);
  free(model_data);
  afm_free(NULL, doc);
  return status;
}
