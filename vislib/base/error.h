// error.h: the typed errors vislib throws (house style: three tiers of error).
//  - Caller bugs: assert at entry.
//  - Bad input (a file that is missing, malformed or inconsistent): InputError, thrown only at the
//    I/O boundary (importers, writers). Its message always names the file and what is wrong.
//  - Anything else (out of memory, an Embree failure): std::runtime_error.
// The library never calls exit(); the CLI maps InputError to exit code 2 and the rest to 1.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdio>
#include <new>
#include <stdexcept>
#include <string>

namespace vislib {

class InputError : public std::runtime_error {
 public:
  // `path` is the file, `what` says what is wrong and where (accessor index, line, byte offset).
  InputError(const std::string& path, const std::string& what)
      : std::runtime_error(path + ": " + what), path_(path) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Out of memory in a named stage ("loading scene.glb", "baking cell 17 of 400"): thrown where a
// stage catches std::bad_alloc, so that the message says what was being done and, when known,
// how large the failed request was. A std::runtime_error (CLI exit code 1).
class OutOfMemory : public std::runtime_error {
 public:
  OutOfMemory(const std::string& stage, std::size_t requested_bytes)
      : std::runtime_error(message(stage, requested_bytes)),
        stage_(stage),
        requested_(requested_bytes) {}
  const std::string& stage() const { return stage_; }
  // Size of the allocation that failed, 0 if unknown.
  std::size_t requested_bytes() const { return requested_; }

 private:
  static std::string message(const std::string& stage, std::size_t bytes) {
    std::string m = "out of memory while " + stage;
    if (bytes) {
      char buf[64];
      if (bytes >= (std::size_t(1) << 20))
        std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / double(1 << 20));
      else
        std::snprintf(buf, sizeof buf, "%zu bytes", bytes);
      m += std::string(": a request for ") + buf + " (" + std::to_string(bytes) + " bytes) failed";
    }
    return m;
  }
  std::string stage_;
  std::size_t requested_;
};

// The size of the latest allocation that failed, recorded by an operator new that knows it (the
// `pvs` executable replaces the global operator new to do so); 0 if none was recorded.
inline std::atomic<std::size_t> g_failed_allocation_bytes{0};
inline void record_failed_allocation(std::size_t bytes) {
  g_failed_allocation_bytes.store(bytes);
}
inline std::size_t failed_allocation_bytes() {
  return g_failed_allocation_bytes.load();
}

// Runs f(); a std::bad_alloc escaping it becomes OutOfMemory(stage, last failed size). An
// OutOfMemory from an inner stage passes through unchanged (the innermost stage is the precise
// one).
template <class F>
auto with_memory_stage(const std::string& stage, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const OutOfMemory&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw OutOfMemory(stage, failed_allocation_bytes());
  }
}

}  // namespace vislib
