// file_util.h: whole-file reads and crash-safe writes, shared by importers, writers and the CLI.
#pragma once

#include <string>

namespace vislib {

// Reads a whole file. Throws InputError(path, "cannot open ...") if it is missing or unreadable.
std::string read_file(const std::string& path);

// Writes `bytes` to `path` through a temporary file in the same folder, flushed and renamed into
// place, so a crash never leaves a half-written `path`. Throws std::runtime_error on I/O failure
// (the temporary is removed).
void write_file_atomic(const std::string& path, const std::string& bytes);

// Lower-case extension including the dot (".glb"), or "" if none.
std::string file_extension(const std::string& path);

}  // namespace vislib
