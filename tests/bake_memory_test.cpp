// Memory per thread of a bake: the same bake at -j 1 and -j 8 in child processes, their peak
// resident memory read from the kernel's accounting of each child (wait4's ru_maxrss). Memory
// only, never time. Release builds only: the sanitizers' shadow memory and quarantine dwarf what
// is measured, and a debug build's figures are not the shipped program's.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <filesystem>
#include <string>
#include <vector>

#include "tests/test_support.h"
#include "vislib/base/file_util.h"

using namespace vislib_test;

namespace {

// Runs `pvs args...` with stdout and stderr sent to /dev/null; returns its peak RSS in MB, or a
// negative value when it could not be run or did not exit 0.
double run_pvs_peak_mb(const std::vector<std::string>& args) {
  const pid_t pid = spawn_pvs_quiet(args);
  if (pid < 0) return -1;
  int status = 0;
  struct rusage ru {};
  if (wait4(pid, &status, 0, &ru) != pid) return -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1;
  return double(ru.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

}  // namespace

// A 300K-triangle city (the suite's city2 scene) and 9 of its walkable 2 m cells at N = 64, with
// the BVH: each thread's working memory must be sized to its work (the ids a run sees, one tile's
// lists, the bounds its walk touches), not to the scene. With marks of 1 byte per triangle per
// thread and per run in flight, and per-run bound caches from malloc, each added thread cost 7.2 MB
// here (43 MB at -j 1, 94 MB at -j 8); with marks in pages, one tile scratch per thread and the
// caches mapped untouched, 3.4 MB. About 4 CPU seconds in all.
TEST(BakeMemory, PeakMemoryGrowsBoundedPerThreadAndFilesAreIdentical) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's shadow memory and quarantine dwarf the bake's own memory";
#endif
#ifndef NDEBUG
  GTEST_SKIP() << "memory is bounded on release builds (NDEBUG) only";
#endif
  const std::string dir = temp_dir("bake_memory");
  const std::string scene = dir + "/city.glb";
  ASSERT_GT(run_pvs_peak_mb({"generate", "city", "--target-triangles", "300000", "--seed", "1",
                             "-q", "-o", scene}),
            0);
  auto bake = [&](int threads) {
    return run_pvs_peak_mb({"bake", scene, "--walkable", "--cell-size", "2", "--box",
                            "-3,-1,-3,3,71,3", "--res", "64", "-q", "-j", std::to_string(threads),
                            "-o", dir + "/j" + std::to_string(threads) + ".pvs"});
  };
  const double one = bake(1);
  const double eight = bake(8);
  ASSERT_GT(one, 0) << "pvs bake -j 1 failed";
  ASSERT_GT(eight, 0) << "pvs bake -j 8 failed";
  const double per_thread = (eight - one) / 7;
  std::printf("peak RSS: %.1f MB at -j 1, %.1f MB at -j 8: %.2f MB per added thread\n", one, eight,
              per_thread);
  EXPECT_LE(per_thread, 5.0) << one << " MB at -j 1, " << eight << " MB at -j 8";
  EXPECT_EQ(vislib::read_file(dir + "/j1.pvs"), vislib::read_file(dir + "/j8.pvs"));
}
