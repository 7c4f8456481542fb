#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace afmb {

void for_each_task(size_t count, int workers, const std::function<void(size_t task)> &task) {
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t k; (k = next++) < count;) task(k);
  };
  const size_t cores = std::max(1u, std::thread::hardware_concurrency());
  const size_t n = std::min(count, workers > 0 ? static_cast<size_t>(workers) : cores);
  std::vector<std::thread> pool;
  for (size_t w = 1; w < n; ++w) pool.emplace_back(work);
  work();
  for (std::thread &t : pool) t.join();
}

}  // namespace afmb
