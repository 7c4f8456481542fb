// core/allocator.h: a block freed is reused without the kernel's page faults.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
// glibc's allocator only: the sanitizers bring their own, which ignores it.
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
#define AFM_GLIBC_MALLOC 1
#include <sys/resource.h>
#endif

#include "core/allocator.h"

using namespace afmb;

namespace {

#if defined(AFM_GLIBC_MALLOC)
long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}
#endif

TEST(Allocator, AFreedBlockOfAFewMegabytesIsReusedWithoutPageFaults) {
#if !defined(AFM_GLIBC_MALLOC)
  GTEST_SKIP() << "glibc's allocator only (the sanitizers bring their own)";
#else
  keep_freed_memory();
  // As a solve's factor buffers: allocated, written, freed, then again.
  const size_t bytes = size_t{8} << 20, pages = bytes / 4096;
  for (int round = 0; round < 2; ++round) {
    const long before = minor_faults();
    std::unique_ptr<char[]> block(new char[bytes]);
    std::memset(block.get(), round + 1, bytes);
    const long faults = minor_faults() - before;
    EXPECT_EQ(block[bytes - 1], round + 1);
    // The first round faults its pages in; the second finds them mapped.
    if (round == 1) EXPECT_LT(faults, static_cast<long>(pages / 10)) << "of " << pages << " pages";
    else std::printf("first round: %ld minor page faults for %zu pages\n", faults, pages);
  }
#endif
}

}  // namespace
