/* GEOM chunk: neutral mesh with named parts (formats/afm.md). */
#include <stdlib.h>
#include <string.h>

#include "afm_internal.h"

enum { kPartFixedSize = 24 };

static int finite_all(const float *v, int n) {
  int i;
  for (i = 0; i < n; ++i)
    if (!afm_f32_finite(v[i])) return 0;
  return 1;
}

/* Triangle a,b,c rotated so the smallest index leads, winding kept. */
static void rotate_min_first(const uint32_t *t, uint32_t out[3]) {
  int k = 0;
  if (t[1] < t[k]) k = 1;
  if (t[2] < t[k]) k = 2;
  out[0] = t[k];
  out[1] = t[(k + 1) % 3];
  out[2] = t[(k + 2) % 3];
}

static int tri_compare(const void *a, const void *b) {
  const uint32_t *x = (const uint32_t *)a, *y = (const uint32_t *)b;
  int k;
  for (k = 0; k < 3; ++k)
    if (x[k] != y[k]) return x[k] < y[k] ? -1 : 1;
  return 0;
}

void afm_canonicalize_triangles(uint32_t *triangles, const afm_part *parts,
                                uint32_t part_count) {
  uint32_t p, t;
  for (p = 0; p < part_count; ++p) {
    uint32_t *first = triangles + 3 * (size_t)parts[p].first_triangle;
    for (t = 0; t < parts[p].triangle_count; ++t) {
      uint32_t r[3];
      rotate_min_first(first + 3 * (size_t)t, r);
      memcpy(first + 3 * (size_t)t, r, sizeof r);
    }
    qsort(first, parts[p].triangle_count, 3 * sizeof(uint32_t), tri_compare);
  }
}

/* Checks parts tile the vertex and triangle ranges and names are unique. */
static afm_result check_parts(afm_reader *r, const afm_geometry *g, const afm_part *parts) {
  uint32_t p, q, v_end = 0, t_end = 0;
  for (p = 0; p < g->part_count; ++p) {
    const afm_part *a = &parts[p];
    if (a->first_vertex != v_end || a->first_triangle != t_end)
      return afm_fail(r, AFM_ERR_RANGE,
                      "part %lu '%s': starts at vertex %lu, triangle %lu; parts must tile the "
                      "mesh in order (expected %lu, %lu)",
                      (unsigned long)p, a->name, (unsigned long)a->first_vertex,
                      (unsigned long)a->first_triangle, (unsigned long)v_end,
                      (unsigned long)t_end);
    if (a->vertex_count > g->vertex_count - v_end ||
        a->triangle_count > g->triangle_count - t_end)
      return afm_fail(r, AFM_ERR_RANGE, "part %lu '%s': runs past the mesh end", (unsigned long)p,
                      a->name);
    if (a->name[0] == '\0')
      return afm_fail(r, AFM_ERR_RANGE, "part %lu: empty name", (unsigned long)p);
    for (q = 0; q < p; ++q)
      if (strcmp(parts[q].name, a->name) == 0)
        return afm_fail(r, AFM_ERR_RANGE, "part %lu: name '%s' used twice", (unsigned long)p,
                        a->name);
    v_end += a->vertex_count;
    t_end += a->triangle_count;
  }
  if (v_end != g->vertex_count || t_end != g->triangle_count)
    return afm_fail(r, AFM_ERR_RANGE,
                    "parts cover %lu vertices and %lu triangles of %lu and %lu",
                    (unsigned long)v_end, (unsigned long)t_end, (unsigned long)g->vertex_count,
                    (unsigned long)g->triangle_count);
  return AFM_OK;
}

/* Each triangle indexes its own part, has three distinct corners, and the
 * part's triangles are in canonical order. */
