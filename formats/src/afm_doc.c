/* The whole document: reading, writing and transcoding (formats/afm.md). */
#include <stdlib.h>
#include <string.h>

#include "afm_internal.h"

/* ---- resolving chunks to raw payloads ------------------------------------ */

enum { kMeta, kGeom, kLift, kMtgt, kRigd, kKnownCount };

typedef struct raw_chunks {
  const uint8_t *data[kKnownCount]; /* raw payload, or NULL when absent */
  size_t size[kKnownCount];
  uint64_t offset[kKnownCount];     /* of the chunk in the file, for messages */
  uint8_t *owned[kKnownCount];      /* transcoded payloads to free */
  uint32_t skipped;
} raw_chunks;

static int known_index(uint32_t kind) {
  switch (kind) {
    case AFM_CHUNK_META: return kMeta;
    case AFM_CHUNK_GEOM: return kGeom;
    case AFM_CHUNK_LIFT: return kLift;
    case AFM_CHUNK_MTGT: return kMtgt;
    case AFM_CHUNK_RIGD: return kRigd;
    default: return -1;
  }
}

static void release_chunks(raw_chunks *rc, const afm_allocator *allocator) {
  int i;
  for (i = 0; i < kKnownCount; ++i) afm_free(allocator, rc->owned[i]);
  memset(rc, 0, sizeof *rc);
}

/* Opens the container, picks the known chunks, refuses unknown required
 * ones and decodes draco payloads to raw through the codec. */
static afm_result resolve_chunks(const uint8_t *data, size_t size, const afm_read_options *opt,
                                 const afm_allocator *allocator, raw_chunks *rc) {
  afm_container c;
  afm_diag *diag = opt ? opt->diag : NULL;
  const afm_chunk_codec *draco = opt ? opt->draco : NULL;
  afm_result res;
  uint32_t i;

  memset(rc, 0, sizeof *rc);
  res = afm_container_open(data, size, &c, diag);
  if (res != AFM_OK) return res;
  for (i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    int k;
    char name[5];
    afm_container_chunk(&c, i, &ch);
    k = known_index(ch.kind);
    afm_fourcc_text(ch.kind, name);
    if (k < 0 || ch.encoding > AFM_ENCODING_DRACO) {
      if (ch.flags & AFM_CHUNK_REQUIRED) {
        afm_diag_set(diag, ch.kind, ch.offset,
                     k < 0 ? "required chunk '%s' unknown to this reader"
                           : "required chunk '%s' has unknown encoding",
                     name);
        release_chunks(rc, allocator);
        return AFM_ERR_UNKNOWN_REQUIRED;
      }
      rc->skipped++;
      continue;
    }
    if (rc->data[k]) {
      afm_diag_set(diag, ch.kind, ch.offset, "chunk '%s' appears twice", name);
      release_chunks(rc, allocator);
      return AFM_ERR_DUPLICATE_CHUNK;
    }
    rc->offset[k] = ch.offset;
    if (ch.encoding == AFM_ENCODING_RAW) {
      rc->data[k] = ch.data;
      rc->size[k] = ch.length;
      continue;
    }
    if (!draco || !draco->to_raw) {
      afm_diag_set(diag, ch.kind, ch.offset,
                   "chunk is draco-encoded; link the Draco codec (afm/draco.h) or convert the "
                   "file with 'afm-pack --raw'");
      release_chunks(rc, allocator);
      return AFM_ERR_NEED_DRACO;
    }
    res = draco->to_raw(draco->ctx, ch.kind, ch.data, ch.length, allocator, &rc->owned[k],
                        &rc->size[k], diag);
    if (res != AFM_OK) {
      release_chunks(rc, allocator);
      return res;
    }
    rc->data[k] = rc->owned[k];
  }
  if (!rc->data[kMeta] || !rc->data[kGeom]) {
    afm_diag_set(diag, rc->data[kMeta] ? AFM_CHUNK_GEOM : AFM_CHUNK_META, 0,
                 "required chunk missing");
    release_chunks(rc, allocator);
    return AFM_ERR_MISSING_CHUNK;
  }
  return AFM_OK;
}

/* Decodes resolved raw payloads into the arena (or measures when the arena
 * has no base). Cross-chunk checks live here. */
