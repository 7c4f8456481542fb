/* afm-info: what an AFM file holds. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "afm/draco.h"
#include "afm/format.h"
#include "afm/mpeg4.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: afm-info [--fdps] [--targets] FILE.afm\n"
          "\n"
          "Prints an Animatable Face Model's chunks (kind, encoding, size, CRC), model\n"
          "name, FAPU, parts, quantisation, morph targets, control points (LIFT) and\n"
          "rigid parts.\n"
          "\n"
          "  --fdps      list every feature point\n"
          "  --targets   list every morph target (default: a summary per kind)\n"
          "  --help      this text\n"
          "\n"
          "Exit status: 0 when the file is valid, 1 when it is not, 2 on bad usage.\n");
}

static const char *target_kind(uint8_t k) {
  return k == AFM_TARGET_FAP           ? "FAP"
         : k == AFM_TARGET_VISEME      ? "viseme"
         : k == AFM_TARGET_COMBINATION ? "comb"
                                       : "expression";
}

static const char *target_name(const afm_target *t) {
  if (t->kind == AFM_TARGET_FAP || t->kind == AFM_TARGET_COMBINATION) {
    const afm_fap_info *f = afm_fap(t->number);
    return f ? f->name : "?";
  }
  if (t->kind == AFM_TARGET_VISEME) return afm_viseme_name(t->number);
  return afm_expression_name(t->number);
}

static const char *rigid_kind(uint8_t k) {
  switch (k) {
    case AFM_RIGID_EYE_LEFT: return "eye_left";
    case AFM_RIGID_EYE_RIGHT: return "eye_right";
    case AFM_RIGID_JAW: return "jaw";
    case AFM_RIGID_HEAD: return "head";
    default: return "?";
  }
}

static void print_chunks(const afm_container *c) {
  uint32_t i;
  printf("chunks: %u (format %u.%u)\n", (unsigned)c->chunk_count, (unsigned)c->major,
         (unsigned)c->minor);
  printf("  kind  encoding  required  offset      bytes  crc32\n");
  for (i = 0; i < c->chunk_count; ++i) {
    afm_chunk_info ch;
    char kind[5];
    int k;
    afm_container_chunk(c, i, &ch);
    for (k = 0; k < 4; ++k) {
      unsigned b = (ch.kind >> (8 * k)) & 0xFFu;
      kind[k] = (b >= 0x20 && b < 0x7F) ? (char)b : '?';
    }
    kind[4] = '\0';
    printf("  %-4s  %-8s  %-8s  %8lu  %9lu  %08lx\n", kind,
           ch.encoding == AFM_ENCODING_RAW     ? "raw"
           : ch.encoding == AFM_ENCODING_DRACO ? "draco"
                                               : "?",
           (ch.flags & AFM_CHUNK_REQUIRED) ? "yes" : "no", (unsigned long)ch.offset,
           (unsigned long)ch.length, (unsigned long)ch.crc32);
  }
}

static void print_meta(const afm_doc *d, int list_fdps) {
  const afm_meta *m = &d->meta;
  const char *u = m->units[0] ? m->units : "model units";
  uint32_t i;
  printf("model: %s\n", m->name[0] ? m->name : "(unnamed)");
  printf("units: %s\n", m->units[0] ? m->units : "(unknown)");
  printf("generator: %s\n", m->generator[0] ? m->generator : "(unknown)");
  printf("FAPU (X0, %s): ES0 %.6g  IRISD0 %.6g  ENS0 %.6g  MNS0 %.6g  MW0 %.6g\n", u,
         (double)m->es0, (double)m->irisd0, (double)m->ens0, (double)m->mns0, (double)m->mw0);
  printf("FDPs: %u\n", (unsigned)m->fdp_count);
  if (!list_fdps) return;
  for (i = 0; i < m->fdp_count; ++i) {
    const afm_fdp_point *p = &m->fdps[i];
    const afm_fdp_info *info = afm_fdp_find(p->group, p->index);
    char vertex[16];
    if (p->vertex == AFM_NONE)
      strcpy(vertex, "free");
    else
      snprintf(vertex, sizeof vertex, "%lu", (unsigned long)p->vertex);
    printf("  %2u.%-2u  vertex %-7s  (%+.5g %+.5g %+.5g)  %s\n", p->group, p->index, vertex,
           (double)p->pos[0], (double)p->pos[1], (double)p->pos[2],
           info ? info->description : "");
  }
}

static void print_geometry(const afm_doc *d) {
  const afm_geometry *g = &d->geometry;
  uint32_t p;
  printf("geometry: %lu vertices, %lu triangles, %lu parts; attributes:%s%s%s%s\n",
         (unsigned long)g->vertex_count, (unsigned long)g->triangle_count,
         (unsigned long)g->part_count, "", (g->attributes & AFM_ATTR_NORMALS) ? " normals" : "",
         (g->attributes & AFM_ATTR_TEXCOORDS) ? " texcoords" : "",
         (g->attributes & AFM_ATTR_COLORS) ? " colours" : "");
  printf("quantisation: positions int16, step %.6g %s (range %.6g), origin (%.6g %.6g %.6g);"
         " normals Q14",
         (double)g->step, d->meta.units[0] ? d->meta.units : "units", (double)g->step * 65535.0,
         (double)g->origin[0], (double)g->origin[1], (double)g->origin[2]);
  if (g->attributes & AFM_ATTR_TEXCOORDS)
    printf("; uv uint16, step %.3g x %.3g", (double)g->uv_step[0], (double)g->uv_step[1]);
  printf("\n");
  printf("  part                      kind          vertices  triangles  texture\n");
  for (p = 0; p < g->part_count; ++p) {
    const afm_part *a = &g->parts[p];
    printf("  %-24s  %-12s  %8lu  %9lu  %s\n", a->name, afm_part_kind_name(a->kind),
           (unsigned long)a->vertex_count, (unsigned long)a->triangle_count,
           a->texture[0] ? a->texture : "-");
  }
}

static void print_targets(const afm_doc *d, int list) {
  uint32_t i, counts[4] = {0, 0, 0, 0};
  unsigned long deltas = 0, runs = 0;
  for (i = 0; i < d->target_count; ++i) {
    counts[d->targets[i].kind < 4 ? d->targets[i].kind : 0]++;
    deltas += d->targets[i].delta_count;
    runs += d->targets[i].run_count;
  }
  printf("morph targets: %lu (%lu FAP, %lu viseme, %lu expression, %lu combination); %lu deltas in %lu runs;"
         " deltas int16 in position quanta\n",
         (unsigned long)d->target_count, (unsigned long)counts[0], (unsigned long)counts[1],
         (unsigned long)counts[2], (unsigned long)counts[3], deltas, runs);
  if (d->lift)
    printf("control points (LIFT): %lu, driving %lu vertices in %lu run(s); target entries from %lu on are "
           "controls\n",
           (unsigned long)d->lift->control_count, (unsigned long)d->lift->bound_count,
           (unsigned long)d->lift->run_count, (unsigned long)d->geometry.vertex_count);
  if (!list) return;
  printf("  kind        no  name                          reference   runs  entries   normals\n");
  for (i = 0; i < d->target_count; ++i) {
    const afm_target *t = &d->targets[i];
    printf("  %-10s  %2u  %-28s  %9ld  %5lu  %8lu  %s\n", target_kind(t->kind), t->number,
           target_name(t), (long)t->reference, (unsigned long)t->run_count,
           (unsigned long)t->delta_count, (t->flags & AFM_TARGET_NORMALS) ? "yes" : "no");
    if (t->kind == AFM_TARGET_COMBINATION)
      printf("  %-10s  %2s  gated by FAP %u (%s) at %ld\n", "", "", (unsigned)t->gate,
             afm_fap(t->gate) ? afm_fap(t->gate)->name : "?", (long)t->gate_reference);
  }
}

static void print_rigids(const afm_doc *d) {
  uint32_t i, k;
  const afm_geometry *g = &d->geometry;
  printf("rigid parts: %lu\n", (unsigned long)d->rigid_count);
  for (i = 0; i < d->rigid_count; ++i) {
    const afm_rigid *r = &d->rigids[i];
    printf("  %-9s pivot (%.5g %.5g %.5g) moves", rigid_kind(r->kind),
           (double)(g->origin[0] + (float)r->pivot[0] * g->step),
           (double)(g->origin[1] + (float)r->pivot[1] * g->step),
           (double)(g->origin[2] + (float)r->pivot[2] * g->step));
    for (k = 0; k < r->part_count; ++k) printf(" %s", g->parts[r->parts[k]].name);
    printf("; FAPs");
    for (k = 0; k < r->control_count; ++k) {
      printf(" %u", r->controls[k].fap);
      if (r->controls[k].knot) printf(" (beyond %d)", r->controls[k].knot);
    }
    printf("\n");
  }
}

int main(int argc, char **argv) {
  const char *path = NULL;
  int list_fdps = 0, list_targets = 0, i;
  uint8_t *data = NULL;
  size_t size = 0;
  afm_container c;
  afm_diag diag;
  afm_read_options ro;
  afm_doc *doc = NULL;
  afm_result r;

  for (i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
      usage(stdout);
      return 0;
    } else if (!strcmp(argv[i], "--fdps")) {
      list_fdps = 1;
    } else if (!strcmp(argv[i], "--targets")) {
      list_targets = 1;
    } else if (argv[i][0] == '-' && argv[i][1]) {
      fprintf(stderr, "afm-info: unknown option '%s' (see --help)\n", argv[i]);
      return 2;
    } else if (path) {
      fprintf(stderr, "afm-info: one file at a time (see --help)\n");
      return 2;
    } else {
      path = argv[i];
    }
  }
  if (!path) {
    usage(stderr);
    return 2;
  }
  r = afm_file_read(path, NULL, &data, &size);
  if (r != AFM_OK) {
    fprintf(stderr, "afm-info: %s: cannot read: %s\n", path,
            r == AFM_ERR_IO ? strerror(errno) : afm_result_string(r));
    return 1;
  }
  memset(&diag, 0, sizeof diag);
  r = afm_container_open(data, size, &c, &diag);
  if (r == AFM_OK) {
    printf("file: %s (%lu bytes)\n", path, (unsigned long)size);
    print_chunks(&c);
    ro.draco = afm_draco_codec();
    ro.diag = &diag;
    r = afm_doc_read_alloc(data, size, &ro, NULL, &doc);
  }
  if (r != AFM_OK) {
    if (diag.message[0])
      fprintf(stderr, "afm-info: %s: %s (at byte %lu)\n", path, diag.message,
              (unsigned long)diag.offset);
    else
      fprintf(stderr, "afm-info: %s: %s\n", path, afm_result_string(r));
    free(data);
    return 1;
  }
  print_meta(doc, list_fdps);
  print_geometry(doc);
  print_targets(doc, list_targets);
  print_rigids(doc);
  if (doc->skipped_chunks)
    printf("skipped: %lu unknown optional chunks\n", (unsigned long)doc->skipped_chunks);
  afm_free(NULL, doc);
  free(data);
  return 0;
}
