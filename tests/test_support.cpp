#include "tests/test_support.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

extern char** environ;

namespace vislib_test {

std::string source_dir() {
  return VISLIB_SOURCE_DIR;
}

std::optional<std::string> shared_dir() {
  const char* env = std::getenv("VISLIB_SHARED_DIR");
  std::string dir = env ? env : source_dir() + "/../shared";
  std::error_code ec;
  if (std::filesystem::is_directory(dir + "/scenes", ec)) return dir;
  return std::nullopt;
}

std::optional<std::string> librequake(const std::string& name) {
  auto shared = shared_dir();
  if (!shared) return std::nullopt;
  std::string p = *shared + "/scenes/librequake/" + name;
  if (!std::filesystem::exists(p)) return std::nullopt;
  return p;
}

namespace {

// Runs `cmd` through the shell; returns its exit code and captures its stdout into `output`.
int run_command(const std::string& cmd, std::string* output) {
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf;
  std::string out;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  int status = pclose(pipe);
  if (output) *output = out;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

int run_pvs(const std::string& args, std::string* output) {
  return run_command(std::string(VISLIB_PVS_EXE) + " " + args + " 2>&1", output);
}

int run_pvs_split(const std::string& args, std::string* out, std::string* err) {
  static int serial = 0;
  const std::string err_path =
      (std::filesystem::temp_directory_path() /
       ("vislib_test_stderr_" + std::to_string(::getpid()) + "_" + std::to_string(serial++)))
          .string();
  const int rc = run_command(std::string(VISLIB_PVS_EXE) + " " + args + " 2> " + err_path, out);
  std::string e;
  if (FILE* f = std::fopen(err_path.c_str(), "rb")) {
    std::array<char, 4096> buf;
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) e.append(buf.data(), n);
    std::fclose(f);
  }
  std::filesystem::remove(err_path);
  if (err) *err = e;
  return rc;
}

pid_t spawn_pvs_quiet(const std::vector<std::string>& args) {
  std::vector<std::string> all{VISLIB_PVS_EXE};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

std::string temp_dir(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() /
             ("vislib_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

bool long_tests_enabled() {
  const char* env = std::getenv("VISLIB_LONG_TESTS");
  return env && std::string(env) == "1";
}

}  // namespace vislib_test
