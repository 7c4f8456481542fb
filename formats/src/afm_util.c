/* Result strings, allocator, CRC-32, part kind names. */
#include <stdlib.h>

#include "afm_internal.h"

const char *afm_result_string(afm_result result) {
  switch (result) {
    case AFM_OK: return "ok";
    case AFM_ERR_ARGUMENT: return "invalid argument";
    case AFM_ERR_TRUNCATED: return "data truncated";
    case AFM_ERR_MAGIC: return "not an AFM file (bad magic)";
    case AFM_ERR_VERSION: return "unsupported major version";
    case AFM_ERR_HEADER_CRC: return "header CRC mismatch";
    case AFM_ERR_CHUNK_TABLE: return "inconsistent chunk table";
    case AFM_ERR_CHUNK_CRC: return "chunk CRC mismatch";
    case AFM_ERR_TRAILING_BYTES: return "trailing bytes";
    case AFM_ERR_UNKNOWN_REQUIRED: return "unknown required chunk";
    case AFM_ERR_MISSING_CHUNK: return "required chunk missing";
    case AFM_ERR_DUPLICATE_CHUNK: return "duplicate chunk";
    case AFM_ERR_RANGE: return "value out of range";
    case AFM_ERR_NEED_DRACO: return "draco-encoded chunk but no Draco codec linked";
    case AFM_ERR_DRACO: return "Draco codec error";
    case AFM_ERR_BUFFER_TOO_SMALL: return "buffer too small";
    case AFM_ERR_OUT_OF_MEMORY: return "out of memory";
    case AFM_ERR_IO: return "I/O error";
    case AFM_ERR_LIMIT: return "format limit exceeded";
    case AFM_ERR_SYNTAX: return "syntax error";
    case AFM_ERR_STATE: return "call out of order";
  }
  return "unknown error";
}

void *afm_alloc(const afm_allocator *allocator, size_t size) {
  if (allocator && allocator->alloc) return allocator->alloc(allocator->ctx, size);
  return malloc(size);
}

void afm_free(const afm_allocator *allocator, void *ptr) {
  if (!ptr) return;
  if (allocator && allocator->free) {
    allocator->free(allocator->ctx, ptr);
    return;
  }
  free(ptr);
}

/* CRC-32/ISO-HDLC (zlib's): reflected polynomial 0xEDB88320, init and final
 * xor 0xFFFFFFFF. Half-byte table: 64 bytes of constants, no init step. */
uint32_t afm_crc32(const uint8_t *data, size_t size) {
  static const uint32_t nibble[16] = {
      0x00000000u, 0x1DB71064u, 0x3B6E20C8u, 0x26D930ACu, 0x76DC4190u, 0x6B6B51F4u,
      0x4DB26158u, 0x5005713Cu, 0xEDB88320u, 0xF00F9344u, 0xD6D6A3E8u, 0xCB61B38Cu,
      0x9B64C2B0u, 0x86D3D2D4u, 0xA00AE278u, 0xBDBDF21Cu};
  uint32_t crc = 0xFFFFFFFFu;
  size_t i;
  for (i = 0; i < size; ++i) {
    crc ^= data[i];
    crc = (crc >> 4) ^ nibble[crc & 0xFu];
    crc = (crc >> 4) ^ nibble[crc & 0xFu];
  }
  return crc ^ 0xFFFFFFFFu;
}

const char *afm_part_kind_name(uint8_t kind) {
  static const char *const names[AFM_PART_KIND_COUNT] = {
      "other", "skin", "eye_left", "eye_right", "teeth_upper",
      "teeth_lower", "tongue", "hair", "eyelid", "mouth"};
  return kind < AFM_PART_KIND_COUNT ? names[kind] : "?";
}
