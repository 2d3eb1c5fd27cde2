// options.cpp: shared option conventions of `pvs` (see options.h).
#include "cli/options.h"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace pvs_cli {

namespace fs = std::filesystem;

namespace {
std::atomic<int> g_verbosity{1};

std::string number_text(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

// Creates `dir` (and parents) if missing; throws naming `option` when that fails or `dir` is not
// a writable folder.
void ensure_writable_dir(const fs::path& dir, const std::string& option, const std::string& path) {
  if (dir.empty()) return ensure_writable_dir(fs::path("."), option, path);
  std::error_code ec;
  // The nearest existing ancestor must be a folder.
  for (fs::path p = dir; !p.empty(); p = p.parent_path()) {
    if (fs::exists(p, ec)) {
      if (!fs::is_directory(p, ec))
        throw CLI::ValidationError(
            option, "'" + path + "': '" + p.string() + "' exists and is not a folder");
      break;
    }
    if (p == p.parent_path()) break;
  }
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec)
      throw CLI::ValidationError(
          option, "'" + path + "': cannot create folder '" + dir.string() + "': " + ec.message());
    info("created folder " + dir.string());
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw CLI::ValidationError(option,
                               "'" + path + "': folder '" + dir.string() + "' is not writable");
}
}  // namespace

int verbosity() {
  return g_verbosity.load();
}
void set_verbosity(int level) {
  g_verbosity.store(level);
}

void info(const std::string& message) {
  if (verbosity() >= 2) std::fprintf(stderr, "pvs: %s\n", message.c_str());
}

void add_common_options(CLI::App& cmd) {
  cmd.add_flag_callback(
      "-v,--verbose", [] { set_verbosity(2); },
      "Verbose: also print what is loaded, created and chosen");
  cmd.add_flag_callback(
      "-q,--quiet", [] { set_verbosity(0); }, "Quiet: no progress and no warnings, errors only");
  for (CLI::App* sub : cmd.get_subcommands({}))
    if (!sub->get_name().empty()) add_common_options(*sub);  // not option groups
}

void check_output_file(const std::string& path, const std::string& option, bool allow_stdout) {
  if (allow_stdout && path == "-") return;
  if (path.empty()) throw CLI::ValidationError(option, "empty output path");
  std::error_code ec;
  fs::path p(path);
  if (fs::is_directory(p, ec))
    throw CLI::ValidationError(option, "'" + path + "' is a folder, not a file");
  if (!p.has_filename())
    throw CLI::ValidationError(option, "'" + path + "' names a folder, not a file");
  ensure_writable_dir(p.parent_path(), option, path);
  if (fs::exists(p, ec) && ::access(p.c_str(), W_OK) != 0)
    throw CLI::ValidationError(option, "'" + path + "' exists and is not writable");
}

void check_output_dir(const std::string& path, const std::string& option) {
  if (path.empty()) throw CLI::ValidationError(option, "empty output folder");
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec))
    throw CLI::ValidationError(option, "'" + path + "' exists and is not a folder");
  ensure_writable_dir(fs::path(path), option, path);
}

void add_fans_option(CLI::App& cmd, std::string& value) {
  cmd.add_option("--fans", value,
                 "Static scenes: composite each convex planar fan of triangles (a map's face, a "
                 "mesh's quad) as one polygon, cut back into its triangles at the end (the same "
                 "sets but for depth ties at corners, docs/visibility-math.md 2.6; faster); "
                 "'off': triangle by triangle")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
}

CLI::Validator in_range(double lo, double hi) {
  CLI::Validator v(
      [lo, hi](std::string& input) -> std::string {
        double x = 0;
        if (!CLI::detail::lexical_cast(input, x) || !(x >= lo && x <= hi))
          return "must be in [" + number_text(lo) + ", " + number_text(hi) + "], got " + input;
        return {};
      },
      "in [" + number_text(lo) + " - " + number_text(hi) + "]");
  return v;
}

CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        double x = 0;
        if (!CLI::detail::lexical_cast(input, x) || !(x > 0) || !std::isfinite(x))
          return "must be a positive number, got " + input;
        return {};
      },
      "POSITIVE");
}

CLI::Validator non_negative() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        double x = 0;
        if (!CLI::detail::lexical_cast(input, x) || !(x >= 0) || !std::isfinite(x))
          return "must be a number >= 0, got " + input;
        return {};
      },
      "NONNEGATIVE");
}

std::string first_unknown_option(CLI::App& app, int argc, char** argv) {
  // The selected subcommand chain: the words that name subcommands, in order.
  CLI::App* cmd = &app;
  bool options_done = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (options_done) continue;
    if (a == "--") {
      options_done = true;
      continue;
    }
    if (a.size() > 1 && a[0] == '-' &&
        !(std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.')) {
      std::string name = a.substr(0, a.find('='));
      if (name.rfind("--", 0) == 0) {
        if (!cmd->get_option_no_throw(name)) return name;
      } else {
        // -abc: each letter a short flag (the first may take the rest as its value).
        for (size_t k = 1; k < name.size(); ++k) {
          const CLI::Option* o = cmd->get_option_no_throw(std::string("-") + name[k]);
          if (!o) return std::string("-") + name[k];
          if (o->get_type_size_max() != 0) break;  // takes a value: the rest is the value
        }
      }
      continue;
    }
    try {
      cmd = cmd->get_subcommand(a);
    } catch (const CLI::Error&) {
      // a positional or an option's value
    }
  }
  return "";
}

}  // namespace pvs_cli
