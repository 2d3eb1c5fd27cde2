// commands.h: how `pvs` subcommands register themselves, and the option parsers they share.
// Each cli/cmd_<name>.cpp defines one subcommand and registers it with a static
// `Registration`; main.cpp knows none of them by name.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "vislib/base/vec.h"

namespace pvs_cli {

// Adds one subcommand to the top-level app.
using AddCommand = std::function<void(CLI::App&)>;
struct Registration {
  Registration(const char* name, AddCommand add);
};
std::vector<std::pair<std::string, AddCommand>>& registry();

// Thrown by a command to end with a given exit code after printing its own message.
struct Exit {
  int code;
};

// "x,y,z" -> Vec3; throws CLI::ValidationError naming `option` on bad text.
vislib::Vec3 parse_vec3(const std::string& text, const std::string& option);
// "a,b,c,..." -> exactly `count` doubles (count 0 = any number).
std::vector<double> parse_doubles(const std::string& text, const std::string& option,
                                  size_t count = 0);

// Progress/warnings go to stderr; results to stdout or files.
void warn(const std::string& message);

}  // namespace pvs_cli
