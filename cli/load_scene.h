// load_scene.h (cli): loading a scene for a subcommand: option check, warnings to stderr.
#pragma once

#include <string>

#include "vislib/scene/import.h"

namespace pvs_cli {

// Loads `path` with `states` key states (throws CLI::ValidationError naming --states if < 1;
// InputError from the importer passes through). Importer warnings go to stderr.
vislib::Scene load_scene_for_cli(const std::string& path, int states = 1);

}  // namespace pvs_cli
