/* AFM: the Animatable Face Model file. Reader, writer and in-memory form.
 *
 * The byte-exact specification is formats/afm.md; this header is its C API.
 * C99, no dependencies but the C library, no global state.
 *
 * Layers:
 *   1. Container: afm_container_open() checks the magic, version, chunk table
 *      and every CRC of a file in memory; afm_container_chunk() lists chunks.
 *      afm_container_write() assembles chunks into a file.
 *   2. Document: afm_doc_measure() + afm_doc_read() decode the whole file into
 *      one caller-owned buffer (size query, then init into the buffer); no
 *      allocation. afm_doc_write() encodes a document (this one allocates,
 *      through the allocator in its options).
 *   3. Chunk codec hooks (afm_chunk_codec) transcode draco-encoded chunks to
 *      and from their raw form. libafm_format knows only the raw encoding;
 *      afm_draco_codec() from afm/draco.h supplies Draco.
 *
 * Units: positions and position deltas are integer "quanta" on the model's
 * grid, model = origin + quanta * step (GEOM chunk). Unit vectors (normals,
 * normal deltas, rigid axes) are Q14: value / 16384. FAP reference values
 * are in FAP units. Strings are UTF-8 and NUL-terminated in memory.
 *
 * Errors: every fallible function returns afm_result. Functions that parse
 * take an optional afm_diag to which they write a message naming the chunk,
 * the field and the byte offset. On error, outputs are unspecified except
 * that nothing is allocated and nothing outside the given buffers is written.
 */
#ifndef AFM_FORMAT_H
#define AFM_FORMAT_H

#include <stddef.h>
#include <stdint.h>

#include "afm/mpeg4.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- results ------------------------------------------------------------ */

typedef enum afm_result {
  AFM_OK = 0,
  AFM_ERR_ARGUMENT = 1,          /* NULL where a value is needed, bad option */
  AFM_ERR_TRUNCATED = 2,         /* the data ends inside a field */
  AFM_ERR_MAGIC = 3,             /* not an AFM file */
  AFM_ERR_VERSION = 4,           /* major version this reader does not know */
  AFM_ERR_HEADER_CRC = 5,        /* header or chunk table damaged */
  AFM_ERR_CHUNK_TABLE = 6,       /* offsets/lengths overlap, leave gaps or misalign */
  AFM_ERR_CHUNK_CRC = 7,         /* a chunk's payload damaged */
  AFM_ERR_TRAILING_BYTES = 8,    /* bytes after the last chunk or after a chunk's fields */
  AFM_ERR_UNKNOWN_REQUIRED = 9,  /* required chunk of unknown kind or encoding */
  AFM_ERR_MISSING_CHUNK = 10,    /* META or GEOM absent */
  AFM_ERR_DUPLICATE_CHUNK = 11,  /* a known chunk kind appears twice */
  AFM_ERR_RANGE = 12,            /* a field out of its range (index, enum, count) */
  AFM_ERR_NEED_DRACO = 13,       /* draco-encoded chunk and no Draco codec given */
  AFM_ERR_DRACO = 14,            /* the Draco codec failed */
  AFM_ERR_BUFFER_TOO_SMALL = 15, /* caller's buffer smaller than measured */
  AFM_ERR_OUT_OF_MEMORY = 16,
  AFM_ERR_IO = 17,               /* open, read, write or rename failed */
  AFM_ERR_LIMIT = 18,            /* beyond a format limit (4 GiB file, 65535 parts) */
  AFM_ERR_SYNTAX = 19,           /* a text stream (.fap) does not parse; see afm_diag.line */
  AFM_ERR_STATE = 20             /* a call out of order (e.g. feeding a finished reader) */
} afm_result;

/* Short English text for a result ("chunk CRC mismatch"). Never NULL. */
const char *afm_result_string(afm_result result);

