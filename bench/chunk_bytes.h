// The payload size of one chunk of an AFM file, for the benchmarks that
// compare chunk sizes (bench_afm, bench_afm_size).
#pragma once

#include <afm/format.h>

#include <cstdint>
#include <vector>

// Bytes of the first chunk of `kind`; 0 when there is none or `f` is no AFM.
inline size_t chunk_bytes(const std::vector<uint8_t> &f, uint32_t kind) {
  afm_container c;
  if (afm_container_open(f.data(), f.size(), &c, nullptr) != AFM_OK) return 0;
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    if (ch.kind == kind) return ch.length;
  }
  return 0;
}
