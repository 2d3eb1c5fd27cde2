// phase_times_test.cpp: the per-phase timers (vislib/base/phase_times.h).
#include "vislib/base/phase_times.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

using namespace vislib;

namespace {

// Busy work until the steady clock has moved (so that a phase has a non-zero wall time; nothing
// here asserts how long anything took).
void until_the_clock_moves() {
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() == t0) {
  }
}

double seconds_between(std::chrono::steady_clock::time_point a,
                       std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

TEST(PhaseTimes, NestedScopesCountEachSecondOnceInTheInnermostPhase) {
  PhaseTimes times;
  const auto t0 = std::chrono::steady_clock::now();
  {
    PhaseScope cell(Phase::Cell, &times);
    until_the_clock_moves();
    {
      PhaseScope run(Phase::Run);  // charges the enclosing scope's PhaseTimes
      until_the_clock_moves();
      {
        PhaseScope merge(Phase::Merge);
        until_the_clock_moves();
      }
      until_the_clock_moves();
    }
    until_the_clock_moves();
  }
  const double outside = seconds_between(t0, std::chrono::steady_clock::now());
  EXPECT_GT(times.wall(Phase::Cell), 0);
  EXPECT_GT(times.wall(Phase::Run), 0);
  EXPECT_GT(times.wall(Phase::Merge), 0);
  EXPECT_EQ(times.wall(Phase::SharedWait), 0);
  // Exclusive: the three phases add up to no more than the time around them.
  EXPECT_LE(times.wall_total(), outside + 1e-6);
  EXPECT_NEAR(times.wall_total(),
              times.wall(Phase::Cell) + times.wall(Phase::Run) + times.wall(Phase::Merge), 1e-12);
  EXPECT_GE(times.cpu(Phase::Run), 0);
}

TEST(PhaseTimes, AScopeWithoutTimesOutsideAnyTimedScopeChargesNothing) {
  PhaseTimes times;
  {
    PhaseScope run(Phase::Run);  // nobody times this thread
    until_the_clock_moves();
  }
  {
    PhaseScope timed(Phase::Write, &times);
    until_the_clock_moves();
  }
  {
    PhaseScope run(Phase::Run);  // the timed scope has closed: nothing to charge again
    until_the_clock_moves();
  }
  EXPECT_EQ(times.wall(Phase::Run), 0);
  EXPECT_GT(times.wall(Phase::Write), 0);
  EXPECT_EQ(times.wall_total(), times.wall(Phase::Write));
}

TEST(PhaseTimes, ThreadsChargeTheirOwnScopesToOneSum) {
  PhaseTimes times;
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i)
    threads.emplace_back([&times] {
      PhaseScope run(Phase::Run, &times);
      {
        PhaseScope wait(Phase::SharedWait);
        until_the_clock_moves();
      }
      until_the_clock_moves();
    });
  for (std::thread& t : threads) t.join();
  EXPECT_GT(times.wall(Phase::Run), 0);
  EXPECT_GT(times.wall(Phase::SharedWait), 0);
  EXPECT_EQ(times.wall(Phase::Cell), 0);
}

TEST(PhaseTimes, AFallbackTimesThreadsOutsideAnyScopeAndOnlyWhileItLives) {
  PhaseTimes bake, other;
  {
    PhaseFallback lent(&bake);
    PhaseFallback second(&other);  // one at a time: installs nothing
    EXPECT_FALSE(PhaseScope::open_on_this_thread());
    std::thread helper([] {
      PhaseScope tiles(Phase::Helping);  // no scope of its own: the fallback's times
      EXPECT_TRUE(PhaseScope::open_on_this_thread());
      until_the_clock_moves();
    });
    helper.join();
    {
      PhaseScope timed(Phase::Write, &other);  // an open scope wins over the fallback
      PhaseScope run(Phase::Run);
      until_the_clock_moves();
    }
  }
  {
    PhaseScope tiles(Phase::Helping);  // the fallback is gone: nothing to charge
    EXPECT_FALSE(PhaseScope::open_on_this_thread());
    until_the_clock_moves();
  }
  EXPECT_GT(bake.wall(Phase::Helping), 0);
  EXPECT_EQ(bake.wall_total(), bake.wall(Phase::Helping));
  EXPECT_EQ(other.wall(Phase::Helping), 0);
  EXPECT_GT(other.wall(Phase::Run), 0);
  // A fallback installed after the first is gone installs again.
  PhaseTimes later;
  PhaseFallback again(&later);
  std::thread helper([] {
    PhaseScope tiles(Phase::Helping);
    until_the_clock_moves();
  });
  helper.join();
  EXPECT_GT(later.wall(Phase::Helping), 0);
}
