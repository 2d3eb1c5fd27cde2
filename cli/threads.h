// threads.h: what -j/--threads N means for every `pvs` command: N threads run the work, as with
// `make -j N`, whatever the machine's core count.
#pragma once

#include <functional>

namespace pvs_cli {

// The most threads -j accepts (each costs a stack and its working memory, docs/performance.md).
constexpr int kMaxThreads = 1024;

// Runs `body` on `threads` threads: inside a tbb::task_arena of `threads` slots (the calling
// thread and threads - 1 TBB workers), with TBB's worker pool sized to match through
// tbb::global_control (raised above the core count when asked: 16 threads run on 2 cores, each
// with its own working memory, so a bake's memory at -j 16 can be measured anywhere). Every
// parallel loop of the library called from `body` runs in that arena, so `threads` is its
// tbb::this_task_arena::max_concurrency(). threads <= 0: TBB's default (one thread per core), and
// `body` runs directly. Exceptions from `body` reach the caller. threads must be <= kMaxThreads.
// Outputs never depend on the thread count (the library's determinism contracts).
void run_with_threads(int threads, const std::function<void()>& body);

}  // namespace pvs_cli
