// pvs: the vislib command-line tool. Only parses options, calls the library, prints progress and
// chooses exit codes: 0 success, 2 bad input (bad file or bad option), 1 any other failure.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <sstream>

#include "cli/commands.h"
#include "cli/options.h"
#include "pvs_format/pvs_format.h"
#include "vislib/base/error.h"

namespace pvs_cli {

std::vector<std::pair<std::string, AddCommand>>& registry() {
  static std::vector<std::pair<std::string, AddCommand>> commands;
  return commands;
}

Registration::Registration(const char* name, AddCommand add) {
  registry().emplace_back(name, std::move(add));
}

std::vector<double> parse_doubles(const std::string& text, const std::string& option,
                                  size_t count) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      double v = std::stod(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw CLI::ValidationError(option, "'" + text + "' is not a comma-separated list of numbers");
    }
  }
  if (count && out.size() != count)
    throw CLI::ValidationError(option, "expected " + std::to_string(count) +
                                           " comma-separated numbers, got '" + text + "'");
  return out;
}

vislib::Vec3 parse_vec3(const std::string& text, const std::string& option) {
  auto v = parse_doubles(text, option, 3);
  return {v[0], v[1], v[2]};
}

void warn(const std::string& message) {
  if (show_progress()) std::fprintf(stderr, "pvs: warning: %s\n", message.c_str());
}

}  // namespace pvs_cli

int main(int argc, char** argv) {
  CLI::App app{
      "pvs: precomputed visibility for virtual environments (vislib "
      "0.1.0)",
      "pvs"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pvs 0.1.0");
  auto& reg = pvs_cli::registry();
  std::sort(reg.begin(), reg.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [name, add] : reg) add(app);
  for (CLI::App* sub : app.get_subcommands({}))
    if (!sub->get_name().empty()) pvs_cli::add_common_options(*sub);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      // An unknown option is named before any other mistake (a missing required option, which
      // CLI11 checks first, is often a consequence of it).
      std::string unknown = pvs_cli::first_unknown_option(app, argc, argv);
      if (!unknown.empty()) {
        std::fprintf(stderr, "pvs: error: unknown option '%s' (see --help)\n", unknown.c_str());
        return 2;
      }
    }
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const pvs_cli::Exit& e) {
    return e.code;
  } catch (const vislib::InputError& e) {
    std::fprintf(stderr, "pvs: error: %s\n", e.what());
    return 2;
  } catch (const pvs::FormatError& e) {
    // A bad PVS file that no command named (commands read PVS files through vislib::reading_pvs,
    // which names the file); still bad input.
    std::fprintf(stderr, "pvs: error: PVS file: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    // Out of memory outside every named stage: still say how much was asked for.
    std::fprintf(
        stderr, "pvs: error: %s\n",
        vislib::OutOfMemory("running the command", vislib::failed_allocation_bytes()).what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pvs: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
