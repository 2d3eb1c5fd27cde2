#include "cli/load_scene.h"

#include "cli/commands.h"

namespace pvs_cli {

vislib::Scene load_scene_for_cli(const std::string& path, int states) {
  if (states < 1)
    throw CLI::ValidationError("--states", "must be >= 1, got " + std::to_string(states));
  vislib::LoadOptions options;
  options.states = states;
  std::vector<std::string> warnings;
  vislib::Scene scene = vislib::load_scene(path, options, &warnings);
  for (const auto& w : warnings) warn(w);
  return scene;
}

}  // namespace pvs_cli