static afm_result check_triangles(afm_reader *r, const afm_geometry *g, const afm_part *parts) {
  uint32_t p, t;
  for (p = 0; p < g->part_count; ++p) {
    const afm_part *a = &parts[p];
    const uint32_t *tri = g->triangles + 3 * (size_t)a->first_triangle;
    uint32_t lo = a->first_vertex, hi = a->first_vertex + a->vertex_count;
    for (t = 0; t < a->triangle_count; ++t) {
      const uint32_t *x = tri + 3 * (size_t)t;
      int k;
      for (k = 0; k < 3; ++k)
        if (x[k] < lo || x[k] >= hi)
          return afm_fail(r, AFM_ERR_RANGE,
                          "triangle %lu (part '%s'): index %lu outside the part's vertices "
                          "[%lu, %lu)",
                          (unsigned long)(a->first_triangle + t), a->name, (unsigned long)x[k],
                          (unsigned long)lo, (unsigned long)hi);
      if (x[0] == x[1] || x[1] == x[2] || x[0] == x[2])
        return afm_fail(r, AFM_ERR_RANGE, "triangle %lu (part '%s'): repeated index %lu",
                        (unsigned long)(a->first_triangle + t), a->name,
                        (unsigned long)(x[0] == x[1] ? x[0] : x[2]));
      if (x[0] > x[1] || x[0] > x[2] || (t > 0 && tri_compare(x - 3, x) > 0))
        return afm_fail(r, AFM_ERR_RANGE,
                        "triangle %lu (part '%s'): not in canonical order (smallest index "
                        "first, part sorted; see afm_canonicalize_triangles)",
                        (unsigned long)(a->first_triangle + t), a->name);
    }
  }
  return AFM_OK;
}

/* Header and part table: everything before the position arrays. */
static afm_result decode_header(afm_reader *r, afm_arena *arena, afm_geometry *g) {
  afm_part *parts;
  uint32_t p;

  memset(g, 0, sizeof *g);
  g->vertex_count = afm_read_u32(r, "vertex_count");
  g->triangle_count = afm_read_u32(r, "triangle_count");
  g->part_count = afm_read_u16(r, "part_count");
  g->attributes = afm_read_u16(r, "attributes");
  for (p = 0; p < 3; ++p) g->origin[p] = afm_read_f32(r, "origin");
  g->step = afm_read_f32(r, "step");
  for (p = 0; p < 2; ++p) g->uv_origin[p] = afm_read_f32(r, "uv_origin");
  for (p = 0; p < 2; ++p) g->uv_step[p] = afm_read_f32(r, "uv_step");
  if (r->error != AFM_OK) return r->error;
  if (g->attributes & ~(uint32_t)(AFM_ATTR_NORMALS | AFM_ATTR_TEXCOORDS | AFM_ATTR_COLORS))
    return afm_fail(r, AFM_ERR_RANGE, "attributes 0x%x has unknown bits",
                    (unsigned)g->attributes);
  if (g->part_count == 0) return afm_fail(r, AFM_ERR_RANGE, "part_count is 0");
  if (!finite_all(g->origin, 3) || !afm_f32_positive(g->step) ||
      !finite_all(g->uv_origin, 2) || !finite_all(g->uv_step, 2))
    return afm_fail(r, AFM_ERR_RANGE, "quantisation: origin/step not finite or step <= 0");
  if (g->part_count > afm_remaining(r) / (kPartFixedSize + 8))
    return afm_fail(r, AFM_ERR_TRUNCATED, "%lu parts cannot fit in %lu bytes",
                    (unsigned long)g->part_count, (unsigned long)afm_remaining(r));

  parts = (afm_part *)afm_arena_take(arena, afm_mul_size(g->part_count, sizeof *parts));
  for (p = 0; p < g->part_count && r->error == AFM_OK; ++p) {
    afm_part a;
    int k;
    a.name = afm_read_string(r, arena, "part.name");
    a.texture = afm_read_string(r, arena, "part.texture");
    a.kind = afm_read_u8(r, "part.kind");
    for (k = 0; k < 3; ++k)
      if (afm_read_u8(r, "part.reserved") != 0 && r->error == AFM_OK)
        return afm_fail(r, AFM_ERR_RANGE, "part %lu: reserved byte not zero", (unsigned long)p);
    for (k = 0; k < 4; ++k) a.diffuse[k] = afm_read_u8(r, "part.diffuse");
    a.first_vertex = afm_read_u32(r, "part.first_vertex");
    a.vertex_count = afm_read_u32(r, "part.vertex_count");
    a.first_triangle = afm_read_u32(r, "part.first_triangle");
    a.triangle_count = afm_read_u32(r, "part.triangle_count");
    if (parts) parts[p] = a;
  }
  if (r->error != AFM_OK) return r->error;
  if (parts && check_parts(r, g, parts) != AFM_OK) return r->error;
  g->parts = parts;
  return AFM_OK;
}

