// load_scene.h (cli): loading a scene for a subcommand: option check, warnings to stderr.
#pragma once

#include <string>
#include <vector>

#include "vislib/scene/import.h"

namespace pvs_cli {

// Loads `path` with `states` key states (throws CLI::ValidationError naming --states if < 1;
// InputError from the importer passes through). Importer warnings go to stderr. Objects whose
// names match one of `see_through` (vislib::mark_see_through) become see-through; a pattern that
// matches no object is an error naming it (CLI::ValidationError, exit 2).
vislib::Scene load_scene_for_cli(const std::string& path, int states = 1,
                                 const std::vector<std::string>& see_through = {});

}  // namespace pvs_cli
