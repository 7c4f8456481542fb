// The C library's allocator, tuned for the builder's solves.
#pragma once

namespace afmb {

// Keeps memory freed by the process in the process, instead of handing it
// back to the kernel (glibc: mallopt's mmap and trim thresholds; elsewhere
// it does nothing). Every solve builds a system and a factor cache whose
// buffers run to a few MB (Song's AFM: 298 solves, `afm-build --stats`); by default glibc
// returns such blocks to the kernel when freed, and the next solve's take
// page faults and freshly zeroed pages again: Song's AFM took 60,000-87,000
// minor page faults, 34,000 (its peak memory, touched once) with this. The
// cost: the process keeps up to its peak memory until it exits. For a
// program's main, before any allocation worth keeping; not thread-safe.
void keep_freed_memory();

}  // namespace afmb
