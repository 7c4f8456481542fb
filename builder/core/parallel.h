// Independent tasks on worker threads (the calling thread is one of them).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

namespace afmb {

// Runs task(0) .. task(count - 1), each once, on min(count, workers)
// threads; workers <= 0: one per core. Tasks are taken in index order as
// workers come free, so a task must write only its own results; callers
// that need a deterministic output put the results together by index.
void for_each_task(size_t count, int workers, const std::function<void(size_t task)> &task);

// As for_each_task, but task k starts only once task after[k] has finished
// (after[k] < k; -1: no wait). Tasks are taken in index order, so the task
// waited for is running or done: nothing deadlocks. `after` has count
// entries.
void for_each_task_after(size_t count, int workers, const std::vector<int> &after,
                         const std::function<void(size_t task)> &task);

}  // namespace afmb
