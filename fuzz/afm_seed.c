/* afm_seed: small AFM files for the fuzzers' seed corpora.
 *
 *   afm_seed DIR
 *
 * Writes DIR/tiny.afm (raw: META, GEOM with normals, uv and colours, MTGT with
 * FAP, negative-side, viseme and expression targets, RIGD with an eye and the
 * head) and DIR/tiny-neutral.afm (META and GEOM only), a few hundred bytes
 * each, so that mutations reach every chunk kind quickly; and DIR/ball.afm
 * and DIR/ball-draco.afm, the same with a 146-vertex sphere for a skin, large
 * enough for the draco profile to encode GEOM and MTGT with Draco (a few KB).
 * fuzz/run.sh adds reference heads beside them.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "afm/draco.h"
#include "afm/format.h"

static int write_doc(const afm_doc *doc, afm_profile profile, const char *dir, const char *name) {
  afm_write_options wo;
  afm_diag diag;
  uint8_t *out = NULL;
  size_t size = 0;
  char path[4096];
  afm_result r;
  memset(&wo, 0, sizeof wo);
  memset(&diag, 0, sizeof diag);
  wo.profile = profile;
  wo.draco = afm_draco_codec();
  wo.diag = &diag;
  r = afm_doc_write(doc, &wo, &out, &size);
  if (r != AFM_OK) {
    fprintf(stderr, "afm_seed: %s: %s: %s\n", name, afm_result_string(r), diag.message);
    return 0;
  }
  snprintf(path, sizeof path, "%s/%s", dir, name);
  r = afm_file_write_atomic(path, out, size);
  afm_free(NULL, out);
  if (r != AFM_OK) {
    fprintf(stderr, "afm_seed: cannot write %s\n", path);
    return 0;
  }
  return 1;
}

/* The tiny document with its skin replaced by a sphere of radius 100 quanta
 * (10 rings of 16 vertices between two poles) and FAP 3's target moving all
 * of it; the eye keeps its tetrahedron. */
#define BALL_RINGS 10
#define BALL_SEGMENTS 16
#define BALL_SKIN (2 + (BALL_RINGS - 1) * BALL_SEGMENTS)
#define BALL_V (BALL_SKIN + 4)
#define BALL_SKIN_T (2 * BALL_SEGMENTS * (BALL_RINGS - 1))
#define BALL_T (BALL_SKIN_T + 4)

