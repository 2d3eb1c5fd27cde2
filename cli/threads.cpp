// threads.cpp: -j/--threads as N threads (threads.h).
#include "cli/threads.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cassert>
#include <cstddef>

namespace pvs_cli {

void run_with_threads(int threads, const std::function<void()>& body) {
  assert(threads <= kMaxThreads);
  if (threads <= 0) {
    body();
    return;
  }
  // global_control alone only caps the pool at the core count; the arena alone gets no more
  // workers than the pool's default (one per core). Together: exactly `threads` threads.
  tbb::global_control pool(tbb::global_control::max_allowed_parallelism, size_t(threads));
  tbb::task_arena arena(threads);
  arena.execute(body);
}

}  // namespace pvs_cli