/* Where a parse failed. Fill-in only; zero-initialise it before use. */
typedef struct afm_diag {
  char message[256]; /* e.g. "GEOM: triangle 12: index 5001 >= part end 5000" */
  uint32_t chunk;    /* fourcc of the chunk being read, 0 for the container */
  uint64_t offset;   /* byte offset in the file of the offending field */
  uint32_t line;     /* text streams: 1-based line of the error; 0 otherwise */
} afm_diag;

/* An allocator passed per call. Zeroed: malloc and free. */
typedef struct afm_allocator {
  void *(*alloc)(void *ctx, size_t size);
  void (*free)(void *ctx, void *ptr);
  void *ctx;
} afm_allocator;

void *afm_alloc(const afm_allocator *allocator, size_t size); /* NULL allocator: malloc */
void afm_free(const afm_allocator *allocator, void *ptr);

/* ---- container ---------------------------------------------------------- */

#define AFM_MAGIC_SIZE 8          /* 0x89 'A' 'F' 'M' '\r' '\n' 0x1A '\n' */
#define AFM_VERSION_MAJOR 1
#define AFM_VERSION_MINOR 4 /* 1.1 added LIFT, 1.2 in-between targets, 1.3 control knots,
                              1.4 combination targets */

#define AFM_FOURCC(a, b, c, d)                                        \
  ((uint32_t)(uint8_t)(a) | ((uint32_t)(uint8_t)(b) << 8) |           \
   ((uint32_t)(uint8_t)(c) << 16) | ((uint32_t)(uint8_t)(d) << 24))
#define AFM_CHUNK_META AFM_FOURCC('M', 'E', 'T', 'A')
#define AFM_CHUNK_GEOM AFM_FOURCC('G', 'E', 'O', 'M')
#define AFM_CHUNK_MTGT AFM_FOURCC('M', 'T', 'G', 'T')
#define AFM_CHUNK_RIGD AFM_FOURCC('R', 'I', 'G', 'D')
#define AFM_CHUNK_LIFT AFM_FOURCC('L', 'I', 'F', 'T')

#define AFM_CHUNK_REQUIRED 0x0001u /* flag: a reader that does not know it must refuse the file */

typedef enum afm_encoding {
  AFM_ENCODING_RAW = 0,   /* little-endian quantised arrays, formats/afm.md */
  AFM_ENCODING_DRACO = 1  /* Draco bitstreams, formats/afm.md */
} afm_encoding;

typedef struct afm_chunk_info {
  uint32_t kind;       /* fourcc */
  uint16_t flags;      /* AFM_CHUNK_REQUIRED */
  uint16_t encoding;   /* afm_encoding */
  uint32_t offset;     /* from the start of the file */
  uint32_t length;     /* payload bytes, a multiple of 4 */
  uint32_t crc32;      /* CRC-32 (ISO-HDLC, as zlib) of the payload */
  const uint8_t *data; /* the payload, inside the container's data */
} afm_chunk_info;

typedef struct afm_container {
  const uint8_t *data; /* borrowed: the caller keeps it alive */
  size_t size;
  uint16_t major, minor;
  uint32_t chunk_count;
} afm_container;

/* Validates magic, version, chunk table and all CRCs. No allocation. */
afm_result afm_container_open(const uint8_t *data, size_t size, afm_container *container,
                              afm_diag *diag);
/* Chunk i (0-based, i < chunk_count) of an opened container. */
afm_result afm_container_chunk(const afm_container *container, uint32_t i,
                               afm_chunk_info *chunk);

/* A chunk to write: kind, flags, encoding and payload (length % 4 == 0). */
typedef struct afm_chunk_out {
  uint32_t kind;
  uint16_t flags;
  uint16_t encoding;
  const uint8_t *data;
  size_t length;
} afm_chunk_out;

/* Bytes afm_container_write needs for these chunks; AFM_ERR_LIMIT past 4 GiB. */
afm_result afm_container_size(const afm_chunk_out *chunks, uint32_t count, size_t *size);
/* Writes header, table and payloads into out[0..out_size). */
afm_result afm_container_write(const afm_chunk_out *chunks, uint32_t count, uint8_t *out,
                               size_t out_size);