afm_result afm_geometry_decode_at(const uint8_t *raw, size_t size, uint64_t file_offset,
                                  afm_arena *arena, afm_geometry *g, afm_diag *diag) {
  afm_reader r;
  size_t V, T;

  afm_reader_init(&r, raw, size, file_offset, AFM_CHUNK_GEOM, diag);
  if (decode_header(&r, arena, g) != AFM_OK) return r.error;
  V = g->vertex_count;
  T = g->triangle_count;
  /* Each vertex needs at least 6 bytes and each triangle 12: bound the
   * untrusted counts by what is left before allocating anything. */
  if (V > afm_remaining(&r) / 6 || T > afm_remaining(&r) / 12)
    return afm_fail(&r, AFM_ERR_TRUNCATED,
                    "%lu vertices and %lu triangles cannot fit in %lu bytes", (unsigned long)V,
                    (unsigned long)T, (unsigned long)afm_remaining(&r));

  g->px = afm_read_i16_array(&r, arena, V, "positions.x");
  g->py = afm_read_i16_array(&r, arena, V, "positions.y");
  g->pz = afm_read_i16_array(&r, arena, V, "positions.z");
  if (g->attributes & AFM_ATTR_NORMALS) {
    g->nx = afm_read_i16_array(&r, arena, V, "normals.x");
    g->ny = afm_read_i16_array(&r, arena, V, "normals.y");
    g->nz = afm_read_i16_array(&r, arena, V, "normals.z");
  }
  if (g->attributes & AFM_ATTR_TEXCOORDS) {
    g->u = afm_read_u16_array(&r, arena, V, "texcoords.u");
    g->v = afm_read_u16_array(&r, arena, V, "texcoords.v");
  }
  if (g->attributes & AFM_ATTR_COLORS)
    g->rgba = afm_read_u8_array(&r, arena, afm_mul_size(V, 4), "colors");
  g->triangles = afm_read_u32_array(&r, arena, afm_mul_size(T, 3), "triangles");
  if (r.error != AFM_OK) return r.error;
  if (afm_remaining(&r) != 0)
    return afm_fail(&r, AFM_ERR_TRAILING_BYTES, "%lu bytes after the triangles",
                    (unsigned long)afm_remaining(&r));
  if (g->parts && g->triangles && check_triangles(&r, g, g->parts) != AFM_OK) return r.error;
  return AFM_OK;
}

afm_result afm_geometry_decode(const uint8_t *raw, size_t size, void *buffer, size_t buffer_size,
                               size_t *bytes, afm_geometry *geometry, afm_diag *diag) {
  afm_arena arena;
  afm_geometry scratch;
  afm_result res;
  if (!raw || (!buffer && buffer_size) || (!geometry && buffer)) return AFM_ERR_ARGUMENT;
  arena.base = (uint8_t *)buffer;
  arena.size = buffer_size;
  arena.used = 0;
  res = afm_geometry_decode_at(raw, size, 0, &arena, geometry ? geometry : &scratch, diag);
  if (bytes) *bytes = arena.used;
  if (res == AFM_OK && buffer && arena.used > buffer_size) return AFM_ERR_BUFFER_TOO_SMALL;
  return res;
}

afm_result afm_geometry_decode_header(const uint8_t *raw, size_t size, void *buffer,
                                      size_t buffer_size, size_t *bytes, size_t *header_size,
                                      afm_geometry *geometry, afm_diag *diag) {
  afm_arena arena;
  afm_geometry scratch;
  afm_reader r;
  afm_result res;
  if (!raw || (!buffer && buffer_size) || (!geometry && buffer)) return AFM_ERR_ARGUMENT;
  arena.base = (uint8_t *)buffer;
  arena.size = buffer_size;
  arena.used = 0;
  afm_reader_init(&r, raw, size, 0, AFM_CHUNK_GEOM, diag);
  res = decode_header(&r, &arena, geometry ? geometry : &scratch);
  if (bytes) *bytes = arena.used;
  if (header_size) *header_size = r.pos;
  if (res == AFM_OK && buffer && arena.used > buffer_size) return AFM_ERR_BUFFER_TOO_SMALL;
  return res;
}

