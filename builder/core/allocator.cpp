#include "core/allocator.h"

#include <cstdlib>  // on glibc, defines __GLIBC__
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace afmb {

void keep_freed_memory() {
#if defined(__GLIBC__)
  // Blocks up to 32 MB (glibc's largest mmap threshold) come from the heap,
  // and the heap is trimmed only past 1 GB free at its top.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

}  // namespace afmb
