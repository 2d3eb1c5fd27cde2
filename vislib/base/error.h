// error.h: the typed errors vislib throws (house style: three tiers of error).
//  - Caller bugs: assert at entry.
//  - Bad input (a file that is missing, malformed or inconsistent): InputError, thrown only at the
//    I/O boundary (importers, writers). Its message always names the file and what is wrong.
//  - Anything else (out of memory, an Embree failure): std::runtime_error.
// The library never calls exit(); the CLI maps InputError to exit code 2 and the rest to 1.
#pragma once

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

}  // namespace vislib
