// Out of memory through the command line (issue 18 item 6): an allocation that fails names the
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
