/* The container: magic, version, chunk table, CRCs (formats/afm.md, part 1). */
#include <string.h>

#include "afm_internal.h"

static const uint8_t kMagic[AFM_MAGIC_SIZE] = {0x89, 'A', 'F', 'M', '\r', '\n', 0x1A, '\n'};

enum {
  kHeaderSize = 16,  /* magic, major, minor, chunk_count */
  kEntrySize = 20,   /* kind, flags, encoding, offset, length, crc32 */
  kHeaderCrcSize = 4 /* CRC-32 of header + table */
};

afm_result afm_container_open(const uint8_t *data, size_t size, afm_container *c,
                              afm_diag *diag) {
  uint32_t count, i, stored_crc;
  size_t table_end, expected;

  if (!data || !c) return AFM_ERR_ARGUMENT;
  memset(c, 0, sizeof *c);
  if (size < AFM_MAGIC_SIZE) {
    afm_diag_set(diag, 0, 0, "file is %lu bytes, shorter than the 8-byte magic",
                 (unsigned long)size);
    return memcmp(data, kMagic, size) == 0 ? AFM_ERR_TRUNCATED : AFM_ERR_MAGIC;
  }
  if (memcmp(data, kMagic, AFM_MAGIC_SIZE) != 0) {
    afm_diag_set(diag, 0, 0, "bad magic: not an AFM file");
    return AFM_ERR_MAGIC;
  }
  if (size < kHeaderSize) {
    afm_diag_set(diag, 0, 8, "header truncated: %lu of 16 bytes", (unsigned long)size);
    return AFM_ERR_TRUNCATED;
  }
  c->major = afm_load_u16(data + 8);
  c->minor = afm_load_u16(data + 10);
  if (c->major != AFM_VERSION_MAJOR) {
    afm_diag_set(diag, 0, 8, "major version %u; this reader knows %d", (unsigned)c->major,
                 AFM_VERSION_MAJOR);
    return AFM_ERR_VERSION;
  }
  count = afm_load_u32(data + 12);
  if (size < kHeaderSize + kHeaderCrcSize) {
    afm_diag_set(diag, 0, 16, "header CRC truncated");
    return AFM_ERR_TRUNCATED;
  }
  /* Compare the untrusted count against the trusted remainder. */
  if (count > (size - kHeaderSize - kHeaderCrcSize) / kEntrySize) {
    afm_diag_set(diag, 0, 12, "chunk table of %lu entries does not fit in %lu bytes",
                 (unsigned long)count, (unsigned long)size);
    return AFM_ERR_TRUNCATED;
  }
  table_end = kHeaderSize + (size_t)count * kEntrySize;
  stored_crc = afm_load_u32(data + table_end);
  if (afm_crc32(data, table_end) != stored_crc) {
    afm_diag_set(diag, 0, table_end, "header CRC mismatch");
    return AFM_ERR_HEADER_CRC;
  }

  /* Chunks are contiguous, in table order, from the end of the header. */
  expected = table_end + kHeaderCrcSize;
  for (i = 0; i < count; ++i) {
    const uint8_t *e = data + kHeaderSize + (size_t)i * kEntrySize;
    uint32_t kind = afm_load_u32(e);
    uint32_t offset = afm_load_u32(e + 8);
    uint32_t length = afm_load_u32(e + 12);
    uint32_t crc = afm_load_u32(e + 16);
    if (offset != expected || (length & 3u) != 0) {
      afm_diag_set(diag, kind, (uint64_t)(e - data),
                   "chunk %lu: offset %lu length %lu; expected offset %lu and a length that "
                   "is a multiple of 4",
                   (unsigned long)i, (unsigned long)offset, (unsigned long)length,
                   (unsigned long)expected);
      return AFM_ERR_CHUNK_TABLE;
    }
    if (length > size - expected) {
      afm_diag_set(diag, kind, offset, "chunk %lu: %lu bytes announced, %lu left in the file",
                   (unsigned long)i, (unsigned long)length, (unsigned long)(size - expected));
      return AFM_ERR_TRUNCATED;
    }
    if (afm_crc32(data + offset, length) != crc) {
      afm_diag_set(diag, kind, offset, "chunk %lu: payload CRC mismatch", (unsigned long)i);
      return AFM_ERR_CHUNK_CRC;
    }
    expected += length;
  }
  if (expected != size) {
    afm_diag_set(diag, 0, expected, "%lu bytes after the last chunk",
                 (unsigned long)(size - expected));
    return AFM_ERR_TRAILING_BYTES;
  }
  c->data = data;
  c->size = size;
  c->chunk_count = count;
  return AFM_OK;
}

afm_result afm_container_chunk(const afm_container *c, uint32_t i, afm_chunk_info *chunk) {
  const uint8_t *e;
  if (!c || !chunk || !c->data || i >= c->chunk_count) return AFM_ERR_ARGUMENT;
  e = c->data + kHeaderSize + (size_t)i * kEntrySize;
  chunk->kind = afm_load_u32(e);
  chunk->flags = afm_load_u16(e + 4);
  chunk->encoding = afm_load_u16(e + 6);
  chunk->offset = afm_load_u32(e + 8);
  chunk->length = afm_load_u32(e + 12);
  chunk->crc32 = afm_load_u32(e + 16);
  chunk->data = c->data + chunk->offset;
  return AFM_OK;
}

afm_result afm_container_size(const afm_chunk_out *chunks, uint32_t count, size_t *size) {
  uint64_t total;
  uint32_t i;
  if (!size || (count && !chunks)) return AFM_ERR_ARGUMENT;
  total = (uint64_t)kHeaderSize + (uint64_t)count * kEntrySize + kHeaderCrcSize;
  for (i = 0; i < count; ++i) {
    if ((chunks[i].length & 3u) != 0 || (chunks[i].length && !chunks[i].data))
      return AFM_ERR_ARGUMENT;
    total += chunks[i].length;
    if (total > 0xFFFFFFFFu) return AFM_ERR_LIMIT; /* offsets are u32 */
  }
  *size = (size_t)total;
  return AFM_OK;
}

afm_result afm_container_write(const afm_chunk_out *chunks, uint32_t count, uint8_t *out,
                               size_t out_size) {
  size_t need, table_end, offset;
  uint32_t i;
  afm_result r = afm_container_size(chunks, count, &need);
  if (r != AFM_OK) return r;
  if (!out) return AFM_ERR_ARGUMENT;
  if (out_size < need) return AFM_ERR_BUFFER_TOO_SMALL;
  memcpy(out, kMagic, AFM_MAGIC_SIZE);
  afm_store_u16(out + 8, AFM_VERSION_MAJOR);
  afm_store_u16(out + 10, AFM_VERSION_MINOR);
  afm_store_u32(out + 12, count);
  table_end = kHeaderSize + (size_t)count * kEntrySize;
  offset = table_end + kHeaderCrcSize;
  for (i = 0; i < count; ++i) {
    uint8_t *e = out + kHeaderSize + (size_t)i * kEntrySize;
    afm_store_u32(e, chunks[i].kind);
    afm_store_u16(e + 4, chunks[i].flags);
    afm_store_u16(e + 6, chunks[i].encoding);
    afm_store_u32(e + 8, (uint32_t)offset);
    afm_store_u32(e + 12, (uint32_t)chunks[i].length);
    afm_store_u32(e + 16, afm_crc32(chunks[i].data, chunks[i].length));
    if (chunks[i].length) memcpy(out + offset, chunks[i].data, chunks[i].length);
    offset += chunks[i].length;
  }
  afm_store_u32(out + table_end, afm_crc32(out, table_end));
  return AFM_OK;
}
