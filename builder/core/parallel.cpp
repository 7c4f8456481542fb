#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <mutex>
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

void for_each_task_after(size_t count, int workers, const std::vector<int> &after,
                         const std::function<void(size_t task)> &task) {
  std::vector<char> finished(count, 0);
  std::mutex lock;
  std::condition_variable finished_one;
  for_each_task(count, workers, [&](size_t k) {
    if (after[k] >= 0) {
      std::unique_lock<std::mutex> g(lock);
      finished_one.wait(g, [&] { return finished[static_cast<size_t>(after[k])] != 0; });
    }
    task(k);
    std::lock_guard<std::mutex> g(lock);
    finished[k] = 1;
    finished_one.notify_all();
  });
}

}  // namespace afmb
