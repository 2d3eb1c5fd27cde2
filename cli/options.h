// options.h: the conventions every `pvs` subcommand shares: verbosity
// (-v/-q), output paths checked before any work, validators whose messages name the bounds
// readably, and the unknown-option check that runs before "--x is required".
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace pvs_cli {

// -v / -q, added to every subcommand by main.cpp (add_common_options). 0 quiet (errors only),
// 1 normal (warnings and progress), 2 verbose (also `info` lines). Process-wide: set once while
// parsing, before any command runs.
int verbosity();
void set_verbosity(int level);
// Progress and warnings print only when this is true (not -q).
inline bool show_progress() {
  return verbosity() >= 1;
}
// The plural ending of a count in the CLI's English: "" for 1, "s" otherwise ("1 cell", "2 cells").
inline const char* plural_s(unsigned long long n) {
  return n == 1 ? "" : "s";
}
// A line on stderr with -v only.
void info(const std::string& message);

// Adds -v,--verbose and -q,--quiet to `cmd` and its subcommands (recursively).
void add_common_options(CLI::App& cmd);

// Output paths, checked before any work. Each throws CLI::ValidationError naming `option`, the
// path and the problem (exit 2). Parent folders are created (mkdir -p) when missing, for every
// output of every command; a parent that exists but is not a folder, or a folder that cannot be
// written, is an error. "-" (stdout) is accepted where `allow_stdout`.
//  - check_output_file: `path` must not be an existing folder; its folder must be writable.
//  - check_output_dir: `path` must be a folder or absent (then created), and writable.
void check_output_file(const std::string& path, const std::string& option,
                       bool allow_stdout = false);
void check_output_dir(const std::string& path, const std::string& option);

// Range validators with readable messages ("must be in [1, 16384], got 0", "must be > 0, got
// -1"), never printing DBL_MAX. Their help text matches CLI11's ("INT in [1 - 16384]").
CLI::Validator in_range(double lo, double hi);
CLI::Validator positive();
CLI::Validator non_negative();

// --fans on|off into `value` (SegmentOptions::fans), for every command that runs the kernel.
void add_fans_option(CLI::App& cmd, std::string& value);

// argv scanned for options that the selected subcommand does not know; returns the first one
// ("" if none). main.cpp reports it before any other parse error (a missing required option).
std::string first_unknown_option(CLI::App& app, int argc, char** argv);

}  // namespace pvs_cli
