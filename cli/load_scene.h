// load_scene.h (cli): loading a scene for a subcommand: option check, warnings to stderr.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "vislib/scene/import.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/scene_transform.h"

namespace pvs_cli {

// Options of the importers that have them (.bsp: docs/scene-model.md), as every command that
// loads a scene may take them.
struct ImportArgs {
  std::string bsp_models = "world";      // world | all
  std::string bsp_liquids = "opaque";    // opaque | omit | see-through
  std::vector<std::string> see_through;  // --see-through: object name patterns
  std::vector<std::string> opaque;       // --opaque: object or material name patterns
};
// Adds --bsp-models, --bsp-liquids, --see-through and --opaque to `cmd`.
void add_import_options(CLI::App* cmd, ImportArgs& args);

// --scale S, --rotate DEG,AX,AY,AZ, --translate X,Y,Z: the similarity x' = S * (R x) + T (R: DEG
// degrees about the axis through the origin, right-handed), to move a scene to another place,
// orientation and unit (docs/visibility-math.md §6 "Invariance under transformation").
struct TransformArgs {
  double scale = 1;
  std::string rotate, translate;
  bool any() const { return scale != 1 || !rotate.empty() || !translate.empty(); }
};
// Adds --scale, --rotate and --translate to `cmd`; `what` ends their help ("the scene", ...).
void add_transform_options(CLI::App* cmd, TransformArgs& args, const std::string& what);
// The similarity of `args` (CLI::ValidationError naming the option when malformed).
vislib::Similarity parse_transform(const TransformArgs& args);
// transform_scene, then CLI::ValidationError (naming --scale) when a coordinate is no longer
// finite.
void transform_scene_for_cli(vislib::Scene& scene, const vislib::Similarity& sim);
// The matrix as r00,...,r22 (%.17g), as --orientation reads it.
std::string matrix_text(const vislib::Mat3& m);
// The importer options of `import` with `states` key states (not checked here).
vislib::LoadOptions load_options_of(const ImportArgs& import, int states = 1);

// Loads `path` with `states` key states (throws CLI::ValidationError naming --states if < 1;
// InputError from the importer passes through). Importer warnings go to stderr. First the
// objects and materials named by `import.opaque` are kept opaque (vislib::keep_opaque), then the
// objects whose names match one of `import.see_through` become see-through
// (vislib::mark_see_through); a pattern of either that matches nothing is an error naming it
// (CLI::ValidationError, exit 2). A scene left mostly see-through is warned about
// (vislib::see_through_warning). With `map`, `path` must be a .bsp: it is read once
// (vislib::load_bsp_scene) and the parsed map is left in *map for whatever else needs it.
vislib::Scene load_scene_for_cli(const std::string& path, int states = 1,
                                 const ImportArgs& import = {}, vislib::QuakeBsp* map = nullptr);

}  // namespace pvs_cli