static afm_result decode_chunks(const raw_chunks *rc, afm_diag *diag, afm_arena *arena,
                                afm_doc **out) {
  afm_doc scratch, *doc;
  afm_meta meta;
  afm_geometry geom;
  afm_target *targets = NULL;
  afm_rigid *rigids = NULL;
  afm_lift *lift = NULL;
  uint32_t target_count = 0, rigid_count = 0, control_count = 0, i;
  afm_result res;

  doc = (afm_doc *)afm_arena_take(arena, sizeof *doc);
  res = afm_meta_decode(rc->data[kMeta], rc->size[kMeta], rc->offset[kMeta], arena, &meta, diag);
  if (res != AFM_OK) return res;
  res = afm_geometry_decode_at(rc->data[kGeom], rc->size[kGeom], rc->offset[kGeom], arena, &geom,
                               diag);
  if (res != AFM_OK) return res;
  if (rc->data[kLift]) {
    res = afm_lift_decode(rc->data[kLift], rc->size[kLift], rc->offset[kLift], geom.vertex_count,
                          arena, &lift, diag);
    if (res != AFM_OK) return res;
    /* Measuring gives no struct: read the count (checked to fit with V). */
    control_count = afm_load_u32(rc->data[kLift]);
  }
  if (rc->data[kMtgt]) {
    res = afm_targets_decode_at(rc->data[kMtgt], rc->size[kMtgt], rc->offset[kMtgt],
                                geom.vertex_count, control_count, arena, &target_count, &targets,
                                diag);
    if (res != AFM_OK) return res;
    res = afm_lift_check_targets(lift, targets, target_count, rc->offset[kMtgt], diag);
    if (res != AFM_OK) return res;
  }
  if (rc->data[kRigd]) {
    res = afm_rigids_decode(rc->data[kRigd], rc->size[kRigd], rc->offset[kRigd], geom.part_count,
                            arena, &rigid_count, &rigids, diag);
    if (res != AFM_OK) return res;
  }
  for (i = 0; meta.fdps && i < meta.fdp_count; ++i) {
    if (meta.fdps[i].vertex != AFM_NONE && meta.fdps[i].vertex >= geom.vertex_count) {
      afm_diag_set(diag, AFM_CHUNK_META, rc->offset[kMeta],
                   "FDP %u.%u: vertex %lu >= vertex_count %lu", meta.fdps[i].group,
                   meta.fdps[i].index, (unsigned long)meta.fdps[i].vertex,
                   (unsigned long)geom.vertex_count);
      return AFM_ERR_RANGE;
    }
  }
  if (!doc) doc = &scratch;
  doc->meta = meta;
  doc->geometry = geom;
  doc->target_count = target_count;
  doc->targets = targets;
  doc->rigid_count = rigid_count;
  doc->rigids = rigids;
  doc->skipped_chunks = rc->skipped;
  doc->lift = lift;
  if (out) *out = doc;
  return AFM_OK;
}

/* Full validation needs the decoded values: measure, decode into temporary
 * memory, free. */
static afm_result validate_chunks(const raw_chunks *rc, afm_diag *diag,
                                  const afm_allocator *allocator) {
  afm_arena arena = {NULL, 0, 0};
  afm_result res = decode_chunks(rc, diag, &arena, NULL);
  if (res != AFM_OK) return res;
  if (arena.used == SIZE_MAX) return AFM_ERR_LIMIT;
  arena.base = (uint8_t *)afm_alloc(allocator, arena.used ? arena.used : 1);
  if (!arena.base) return AFM_ERR_OUT_OF_MEMORY;
  arena.size = arena.used;
  arena.used = 0;
  res = decode_chunks(rc, diag, &arena, NULL);
  afm_free(allocator, arena.base);
  return res;
}

/* ---- reading --------------------------------------------------------------- */

afm_result afm_doc_measure(const uint8_t *data, size_t size, const afm_read_options *options,
                           size_t *bytes) {
  raw_chunks rc;
  afm_arena arena = {NULL, 0, 0};
  afm_result res;
  if (!data || !bytes) return AFM_ERR_ARGUMENT;
  res = resolve_chunks(data, size, options, NULL, &rc);
  if (res != AFM_OK) return res;
  res = decode_chunks(&rc, options ? options->diag : NULL, &arena, NULL);
  release_chunks(&rc, NULL);
  if (res == AFM_OK && arena.used == SIZE_MAX) res = AFM_ERR_LIMIT;
  *bytes = arena.used;
  return res;
}

