// phase_times.h: where the threads of a parallel computation spend their time, by phase, from
// timers inside the program. A PhaseScope charges the calling thread's wall time (steady_clock)
// and CPU time (CLOCK_THREAD_CPUTIME_ID) inside it to one phase of a PhaseTimes, less the time of
// the scopes opened inside it on the same thread: each thread's time goes to its innermost open
// phase, so the phases never count a second twice, and their sums over threads add up to at most
// threads x wall time. The clocks are read once per scope boundary (a few per from-segment run,
// never per tile or pixel), and nothing here changes what the timed code computes.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace vislib {

// The phases of a bake (bake.h: BakeTimes says what each one holds).
enum class Phase : int {
  Bvh,         // building the BVH the runs share
  Pilot,       // the pilot of --long-segments auto
  Cell,        // inside a cell's computation, outside the phases below
  Run,         // a from-segment run this thread computes (its tiles while it waits in it too)
  SharedWait,  // a shared or long-segment run another thread computes: joining its tiles or idle
  Merge,       // the union of a cell's runs and its ids
  Progress,    // waiting for the progress lock and reporting
  Checkpoint,  // appending a finished cell to the checkpoint
  Encode,      // encoding a cell's block in the writer stage
  Write,       // writing the encoded bytes to the file
  Helping,     // tiles of another thread's run, taken by a thread outside any phase of its own
  BoundTrees,  // building a cell's trees over its runs' bounds (ViewCells::bound_leaves)
};
constexpr int kPhaseCount = 12;

// Wall and CPU seconds per phase, summed over threads. Thread-safe.
class PhaseTimes {
 public:
  void add(Phase phase, double wall_seconds, double cpu_seconds);
  double wall(Phase phase) const { return 1e-9 * double(wall_ns_[int(phase)].load()); }
  double cpu(Phase phase) const { return 1e-9 * double(cpu_ns_[int(phase)].load()); }
  double wall_total() const;  // over every phase
  double cpu_total() const;

 private:
  std::array<std::atomic<uint64_t>, kPhaseCount> wall_ns_{}, cpu_ns_{};
};

// Charges the calling thread's time from construction to destruction to `phase` of `times`,
// less the scopes opened inside it on this thread (which resume it when they close). With
// `times` null the scope charges the PhaseTimes of the innermost scope open on this thread, or,
// when none is, that of the PhaseFallback alive, and does nothing when there is neither: library
// code can mark its phases (a run, a merge, tiles) without knowing whether anyone times it.
// Scopes must close in reverse order on each thread (automatic storage).
class PhaseScope {
 public:
  explicit PhaseScope(Phase phase, PhaseTimes* times = nullptr);
  ~PhaseScope();
  // True when the calling thread is inside a scope that charges a PhaseTimes.
  static bool open_on_this_thread();
  PhaseScope(const PhaseScope&) = delete;
  PhaseScope& operator=(const PhaseScope&) = delete;

 private:
  void charge(double wall, double cpu);  // the time since last_* to this phase; last_* = now
  PhaseTimes* times_;
  Phase phase_;
  PhaseScope* outer_ = nullptr;
  double last_wall_ = 0, last_cpu_ = 0;
};

// While it lives, scopes opened with `times` null on threads with no open scope charge `times`:
// the threads a scheduler lends to a timed computation (work stealing) outside any scope of their
// own are timed too. One at a time in a process: while one lives, a second installs nothing.
class PhaseFallback {
 public:
  explicit PhaseFallback(PhaseTimes* times);
  ~PhaseFallback();
  PhaseFallback(const PhaseFallback&) = delete;
  PhaseFallback& operator=(const PhaseFallback&) = delete;

 private:
  PhaseTimes* installed_ = nullptr;  // `times` if this one installed it
};

// The calling thread's CPU seconds (CLOCK_THREAD_CPUTIME_ID) and the process's (user + system,
// every thread).
double thread_cpu_seconds();
double process_cpu_seconds();

}  // namespace vislib