uint32_t afm_crc32(const uint8_t *data, size_t size);

/* ---- document ----------------------------------------------------------- */

typedef enum afm_part_kind {
  AFM_PART_OTHER = 0,
  AFM_PART_SKIN = 1,        /* the simulated face surface (holds FDP 2.1) */
  AFM_PART_EYE_LEFT = 2,    /* the face's left eyeball */
  AFM_PART_EYE_RIGHT = 3,
  AFM_PART_TEETH_UPPER = 4,
  AFM_PART_TEETH_LOWER = 5,
  AFM_PART_TONGUE = 6,
  AFM_PART_HAIR = 7,
  AFM_PART_EYELID = 8,      /* lashes, lid strips */
  AFM_PART_MOUTH = 9,       /* mouth cavity, throat */
  AFM_PART_KIND_COUNT = 10
} afm_part_kind;

const char *afm_part_kind_name(uint8_t kind); /* "skin", ...; "?" when unknown */

#define AFM_NONE 0xFFFFFFFFu /* "no vertex" */

typedef struct afm_fdp_point {
  uint8_t group, index; /* FDP group.index, e.g. 2 and 1 */
  uint32_t vertex;      /* AFM vertex the point sits on, or AFM_NONE */
  float pos[3];         /* model units */
} afm_fdp_point;

typedef struct afm_meta {
  const char *name;      /* model name */
  const char *units;     /* "m", "cm", "mm" or "" */
  const char *generator; /* tool and version that wrote the file */
  /* FAPU distances X0 in model units (one FAP unit is X0 / 1024); 0 = unknown. */
  float es0, irisd0, ens0, mns0, mw0;
  uint32_t fdp_count;
  const afm_fdp_point *fdps;
} afm_meta;

/* The X0 of a distance unit in model units (a FAP unit is X0 / 1024): the
 * meta's es0, irisd0, ens0, mns0 or mw0; 0 for AFM_FAPU_AU, AFM_FAPU_NONE
 * and a distance the file does not know. */
float afm_meta_fapu_x0(const afm_meta *meta, afm_fapu unit);

typedef struct afm_part {
  const char *name;    /* unique in the file */
  const char *texture; /* image file name, "" when none */
  uint8_t kind;        /* afm_part_kind */
  uint8_t diffuse[4];  /* material RGBA8 */
  uint32_t first_vertex, vertex_count;     /* parts tile [0, vertex_count) in order */
  uint32_t first_triangle, triangle_count; /* and [0, triangle_count) */
} afm_part;

#define AFM_ATTR_NORMALS 0x1u
#define AFM_ATTR_TEXCOORDS 0x2u
#define AFM_ATTR_COLORS 0x4u

typedef struct afm_geometry {
  uint32_t vertex_count;   /* V */
  uint32_t triangle_count; /* T */
  uint32_t part_count;     /* P, 1..65535 */
  uint32_t attributes;     /* AFM_ATTR_* */
  float origin[3];         /* model = origin + quanta * step */
  float step;              /* model units per position quantum, > 0 */
  float uv_origin[2];      /* uv = uv_origin + quanta * uv_step */
  float uv_step[2];
  const afm_part *parts;   /* [P] */
  const int16_t *px, *py, *pz;   /* [V] position quanta, planar */
  const int16_t *nx, *ny, *nz;   /* [V] Q14 unit normals, or NULL */
  const uint16_t *u, *v;         /* [V] texture coordinate quanta, or NULL */
  const uint8_t *rgba;           /* [4V] vertex colours, or NULL */
  const uint32_t *triangles;     /* [3T] counter-clockwise seen from outside */
} afm_geometry;

typedef enum afm_target_kind {
  AFM_TARGET_FAP = 0,       /* low-level FAP 3..68 */
  AFM_TARGET_VISEME = 1,    /* viseme 1..14 */
  AFM_TARGET_EXPRESSION = 2, /* expression 1..6 */
  AFM_TARGET_COMBINATION = 3 /* FAP 3..68, gated by another FAP (since 1.4) */
} afm_target_kind;

