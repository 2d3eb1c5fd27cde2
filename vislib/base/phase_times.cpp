// phase_times.cpp: see phase_times.h.
#include "vislib/base/phase_times.h"

#include <sys/resource.h>
#include <time.h>

#include <chrono>

namespace vislib {

namespace {

// The innermost open scope of the calling thread.
thread_local PhaseScope* t_innermost = nullptr;
// The PhaseFallback alive's PhaseTimes, or null.
std::atomic<PhaseTimes*> g_fallback{nullptr};

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

uint64_t to_ns(double seconds) {
  return seconds > 0 ? uint64_t(seconds * 1e9 + 0.5) : 0;
}

}  // namespace

double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double process_cpu_seconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void PhaseTimes::add(Phase phase, double wall_seconds, double cpu_seconds) {
  wall_ns_[int(phase)].fetch_add(to_ns(wall_seconds), std::memory_order_relaxed);
  cpu_ns_[int(phase)].fetch_add(to_ns(cpu_seconds), std::memory_order_relaxed);
}

double PhaseTimes::wall_total() const {
  double sum = 0;
  for (int p = 0; p < kPhaseCount; ++p) sum += wall(Phase(p));
  return sum;
}

double PhaseTimes::cpu_total() const {
  double sum = 0;
  for (int p = 0; p < kPhaseCount; ++p) sum += cpu(Phase(p));
  return sum;
}

PhaseScope::PhaseScope(Phase phase, PhaseTimes* times)
    : times_(times         ? times
             : t_innermost ? t_innermost->times_
                           : g_fallback.load(std::memory_order_acquire)),
      phase_(phase) {
  if (!times_) return;
  const double wall = wall_seconds(), cpu = thread_cpu_seconds();
  outer_ = t_innermost;
  if (outer_) outer_->charge(wall, cpu);
  last_wall_ = wall;
  last_cpu_ = cpu;
  t_innermost = this;
}

PhaseScope::~PhaseScope() {
  if (!times_) return;
  const double wall = wall_seconds(), cpu = thread_cpu_seconds();
  charge(wall, cpu);
  t_innermost = outer_;
  if (outer_) {
    outer_->last_wall_ = wall;
    outer_->last_cpu_ = cpu;
  }
}

bool PhaseScope::open_on_this_thread() {
  return t_innermost != nullptr;
}

void PhaseScope::charge(double wall, double cpu) {
  if (times_) times_->add(phase_, wall - last_wall_, cpu - last_cpu_);
  last_wall_ = wall;
  last_cpu_ = cpu;
}

PhaseFallback::PhaseFallback(PhaseTimes* times) {
  PhaseTimes* none = nullptr;
  if (times && g_fallback.compare_exchange_strong(none, times, std::memory_order_acq_rel))
    installed_ = times;
}

PhaseFallback::~PhaseFallback() {
  if (installed_) g_fallback.store(nullptr, std::memory_order_release);
}

}  // namespace vislib
