// load_scene.h (cli): loading a scene for a subcommand: option check, warnings to stderr.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "vislib/scene/import.h"

namespace pvs_cli {

// Options of the importers that have them (.bsp: docs/scene-model.md), as every command that
// loads a scene may take them.
struct ImportArgs {
  std::string bsp_models = "world";      // world | all
  std::string bsp_liquids = "opaque";    // opaque | omit | see-through
  std::vector<std::string> see_through;  // --see-through: object name patterns
};
// Adds --bsp-models, --bsp-liquids and --see-through to `cmd`.
void add_import_options(CLI::App* cmd, ImportArgs& args);

// The importer options of `import` with `states` key states (not checked here).
vislib::LoadOptions load_options_of(const ImportArgs& import, int states = 1);

// Loads `path` with `states` key states (throws CLI::ValidationError naming --states if < 1;
// InputError from the importer passes through). Importer warnings go to stderr. Objects whose
// names match one of `import.see_through` (vislib::mark_see_through) become see-through; a
// pattern that matches no object is an error naming it (CLI::ValidationError, exit 2).
vislib::Scene load_scene_for_cli(const std::string& path, int states = 1,
                                 const ImportArgs& import = {});

}  // namespace pvs_cli