#define AFM_TARGET_NORMALS 0x1u /* target flag: normal deltas present */

typedef struct afm_run {
  uint32_t start;  /* first vertex */
  uint32_t length; /* >= 1 */
} afm_run;

/* A morph target: the face at `reference` (FAP units; 63 for visemes and
 * expressions) minus the neutral face, over the vertices of its runs.
 * weight = value / reference. A target with reference > 0 serves positive
 * values (and negative ones by extrapolation when the FAP has no target of
 * its own with reference < 0).
 *
 * A combination target (since 1.4) is a correction added on top of other
 * targets, never a face alone: its weight is
 *   max(0, min(w, gate value / gate_reference)),
 * w the weight of the FAP target with the same number and reference (which
 * the file must hold). The builder stores the lower lip's motion past its
 * muscles' reach as one, gated by the jaw's opening (FAP 3): the lip goes
 * on only as far as the jaw carries it (formats/afm.md, MTGT). */
typedef struct afm_target {
  uint8_t kind;      /* afm_target_kind */
  uint8_t number;    /* FAP, viseme or expression number */
  uint8_t flags;     /* AFM_TARGET_NORMALS */
  int32_t reference; /* != 0 */
  uint8_t gate;           /* combination targets: the gating FAP 3..68, != number; else 0 */
  int32_t gate_reference; /* combination targets: the gate's value at weight 1, != 0; else 0 */
  uint32_t run_count;
  const afm_run *runs; /* [run_count] ascending, disjoint */
  uint32_t delta_count; /* N = sum of run lengths */
  const int16_t *dx, *dy, *dz; /* [N] position deltas in quanta, run after run */
  const int16_t *nx, *ny, *nz; /* [N] Q14 normal deltas, or NULL */
} afm_target;

/* Control points (LIFT chunk): vertices bound to three controls each, which
 * the morph targets move instead of them. With a lift, target runs index
 * entries [0, V + C): entry V + c is control c. A bound vertex's delta is
 * (w0 d[V+c0] + w1 d[V+c1] + w2 d[V+c2]) / 32768 quanta with
 * w0 = 32768 - w1 - w2 (afm_target_expand computes it). No target's runs
 * cover a bound vertex, and no target has normal deltas. */
typedef struct afm_lift {
  uint32_t control_count;       /* C >= 1 */
  uint32_t run_count;
  const afm_run *runs;          /* [run_count] bound vertices: ascending, disjoint, < V */
  uint32_t bound_count;         /* B = sum of run lengths */
  const uint32_t *c0, *c1, *c2; /* [B] control indices < C, run after run */
  const uint16_t *w1, *w2;      /* [B] Q15 weights of c1 and c2, w1 + w2 <= 32768 */
} afm_lift;

typedef enum afm_rigid_kind {
  AFM_RIGID_EYE_LEFT = 1,
  AFM_RIGID_EYE_RIGHT = 2,
  AFM_RIGID_JAW = 3,
  AFM_RIGID_HEAD = 4
} afm_rigid_kind;

typedef enum afm_dof {
  AFM_DOF_ROTATE_X = 0, /* about the rigid's local axes, right-hand rule */
  AFM_DOF_ROTATE_Y = 1,
  AFM_DOF_ROTATE_Z = 2,
  AFM_DOF_TRANSLATE_X = 3, /* along the local axes */
  AFM_DOF_TRANSLATE_Y = 4,
  AFM_DOF_TRANSLATE_Z = 5
} afm_dof;

/* One FAP driving one degree of freedom: motion = u * gain, where u is the
 * FAP value v's part beyond the knot (since 1.3): u = v when knot = 0;
 * v - knot when knot > 0 and v > knot, or knot < 0 and v < knot; else 0.
 * Controls of one FAP and dof with knots at its in-between targets'
 * references make the motion piecewise linear in v, as the targets are
 * (formats/afm.md, RIGD). Rotations: gain in AU (1e-5 rad) per FAP unit;
 * translations: position quanta per FAP unit. Q16.16. */
