// Out of memory through the command line: an allocation that fails names the
// stage that was running and the size of the failed request, exits 1 and leaves no output file.
// The limit is an address-space cap (prlimit --as) on the `pvs` process alone.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include "tests/test_support.h"

using namespace vislib_test;
namespace fs = std::filesystem;

namespace {

// Runs `pvs ARGS` with its address space capped at `mib` MiB; returns the exit status (-1 when
// killed by a signal) and stores stdout + stderr in *output.
int run_pvs_capped(int mib, const std::string& args, std::string* output) {
  const std::string cmd = "prlimit --as=" + std::to_string(size_t(mib) << 20) + " " +
                          VISLIB_PVS_EXE + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf;
  size_t n;
  output->clear();
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) output->append(buf.data(), n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool have_prlimit() {
  return std::system("prlimit --version > /dev/null 2>&1") == 0;
}

}  // namespace

TEST(CliMemory, OutOfMemoryNamesTheStageAndTheRequestSizeAndWritesNothing) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: an --as cap cannot apply";
#endif
  if (!have_prlimit()) GTEST_SKIP() << "prlimit (util-linux) is not installed";
  const std::string dir = temp_dir("cli_memory");
  const std::string out_path = dir + "/big.glb";
  std::string out;
  // A 400 x 400 block city needs several GiB; 600 MiB lets the program start and then fails.
  const int rc = run_pvs_capped(600, "generate city --blocks 400,400 -q -o " + out_path, &out);
  EXPECT_EQ(rc, 1) << out;
  EXPECT_NE(out.find("pvs: error: out of memory while "), std::string::npos) << out;
  // The stage is named (not the catch-all "running the command") ...
  EXPECT_EQ(out.find("running the command"), std::string::npos) << out;
  EXPECT_TRUE(out.find("generating the city scene") != std::string::npos ||
              out.find("encoding " + out_path) != std::string::npos)
      << out;
  // ... and so is the size of the request that failed.
  EXPECT_NE(out.find("a request for "), std::string::npos) << out;
  EXPECT_NE(out.find(" bytes) failed"), std::string::npos) << out;
  EXPECT_EQ(out.find("std::bad_alloc"), std::string::npos) << out;
  // Nothing half-written: neither the output nor a temporary beside it.
  for (const auto& e : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << e.path();
}

// OpenImageIO (with its ~250 shared libraries, ~130 MB resident before main()) is loaded only by
// the first image read or write (vislib/eval/image_module): `pvs info` never loads it, a bake
// neither, `pvs view -o frame.png` does. Seen through the dynamic loader's own trace (LD_DEBUG).
TEST(CliMemory, OpenImageIOIsLoadedOnlyByCommandsThatTouchImages) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP()
      << "sanitizer builds link OpenImageIO into pvs (vislib/CMakeLists.txt: LeakSanitizer "
         "crashed at exit after a dlopen'ed OpenImageIO)";
#endif
  const std::string dir = temp_dir("cli_memory_oiio");
  std::string out;
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 -q -o " + dir + "/city.glb", &out), 0) << out;
  auto loads_oiio = [&](const std::string& args, int expected_rc) {
    std::string trace;
    const std::string cmd = "env LD_DEBUG=files " + std::string(VISLIB_PVS_EXE) + " " + args;
    FILE* pipe = popen((cmd + " 2>&1").c_str(), "r");
    EXPECT_NE(pipe, nullptr);
    if (!pipe) return false;
    std::array<char, 4096> buf;
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) trace.append(buf.data(), n);
    const int status = pclose(pipe);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == expected_rc) << args << "\n" << trace;
    return trace.find("libOpenImageIO") != std::string::npos;
  };
  EXPECT_FALSE(loads_oiio("info " + dir + "/city.glb", 0));
  EXPECT_FALSE(loads_oiio("bake " + dir +
                              "/city.glb --box -20,0,-20,20,3,20 --grid 2,1,2 --eye-height 1.5,1.8 "
                              "--res 8 -q -o " +
                              dir + "/city.pvs",
                          0));
  EXPECT_TRUE(loads_oiio("view " + dir + "/city.pvs --scene " + dir +
                             "/city.glb --at -15,1.6,-15 --look 10,1.6,0 --centre -15,1.65,-15 "
                             "--near-far 5,10 --frame 32x24 -q -o " +
                             dir + "/frame.png",
                         0));
  EXPECT_TRUE(fs::exists(dir + "/frame.png"));
}