afm_result afm_doc_read(const uint8_t *data, size_t size, const afm_read_options *options,
                        void *buffer, size_t buffer_size, afm_doc **doc) {
  raw_chunks rc;
  afm_arena arena;
  afm_result res;
  if (!data || !buffer || !doc || ((uintptr_t)buffer & 7u)) return AFM_ERR_ARGUMENT;
  res = resolve_chunks(data, size, options, NULL, &rc);
  if (res != AFM_OK) return res;
  arena.base = (uint8_t *)buffer;
  arena.size = buffer_size;
  arena.used = 0;
  res = decode_chunks(&rc, options ? options->diag : NULL, &arena, doc);
  release_chunks(&rc, NULL);
  if (res == AFM_OK && arena.used > buffer_size) res = AFM_ERR_BUFFER_TOO_SMALL;
  return res;
}

afm_result afm_doc_read_alloc(const uint8_t *data, size_t size, const afm_read_options *options,
                              const afm_allocator *allocator, afm_doc **doc) {
  raw_chunks rc;
  afm_arena arena = {NULL, 0, 0};
  afm_diag *diag = options ? options->diag : NULL;
  afm_result res;
  if (!data || !doc) return AFM_ERR_ARGUMENT;
  *doc = NULL;
  res = resolve_chunks(data, size, options, allocator, &rc);
  if (res != AFM_OK) return res;
  res = decode_chunks(&rc, diag, &arena, NULL);
  if (res == AFM_OK && arena.used == SIZE_MAX) res = AFM_ERR_LIMIT;
  if (res == AFM_OK) {
    size_t need = arena.used;
    arena.base = (uint8_t *)afm_alloc(allocator, need ? need : 1);
    arena.size = need;
    arena.used = 0;
    if (!arena.base) {
      res = AFM_ERR_OUT_OF_MEMORY;
    } else {
      res = decode_chunks(&rc, diag, &arena, doc);
      if (res != AFM_OK || arena.used > need) {
        afm_free(allocator, arena.base);
        *doc = NULL;
        if (res == AFM_OK) res = AFM_ERR_BUFFER_TOO_SMALL; /* a measuring bug */
      }
    }
  }
  release_chunks(&rc, allocator);
  return res;
}

/* ---- writing --------------------------------------------------------------- */

typedef afm_result (*encode_fn)(const void *what, afm_writer *w);

static afm_result enc_meta(const void *p, afm_writer *w) {
  return afm_meta_encode((const afm_meta *)p, w);
}
static afm_result enc_geom(const void *p, afm_writer *w) {
  return afm_geometry_encode_to((const afm_geometry *)p, w);
}
static afm_result enc_lift(const void *p, afm_writer *w) {
  return afm_lift_encode((const afm_lift *)p, w);
}
static afm_result enc_targets(const void *p, afm_writer *w) {
  const afm_doc *d = (const afm_doc *)p;
  return afm_targets_encode_to(d->targets, d->target_count, w);
}
static afm_result enc_rigids(const void *p, afm_writer *w) {
  const afm_doc *d = (const afm_doc *)p;
  return afm_rigids_encode(d->rigids, d->rigid_count, w);
}

/* Two passes over one encoder: count, allocate, write. */
static afm_result encode_payload(encode_fn fn, const void *what, const afm_allocator *allocator,
                                 uint8_t **out, size_t *size) {
  afm_writer w = {NULL, 0, 0, 0};
  afm_result res = fn(what, &w);
  if (res != AFM_OK) return res;
  *size = w.pos;
  *out = (uint8_t *)afm_alloc(allocator, w.pos ? w.pos : 1);
  if (!*out) return AFM_ERR_OUT_OF_MEMORY;
  w.data = *out;
  w.size = *size;
  w.pos = 0;
  return fn(what, &w);
}