typedef struct afm_control {
  uint8_t fap; /* 3..68 */
  uint8_t dof; /* afm_dof */
  int32_t gain_q16;
  int16_t knot; /* FAP units; 0: the whole value */
} afm_control;

/* A rigid transform about a pivot: eyeballs, jaw, head. */
typedef struct afm_rigid {
  uint8_t kind;       /* afm_rigid_kind */
  int32_t pivot[3];   /* position quanta */
  int16_t axes[9];    /* Q14 rows: local x, y, z in model coordinates */
  uint16_t part_count;
  const uint16_t *parts; /* parts it moves */
  uint16_t control_count;
  const afm_control *controls;
} afm_rigid;

typedef struct afm_doc {
  afm_meta meta;
  afm_geometry geometry;
  uint32_t target_count;
  const afm_target *targets;
  uint32_t rigid_count;
  const afm_rigid *rigids;
  uint32_t skipped_chunks; /* unknown optional chunks the reader skipped */
  const afm_lift *lift;    /* control points, or NULL (no LIFT chunk) */
} afm_doc;

/* Entries a target's runs may index: V, plus C with a lift. */
uint64_t afm_doc_entry_count(const afm_doc *doc);

/* The position deltas target `t` (of doc) gives every entry, control
 * points lifted: out[3 * afm_doc_entry_count(doc)], x y z per entry, in
 * quanta times 32768 (Q15, exact: |value| < 2^30). The first 3V values are
 * the vertices' (bound ones included), the rest the controls' own.
 * AFM_ERR_ARGUMENT for NULLs; AFM_ERR_RANGE for a run past the entries.
 * O(entries + deltas), no allocation. */
afm_result afm_target_expand(const afm_doc *doc, const afm_target *t, int32_t *out);

/* ---- chunk codec hooks (Draco) ------------------------------------------ */

/* Transcodes chunk payloads between the raw encoding and another one. Both
 * functions get `ctx` back and allocate their output with `allocator`;
 * outputs are multiples of 4 bytes. See afm/draco.h for the Draco codec. */
typedef struct afm_chunk_codec {
  /* Decodes an encoded payload of chunk `kind` into its raw payload. */
  afm_result (*to_raw)(void *ctx, uint32_t kind, const uint8_t *data, size_t size,
                       const afm_allocator *allocator, uint8_t **raw, size_t *raw_size,
                       afm_diag *diag);
  /* Encodes a raw payload. Returns AFM_OK with *out == NULL when this codec
   * does not beat the raw encoding for the chunk (the writer keeps raw). */
  afm_result (*from_raw)(void *ctx, uint32_t kind, const uint8_t *raw, size_t raw_size,
                         const afm_allocator *allocator, uint8_t **out, size_t *out_size,
                         afm_diag *diag);
  void *ctx;
} afm_chunk_codec;

/* ---- reading ------------------------------------------------------------ */

typedef struct afm_read_options {
  const afm_chunk_codec *draco; /* NULL: draco chunks fail with AFM_ERR_NEED_DRACO */
  afm_diag *diag;               /* NULL: no message */
} afm_read_options;

/* Bytes afm_doc_read needs for this file. Checks the container and every
 * chunk's structure (lengths, counts, enums); the checks that need decoded
 * values (index ranges, duplicates, canonical order) run in afm_doc_read.
 * Raw-profile files are measured and read without any allocation. Draco
 * chunks are decoded through options->draco into temporary memory (malloc)
 * by each of the two calls; afm_doc_read_alloc decodes them only once. */
afm_result afm_doc_measure(const uint8_t *data, size_t size, const afm_read_options *options,
                           size_t *bytes);
/* Decodes into buffer[0..buffer_size) (8-byte aligned; malloc's alignment
 * suffices). *doc points into buffer; nothing points into `data`. */