static int ball(const afm_doc *tiny, const char *dir) {
  static int16_t p[3][BALL_V], n[3][BALL_V], d[3][BALL_SKIN];
  static uint16_t uv[2][BALL_V];
  static uint8_t rgba[4 * BALL_V];
  static uint32_t tri[3 * BALL_T];
  static afm_part parts[2];
  static afm_target targets[4];
  static afm_run run = {0, BALL_SKIN};
  afm_doc doc = *tiny;
  const afm_geometry *g = &tiny->geometry;
  int i, j, k, v = 0, t = 0, ok;
  for (i = 0; i <= BALL_RINGS; ++i) {
    double theta = 3.14159265358979 * i / BALL_RINGS;
    int count = (i == 0 || i == BALL_RINGS) ? 1 : BALL_SEGMENTS;
    for (j = 0; j < count; ++j, ++v) {
      double phi = 2 * 3.14159265358979 * j / BALL_SEGMENTS;
      double x = sin(theta) * cos(phi), y = cos(theta), z = sin(theta) * sin(phi);
      p[0][v] = (int16_t)floor(100 * x + 0.5);
      p[1][v] = (int16_t)floor(100 * y + 0.5);
      p[2][v] = (int16_t)floor(100 * z + 0.5);
      n[0][v] = (int16_t)floor(16384 * x + 0.5);
      n[1][v] = (int16_t)floor(16384 * y + 0.5);
      n[2][v] = (int16_t)floor(16384 * z + 0.5);
      uv[0][v] = (uint16_t)(j * 4096);
      uv[1][v] = (uint16_t)(i * 6553);
      d[0][v] = (int16_t)(v % 7 - 3);
      d[1][v] = (int16_t)floor(-20 * (1 - y) + 0.5);
      d[2][v] = (int16_t)floor(5 * z + 0.5);
    }
  }
  /* ring r (1..RINGS-1) vertex j: 1 + (r - 1) * S + j; poles 0 and BALL_SKIN - 1 */
  for (j = 0; j < BALL_SEGMENTS; ++j) {
    int a = 1 + j, b = 1 + (j + 1) % BALL_SEGMENTS;
    tri[3 * t] = 0, tri[3 * t + 1] = (uint32_t)b, tri[3 * t + 2] = (uint32_t)a, ++t;
  }
  for (i = 1; i < BALL_RINGS - 1; ++i)
    for (j = 0; j < BALL_SEGMENTS; ++j) {
      int a = 1 + (i - 1) * BALL_SEGMENTS + j, b = 1 + (i - 1) * BALL_SEGMENTS + (j + 1) % BALL_SEGMENTS;
      int c = a + BALL_SEGMENTS, e = b + BALL_SEGMENTS;
      tri[3 * t] = (uint32_t)a, tri[3 * t + 1] = (uint32_t)b, tri[3 * t + 2] = (uint32_t)c, ++t;
      tri[3 * t] = (uint32_t)b, tri[3 * t + 1] = (uint32_t)e, tri[3 * t + 2] = (uint32_t)c, ++t;
    }
  for (j = 0; j < BALL_SEGMENTS; ++j) {
    int a = 1 + (BALL_RINGS - 2) * BALL_SEGMENTS + j;
    int b = 1 + (BALL_RINGS - 2) * BALL_SEGMENTS + (j + 1) % BALL_SEGMENTS;
    tri[3 * t] = (uint32_t)a, tri[3 * t + 1] = (uint32_t)b, tri[3 * t + 2] = BALL_SKIN - 1, ++t;
  }
  /* The eye: the tiny document's last 4 vertices and 4 triangles, moved. */
  for (k = 0; k < 4; ++k, ++v) {
    p[0][v] = g->px[6 + k];
    p[1][v] = g->py[6 + k];
    p[2][v] = (int16_t)(g->pz[6 + k] + 50);
    n[0][v] = g->nx[6 + k];
    n[1][v] = g->ny[6 + k];
    n[2][v] = g->nz[6 + k];
    uv[0][v] = g->u[6 + k];
    uv[1][v] = g->v[6 + k];
  }
  for (k = 0; k < 12; ++k) tri[3 * t + k] = g->triangles[24 + k] - 6 + BALL_SKIN;
  t += 4;
  for (i = 0; i < 4 * BALL_V; ++i) rgba[i] = (uint8_t)(i * 13);
  parts[0] = g->parts[0];
  parts[0].vertex_count = BALL_SKIN;
  parts[0].triangle_count = BALL_SKIN_T;
  parts[1] = g->parts[1];
  parts[1].first_vertex = BALL_SKIN;
  parts[1].first_triangle = BALL_SKIN_T;
  doc.geometry.vertex_count = BALL_V;
  doc.geometry.triangle_count = (uint32_t)t;
  doc.geometry.parts = parts;
  doc.geometry.px = p[0];
  doc.geometry.py = p[1];
  doc.geometry.pz = p[2];
  doc.geometry.nx = n[0];
  doc.geometry.ny = n[1];
  doc.geometry.nz = n[2];
  doc.geometry.u = uv[0];
  doc.geometry.v = uv[1];
  doc.geometry.rgba = rgba;
  doc.geometry.triangles = tri;
  for (k = 0; k < 4; ++k) targets[k] = tiny->targets[k];
  targets[0].runs = &run;
  targets[0].run_count = 1;
  targets[0].delta_count = BALL_SKIN;
  targets[0].dx = d[0];
  targets[0].dy = d[1];
  targets[0].dz = d[2];
  targets[0].nx = d[2];
  targets[0].ny = d[0];
  targets[0].nz = d[1];
  doc.targets = targets;
  ok = write_doc(&doc, AFM_PROFILE_RAW, dir, "ball.afm");
  ok &= write_doc(&doc, AFM_PROFILE_DRACO, dir, "ball-draco.afm");
  return ok;
}

