// test_support.h: helpers shared by the tests (paths to data and ../shared, running `pvs`).
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace vislib_test {

// Repository root (compiled in).
std::string source_dir();
// ../shared beside the repository, or std::nullopt when absent (tests that need it then call
// GTEST_SKIP with a message).
std::optional<std::string> shared_dir();
// ../shared/scenes/librequake/NAME (a LibreQuake map), or std::nullopt when it is absent.
std::optional<std::string> librequake(const std::string& name);
// Runs the built `pvs` with `args` (a shell-quoted string); returns the exit code and captures
// stdout+stderr into `output`.
int run_pvs(const std::string& args, std::string* output = nullptr);
// The same with stdout and stderr captured apart (stderr through a temporary file).
int run_pvs_split(const std::string& args, std::string* out, std::string* err);
// Starts the built `pvs` with `args` (argv after the program name, unquoted) as a child process
// with stdout and stderr sent to /dev/null; returns its pid (for waitpid, wait4 or kill), or -1
// when it could not be started.
pid_t spawn_pvs_quiet(const std::vector<std::string>& args);
// A fresh empty temporary directory for one test.
std::string temp_dir(const std::string& name);
// True when VISLIB_LONG_TESTS=1: the opt-in tests that take tens of minutes (whole maps) run.
bool long_tests_enabled();

}  // namespace vislib_test

#define VISLIB_REQUIRE_SHARED(var)                                      \
  auto var##_opt = vislib_test::shared_dir();                           \
  if (!var##_opt) GTEST_SKIP() << "../shared is absent: skipping test"; \
  const std::string var = *var##_opt

// Skips the test unless the long tests were asked for (long_tests_enabled).
#define VISLIB_REQUIRE_LONG_TESTS() \
  if (!vislib_test::long_tests_enabled()) GTEST_SKIP() << "opt-in: set VISLIB_LONG_TESTS=1"