afm_result afm_doc_read(const uint8_t *data, size_t size, const afm_read_options *options,
                        void *buffer, size_t buffer_size, afm_doc **doc);
/* Measure + allocate + read in one call; free with afm_free(allocator, *doc).
 * Temporary memory for draco chunks also comes from `allocator`. */
afm_result afm_doc_read_alloc(const uint8_t *data, size_t size, const afm_read_options *options,
                              const afm_allocator *allocator, afm_doc **doc);

/* ---- writing ------------------------------------------------------------ */

typedef enum afm_profile {
  AFM_PROFILE_RAW = 0,  /* every chunk raw: for embedded readers */
  AFM_PROFILE_DRACO = 1 /* GEOM, LIFT and MTGT through the codec where it is smaller */
} afm_profile;

typedef struct afm_write_options {
  afm_profile profile;          /* zero: raw */
  const afm_chunk_codec *draco; /* needed for AFM_PROFILE_DRACO */
  afm_allocator allocator;      /* zeroed: malloc/free */
  afm_diag *diag;
} afm_write_options;

/* Validates `doc` as the reader would, encodes it and returns the file in
 * *out (allocated with options->allocator; free with afm_free). */
afm_result afm_doc_write(const afm_doc *doc, const afm_write_options *options, uint8_t **out,
                         size_t *out_size);

/* Re-encodes every GEOM, LIFT and MTGT chunk of a file for `profile`, copying the
 * other chunks (known or not) unchanged. Quantised values are kept exactly. */
afm_result afm_transcode(const uint8_t *data, size_t size, afm_profile profile,
                         const afm_chunk_codec *draco, const afm_allocator *allocator,
                         uint8_t **out, size_t *out_size, afm_diag *diag);

/* ---- single chunks (used by codecs) ------------------------------------- */

/* Raw GEOM / MTGT payloads to and from their structs. `vertex_count` checks
 * MTGT run ranges (pass V + C for a file with control points). A NULL buffer with buffer_size 0 measures: *bytes gets the
 * size the struct needs. */
afm_result afm_geometry_decode(const uint8_t *raw, size_t size, void *buffer, size_t buffer_size,
                               size_t *bytes, afm_geometry *geometry, afm_diag *diag);
/* Only the header and part table (everything before the position arrays);
 * the array pointers stay NULL. *header_size gets the bytes consumed. */
afm_result afm_geometry_decode_header(const uint8_t *raw, size_t size, void *buffer,
                                      size_t buffer_size, size_t *bytes, size_t *header_size,
                                      afm_geometry *geometry, afm_diag *diag);
afm_result afm_geometry_encoded_size(const afm_geometry *geometry, size_t *size);
afm_result afm_geometry_encode(const afm_geometry *geometry, uint8_t *out, size_t size);

afm_result afm_targets_decode(const uint8_t *raw, size_t size, uint32_t vertex_count,
                              void *buffer, size_t buffer_size, size_t *bytes,
                              uint32_t *target_count, afm_target **targets, afm_diag *diag);
afm_result afm_targets_encoded_size(const afm_target *targets, uint32_t count, size_t *size);
afm_result afm_targets_encode(const afm_target *targets, uint32_t count, uint8_t *out,
                              size_t size);

/* Puts each part's triangles in the canonical order the GEOM chunk requires:
 * every triangle rotated so its smallest index comes first (winding kept),
 * then the part's triangles sorted ascending by (first, second, third). */
void afm_canonicalize_triangles(uint32_t *triangles, const afm_part *parts, uint32_t part_count);

/* ---- files -------------------------------------------------------------- */

/* Reads a whole file into memory allocated with `allocator`. */
afm_result afm_file_read(const char *path, const afm_allocator *allocator, uint8_t **data,
                         size_t *size);
/* Writes to "<path>.tmp", then renames over `path`: complete or absent. */
afm_result afm_file_write_atomic(const char *path, const uint8_t *data, size_t size);

#ifdef __cplusplus
}
#endif

#endif /* AFM_FORMAT_H */