int main(int argc, char **argv) {
  /* An octahedron (skin) and a tetrahedron (left eye), in quanta of 1 mm. */
  static const int16_t px[10] = {100, -100, 0, 0, 0, 0, 30, 50, 40, 40};
  static const int16_t py[10] = {0, 0, 100, -100, 0, 0, 20, 20, 40, 30};
  static const int16_t pz[10] = {0, 0, 0, 0, 100, -100, 80, 80, 80, 100};
  static const int16_t nx[10] = {16384, -16384, 0, 0, 0, 0, -9459, 9459, 0, 0};
  static const int16_t ny[10] = {0, 0, 16384, -16384, 0, 0, -9459, -9459, 9459, 0};
  static const int16_t nz[10] = {0, 0, 0, 0, 16384, -16384, -9459, -9459, -9459, 16384};
  static const uint16_t u[10] = {0, 65535, 32768, 32768, 16384, 49152, 0, 100, 200, 300};
  static const uint16_t v[10] = {32768, 32768, 0, 65535, 16384, 49152, 0, 100, 200, 300};
  static uint8_t rgba[40];
  static const uint32_t triangles[36] = {0, 2, 4, 1, 4, 2, 1, 3, 4, 0, 4, 3, 0, 5, 2, 1, 2, 5,
                                         1, 5, 3, 0, 3, 5, 6, 8, 7, 6, 7, 9, 6, 9, 8, 7, 8, 9};
  static const afm_fdp_point fdps[3] = {
      {2, 1, 3, {0.0f, -0.1f, 0.0f}}, {3, 5, 9, {0.04f, 0.03f, 0.1f}}, {7, 1, AFM_NONE, {0, -0.2f, 0}}};
  static const afm_run runs_a[1] = {{0, 3}};
  static const afm_run runs_b[1] = {{2, 2}};
  static const afm_run runs_c[2] = {{0, 1}, {4, 2}};
  static const int16_t da[3] = {5, -7, 9}, db[2] = {-3, 4}, dc[3] = {1, 2, -3};
  static const int16_t na[3] = {-100, 200, 0};
  static const uint16_t eye_parts[1] = {1}, head_parts[2] = {0, 1};
  static const afm_control eye_controls[2] = {{23, AFM_DOF_ROTATE_Y, 65536, 0},
                                              {27, AFM_DOF_TRANSLATE_Z, 12000, 0}};
  static const afm_control head_controls[3] = {
      {48, AFM_DOF_ROTATE_X, 65536, 0}, {49, AFM_DOF_ROTATE_Y, 65536, 0}, {50, AFM_DOF_ROTATE_Z, -65536, 0}};
  afm_part parts[2];
  afm_target targets[4];
  afm_rigid rigids[2];
  afm_doc doc;
  int i, ok = 1;

  if (argc != 2) {
    fprintf(stderr, "usage: afm_seed DIR\n");
    return 2;
  }
  for (i = 0; i < 40; ++i) rgba[i] = (uint8_t)(i * 37);
  memset(&doc, 0, sizeof doc);
  memset(parts, 0, sizeof parts);
  memset(targets, 0, sizeof targets);
  memset(rigids, 0, sizeof rigids);

  doc.meta.name = "tiny";
  doc.meta.units = "m";
  doc.meta.generator = "fuzz/afm_seed";
  doc.meta.es0 = 0.06f;
  doc.meta.irisd0 = 0.012f;
  doc.meta.ens0 = 0.04f;
  doc.meta.mns0 = 0.02f;
  doc.meta.mw0 = 0.05f;
  doc.meta.fdp_count = 3;
  doc.meta.fdps = fdps;

  parts[0].name = "skin";
  parts[0].texture = "skin.png";
  parts[0].kind = 1;
  parts[0].diffuse[0] = 200;
  parts[0].diffuse[3] = 255;
  parts[0].vertex_count = 6;
  parts[0].triangle_count = 8;
  parts[1].name = "eye_left";
  parts[1].texture = "";
  parts[1].kind = 2;
  parts[1].first_vertex = 6;
  parts[1].vertex_count = 4;
  parts[1].first_triangle = 8;
  parts[1].triangle_count = 4;
  doc.geometry.vertex_count = 10;
  doc.geometry.triangle_count = 12;
  doc.geometry.part_count = 2;
  doc.geometry.attributes = AFM_ATTR_NORMALS | AFM_ATTR_TEXCOORDS | AFM_ATTR_COLORS;
  doc.geometry.step = 0.001f;
  doc.geometry.uv_step[0] = doc.geometry.uv_step[1] = 1.0f / 65535.0f;
  doc.geometry.parts = parts;
  doc.geometry.px = px;
  doc.geometry.py = py;
  doc.geometry.pz = pz;
  doc.geometry.nx = nx;
  doc.geometry.ny = ny;
  doc.geometry.nz = nz;
  doc.geometry.u = u;
  doc.geometry.v = v;
  doc.geometry.rgba = rgba;
  doc.geometry.triangles = triangles;

  ok &= write_doc(&doc, AFM_PROFILE_RAW, argv[1], "tiny-neutral.afm");

  targets[0].kind = AFM_TARGET_FAP;
  targets[0].number = 3;
  targets[0].flags = AFM_TARGET_NORMALS;
  targets[0].reference = 256;
  targets[0].run_count = 1;
  targets[0].runs = runs_a;
  targets[0].delta_count = 3;
  targets[0].dx = targets[0].dy = targets[0].dz = da;
  targets[0].nx = targets[0].ny = targets[0].nz = na;
  targets[1].kind = AFM_TARGET_FAP;
  targets[1].number = 5;
  targets[1].reference = -256;
  targets[1].run_count = 1;
  targets[1].runs = runs_b;
  targets[1].delta_count = 2;
  targets[1].dx = targets[1].dy = targets[1].dz = db;
  targets[2].kind = AFM_TARGET_VISEME;
  targets[2].number = 1;
  targets[2].reference = 63;
  targets[2].run_count = 2;
  targets[2].runs = runs_c;
  targets[2].delta_count = 3;
  targets[2].dx = targets[2].dy = targets[2].dz = dc;
  targets[3] = targets[2];
  targets[3].kind = AFM_TARGET_EXPRESSION;
  targets[3].number = 2;
  doc.target_count = 4;
  doc.targets = targets;

  rigids[0].kind = AFM_RIGID_EYE_LEFT;
  rigids[0].pivot[0] = 40;
  rigids[0].pivot[1] = 28;
  rigids[0].pivot[2] = 85;
  rigids[0].axes[0] = rigids[0].axes[4] = rigids[0].axes[8] = 16384;
  rigids[0].part_count = 1;
  rigids[0].parts = eye_parts;
  rigids[0].control_count = 2;
  rigids[0].controls = eye_controls;
  rigids[1].kind = AFM_RIGID_HEAD;
  rigids[1].pivot[1] = -200000; /* far outside the mesh, as FDP 7.1 may be */
  rigids[1].axes[0] = rigids[1].axes[4] = rigids[1].axes[8] = 16384;
  rigids[1].part_count = 2;
  rigids[1].parts = head_parts;
  rigids[1].control_count = 3;
  rigids[1].controls = head_controls;
  doc.rigid_count = 2;
  doc.rigids = rigids;

  ok &= write_doc(&doc, AFM_PROFILE_RAW, argv[1], "tiny.afm");
  ok &= ball(&doc, argv[1]);
  return ok ? 0 : 1;
}