afm_result afm_geometry_encode_to(const afm_geometry *g, afm_writer *w) {
  uint32_t p;
  size_t V = g->vertex_count;
  if (g->part_count == 0 || g->part_count > 0xFFFFu || !g->parts || (V && (!g->px || !g->py || !g->pz)) ||
      (g->triangle_count && !g->triangles))
    return AFM_ERR_ARGUMENT;
  if (((g->attributes & AFM_ATTR_NORMALS) && V && (!g->nx || !g->ny || !g->nz)) ||
      ((g->attributes & AFM_ATTR_TEXCOORDS) && V && (!g->u || !g->v)) ||
      ((g->attributes & AFM_ATTR_COLORS) && V && !g->rgba))
    return AFM_ERR_ARGUMENT;
  afm_write_u32(w, g->vertex_count);
  afm_write_u32(w, g->triangle_count);
  afm_write_u16(w, (uint16_t)g->part_count);
  afm_write_u16(w, (uint16_t)g->attributes);
  for (p = 0; p < 3; ++p) afm_write_f32(w, g->origin[p]);
  afm_write_f32(w, g->step);
  for (p = 0; p < 2; ++p) afm_write_f32(w, g->uv_origin[p]);
  for (p = 0; p < 2; ++p) afm_write_f32(w, g->uv_step[p]);
  for (p = 0; p < g->part_count; ++p) {
    const afm_part *a = &g->parts[p];
    int k;
    if ((a->name && strlen(a->name) > 0xFFFFu) || (a->texture && strlen(a->texture) > 0xFFFFu))
      return AFM_ERR_LIMIT;
    afm_write_string(w, a->name);
    afm_write_string(w, a->texture);
    afm_write_u8(w, a->kind);
    for (k = 0; k < 3; ++k) afm_write_u8(w, 0);
    for (k = 0; k < 4; ++k) afm_write_u8(w, a->diffuse[k]);
    afm_write_u32(w, a->first_vertex);
    afm_write_u32(w, a->vertex_count);
    afm_write_u32(w, a->first_triangle);
    afm_write_u32(w, a->triangle_count);
  }
  afm_write_i16_array(w, g->px, V);
  afm_write_i16_array(w, g->py, V);
  afm_write_i16_array(w, g->pz, V);
  if (g->attributes & AFM_ATTR_NORMALS) {
    afm_write_i16_array(w, g->nx, V);
    afm_write_i16_array(w, g->ny, V);
    afm_write_i16_array(w, g->nz, V);
  }
  if (g->attributes & AFM_ATTR_TEXCOORDS) {
    afm_write_u16_array(w, g->u, V);
    afm_write_u16_array(w, g->v, V);
  }
  if (g->attributes & AFM_ATTR_COLORS) {
    afm_write_bytes(w, g->rgba, V * 4);
  }
  afm_write_u32_array(w, g->triangles, (size_t)g->triangle_count * 3);
  return w->overflow ? AFM_ERR_BUFFER_TOO_SMALL : AFM_OK;
}

afm_result afm_geometry_encoded_size(const afm_geometry *g, size_t *size) {
  afm_writer w = {NULL, 0, 0, 0};
  afm_result r;
  if (!g || !size) return AFM_ERR_ARGUMENT;
  r = afm_geometry_encode_to(g, &w);
  *size = w.pos;
  return r;
}

afm_result afm_geometry_encode(const afm_geometry *g, uint8_t *out, size_t size) {
  afm_writer w;
  if (!g || !out) return AFM_ERR_ARGUMENT;
  w.data = out;
  w.size = size;
  w.pos = 0;
  w.overflow = 0;
  return afm_geometry_encode_to(g, &w);
}