afm_result afm_doc_write(const afm_doc *doc, const afm_write_options *options, uint8_t **out,
                         size_t *out_size) {
  static const uint32_t kinds[kKnownCount] = {AFM_CHUNK_META, AFM_CHUNK_GEOM, AFM_CHUNK_LIFT,
                                              AFM_CHUNK_MTGT, AFM_CHUNK_RIGD};
  const afm_allocator *alloc = options ? &options->allocator : NULL;
  afm_diag *diag = options ? options->diag : NULL;
  afm_profile profile = options ? options->profile : AFM_PROFILE_RAW;
  uint8_t *raw[kKnownCount] = {NULL, NULL, NULL, NULL, NULL};
  uint8_t *packed[kKnownCount] = {NULL, NULL, NULL, NULL, NULL};
  size_t raw_size[kKnownCount] = {0, 0, 0, 0, 0};
  afm_chunk_out chunks[kKnownCount];
  uint32_t *tris = NULL, count = 0;
  afm_geometry geom;
  raw_chunks rc;
  afm_result res = AFM_OK;
  size_t total;
  int k;

  if (!doc || !out || !out_size) return AFM_ERR_ARGUMENT;
  *out = NULL;
  *out_size = 0;
  if (profile != AFM_PROFILE_RAW &&
      (profile != AFM_PROFILE_DRACO || !options->draco || !options->draco->from_raw))
    return AFM_ERR_ARGUMENT;

  /* The file stores triangles in canonical order; sort a copy. */
  geom = doc->geometry;
  if (geom.triangle_count) {
    size_t n = afm_mul_size(geom.triangle_count, 3 * sizeof *tris);
    if (n == SIZE_MAX || !geom.triangles || !geom.parts) return AFM_ERR_ARGUMENT;
    tris = (uint32_t *)afm_alloc(alloc, n);
    if (!tris) return AFM_ERR_OUT_OF_MEMORY;
    memcpy(tris, geom.triangles, n);
    /* Parts must tile before we trust their ranges for sorting. */
    {
      uint32_t p, t_end = 0;
      for (p = 0; p < geom.part_count; ++p) {
        if (geom.parts[p].first_triangle != t_end ||
            geom.parts[p].triangle_count > geom.triangle_count - t_end) {
          afm_diag_set(diag, AFM_CHUNK_GEOM, 0, "part %lu: triangle range does not tile",
                       (unsigned long)p);
          afm_free(alloc, tris);
          return AFM_ERR_RANGE;
        }
        t_end += geom.parts[p].triangle_count;
      }
    }
    afm_canonicalize_triangles(tris, geom.parts, geom.part_count);
    geom.triangles = tris;
  }

  res = encode_payload(enc_meta, &doc->meta, alloc, &raw[kMeta], &raw_size[kMeta]);
  if (res == AFM_OK) res = encode_payload(enc_geom, &geom, alloc, &raw[kGeom], &raw_size[kGeom]);
  if (res == AFM_OK && doc->lift)
    res = encode_payload(enc_lift, doc->lift, alloc, &raw[kLift], &raw_size[kLift]);
  if (res == AFM_OK && doc->target_count)
    res = encode_payload(enc_targets, doc, alloc, &raw[kMtgt], &raw_size[kMtgt]);
  if (res == AFM_OK && doc->rigid_count)
    res = encode_payload(enc_rigids, doc, alloc, &raw[kRigd], &raw_size[kRigd]);

  /* Validate exactly as a reader will, before anything is packed. */
  if (res == AFM_OK) {
    memset(&rc, 0, sizeof rc);
    for (k = 0; k < kKnownCount; ++k) {
      rc.data[k] = raw[k];
      rc.size[k] = raw_size[k];
    }
    res = validate_chunks(&rc, diag, alloc);
  }

  for (k = 0; k < kKnownCount && res == AFM_OK; ++k) {
    if (!raw[k]) continue;
    chunks[count].kind = kinds[k];
    chunks[count].flags = AFM_CHUNK_REQUIRED;
    chunks[count].encoding = AFM_ENCODING_RAW;
    chunks[count].data = raw[k];
    chunks[count].length = raw_size[k];
    if (profile == AFM_PROFILE_DRACO && (k == kGeom || k == kLift || k == kMtgt)) {
      size_t n = 0;
      res = options->draco->from_raw(options->draco->ctx, kinds[k], raw[k], raw_size[k], alloc,
                                     &packed[k], &n, diag);
      if (res == AFM_OK && packed[k]) {
        chunks[count].encoding = AFM_ENCODING_DRACO;
        chunks[count].data = packed[k];
        chunks[count].length = n;
      }
    }
    ++count;
  }

  if (res == AFM_OK) res = afm_container_size(chunks, count, &total);
  if (res == AFM_OK) {
    *out = (uint8_t *)afm_alloc(alloc, total);
    if (!*out) res = AFM_ERR_OUT_OF_MEMORY;
  }
  if (res == AFM_OK) res = afm_container_write(chunks, count, *out, total);
  if (res == AFM_OK) {
    *out_size = total;
  } else {
    afm_free(alloc, *out);
    *out = NULL;
  }
  for (k = 0; k < kKnownCount; ++k) {
    afm_free(alloc, raw[k]);
    afm_free(alloc, packed[k]);
  }
  afm_free(alloc, tris);
  return res;
}

