// core/parallel.h: every task runs once, and a task with a predecessor
// starts only after it has finished.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "core/parallel.h"

using namespace afmb;

namespace {

TEST(Parallel, EveryTaskRunsOnceAndAWaitingTaskStartsAfterItsPredecessorEnds) {
  const size_t n = 40;
  // Task k waits for k - 3 where k is a multiple of 4, else for nothing;
  // the awaited tasks sleep, so a worker that did not wait would start
  // before they end.
  std::vector<int> after(n, -1);
  for (size_t k = 4; k < n; k += 4) after[k] = static_cast<int>(k - 3);
  std::mutex lock;
  std::vector<int> runs(n, 0), started(n, -1), ended(n, -1);
  int clock = 0;
  for_each_task_after(n, 3, after, [&](size_t k) {
    {
      std::lock_guard<std::mutex> g(lock);
      ++runs[k];
      started[k] = clock++;
    }
    if (k % 4 == 1) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::lock_guard<std::mutex> g(lock);
    ended[k] = clock++;
  });
  for (size_t k = 0; k < n; ++k) {
    EXPECT_EQ(runs[k], 1) << k;
    if (after[k] >= 0) {
      EXPECT_GT(started[k], ended[static_cast<size_t>(after[k])]) << k;
    }
  }
}

TEST(Parallel, AChainRunsInOrderOnAnyNumberOfWorkers) {
  for (int workers : {1, 2, 4}) {
    const size_t n = 12;
    std::vector<int> after(n);
    for (size_t k = 0; k < n; ++k) after[k] = static_cast<int>(k) - 1;
    std::vector<size_t> seen;
    std::mutex lock;
    for_each_task_after(n, workers, after, [&](size_t k) {
      std::lock_guard<std::mutex> g(lock);
      seen.push_back(k);
    });
    ASSERT_EQ(seen.size(), n) << workers;
    for (size_t k = 0; k < n; ++k) EXPECT_EQ(seen[k], k) << workers;
  }
}

}  // namespace
