// Independent tasks on worker threads (the calling thread is one of them).
#pragma once

#include <cstddef>
#include <functional>

namespace afmb {

// Runs task(0) .. task(count - 1), each once, on min(count, workers)
// threads; workers <= 0: one per core. Tasks are taken in index order as
// workers come free, so a task must write only its own results; callers
// that need a deterministic output put the results together by index.
void for_each_task(size_t count, int workers, const std::function<void(size_t task)> &task);

}  // namespace afmb