/* ---- transcoding ----------------------------------------------------------- */

afm_result afm_transcode(const uint8_t *data, size_t size, afm_profile profile,
                         const afm_chunk_codec *draco, const afm_allocator *allocator,
                         uint8_t **out, size_t *out_size, afm_diag *diag) {
  afm_read_options ro;
  afm_doc *check = NULL;
  afm_container c;
  afm_chunk_out *chunks = NULL;
  uint8_t **owned = NULL;
  size_t total;
  uint32_t i;
  afm_result res;

  if (!data || !out || !out_size) return AFM_ERR_ARGUMENT;
  *out = NULL;
  *out_size = 0;
  if (profile == AFM_PROFILE_DRACO && (!draco || !draco->from_raw)) return AFM_ERR_ARGUMENT;
  if (profile != AFM_PROFILE_RAW && profile != AFM_PROFILE_DRACO) return AFM_ERR_ARGUMENT;

  /* Never convert what a reader would refuse. */
  ro.draco = draco;
  ro.diag = diag;
  res = afm_doc_read_alloc(data, size, &ro, allocator, &check);
  afm_free(allocator, check);
  if (res != AFM_OK) return res;
  res = afm_container_open(data, size, &c, diag);
  if (res != AFM_OK) return res;

  chunks = (afm_chunk_out *)afm_alloc(allocator, (c.chunk_count + 1) * sizeof *chunks);
  owned = (uint8_t **)afm_alloc(allocator, (c.chunk_count + 1) * 2 * sizeof *owned);
  if (!chunks || !owned) {
    afm_free(allocator, chunks);
    afm_free(allocator, owned);
    return AFM_ERR_OUT_OF_MEMORY;
  }
  memset(owned, 0, (c.chunk_count + 1) * 2 * sizeof *owned);

  for (i = 0; i < c.chunk_count && res == AFM_OK; ++i) {
    afm_chunk_info ch;
    const uint8_t *raw;
    size_t raw_len;
    afm_container_chunk(&c, i, &ch);
    chunks[i].kind = ch.kind;
    chunks[i].flags = ch.flags;
    chunks[i].encoding = ch.encoding;
    chunks[i].data = ch.data;
    chunks[i].length = ch.length;
    if ((ch.kind != AFM_CHUNK_GEOM && ch.kind != AFM_CHUNK_LIFT && ch.kind != AFM_CHUNK_MTGT) ||
        ch.encoding > AFM_ENCODING_DRACO)
      continue; /* copied as is */
    raw = ch.data;
    raw_len = ch.length;
    if (ch.encoding == AFM_ENCODING_DRACO) {
      res = draco->to_raw(draco->ctx, ch.kind, ch.data, ch.length, allocator, &owned[2 * i],
                          &raw_len, diag);
      if (res != AFM_OK) break;
      raw = owned[2 * i];
    }
    chunks[i].encoding = AFM_ENCODING_RAW;
    chunks[i].data = raw;
    chunks[i].length = raw_len;
    if (profile == AFM_PROFILE_DRACO) {
      size_t n = 0;
      res = draco->from_raw(draco->ctx, ch.kind, raw, raw_len, allocator, &owned[2 * i + 1], &n,
                            diag);
      if (res == AFM_OK && owned[2 * i + 1]) {
        chunks[i].encoding = AFM_ENCODING_DRACO;
        chunks[i].data = owned[2 * i + 1];
        chunks[i].length = n;
      }
    }
  }
  if (res == AFM_OK) res = afm_container_size(chunks, c.chunk_count, &total);
  if (res == AFM_OK) {
    *out = (uint8_t *)afm_alloc(allocator, total);
    if (!*out) res = AFM_ERR_OUT_OF_MEMORY;
  }
  if (res == AFM_OK) res = afm_container_write(chunks, c.chunk_count, *out, total);
  if (res == AFM_OK) {
    *out_size = total;
  } else {
    afm_free(allocator, *out);
    *out = NULL;
  }
  for (i = 0; i < 2 * (c.chunk_count + 1); ++i) afm_free(allocator, owned[i]);
  afm_free(allocator, owned);
  afm_free(allocator, chunks);
  return res;
}
