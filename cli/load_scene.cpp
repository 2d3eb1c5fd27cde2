#include "cli/load_scene.h"

#include <chrono>
#include <cstdio>

#include "cli/commands.h"
#include "cli/options.h"
#include "vislib/scene/scene_info.h"

namespace pvs_cli {

void add_import_options(CLI::App* cmd, ImportArgs& args) {
  cmd->add_option("--bsp-models", args.bsp_models,
                  "Quake maps: 'world' (model 0, default) or 'all' (brush entities too)")
      ->check(CLI::IsMember({"world", "all"}));
  cmd->add_option("--bsp-liquids", args.bsp_liquids,
                  "Quake maps, faces with '*' textures: 'opaque' (default), 'omit' or "
                  "'see-through' (seen, not occluding)")
      ->check(CLI::IsMember({"opaque", "omit", "see-through"}));
  cmd->add_option("--see-through", args.see_through,
                  "Objects whose names match these shell patterns (comma-separated; a literal * "
                  "is [*]) are see-through: seen, never hiding anything (static scenes; glTF "
                  "objects with BLEND or MASK materials are see-through already; "
                  "docs/scene-model.md)")
      ->delimiter(',');
}

vislib::LoadOptions load_options_of(const ImportArgs& import, int states) {
  vislib::LoadOptions options;
  options.states = states;
  options.bsp_models =
      import.bsp_models == "all" ? vislib::BspModels::all : vislib::BspModels::world;
  options.bsp_liquids = import.bsp_liquids == "omit"          ? vislib::BspLiquids::omit
                        : import.bsp_liquids == "see-through" ? vislib::BspLiquids::see_through
                                                              : vislib::BspLiquids::opaque;
  return options;
}

vislib::Scene load_scene_for_cli(const std::string& path, int states, const ImportArgs& import) {
  if (states < 1)
    throw CLI::ValidationError("--states", "must be >= 1, got " + std::to_string(states));
  const vislib::LoadOptions options = load_options_of(import, states);
  std::vector<std::string> warnings;
  const auto t0 = std::chrono::steady_clock::now();
  vislib::Scene scene = vislib::load_scene(path, options, &warnings);
  for (const auto& w : warnings) warn(w);
  for (const std::string& p : import.see_through)
    if (vislib::mark_see_through(scene, {p}) == 0)
      throw CLI::ValidationError("--see-through",
                                 "pattern '" + p + "' matches no object of " + path);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "loaded %s: %zu triangles, %zu objects, %zu spheres, %zu key states in %.2f s",
                path.c_str(), scene.triangle_count(), scene.objects.size(), scene.sphere_count(),
                scene.state_count(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  info(buf);
  vislib::Box3 b = scene.bounds();
  if (vislib::far_from_origin(b)) {
    char far_msg[512];
    std::snprintf(far_msg, sizeof far_msg,
                  "%s: the scene lies far from the origin (centre %g away, %g times its size): "
                  "vislib works in "
                  "double and is not affected, but float32 consumers (the Embree baseline, "
                  "renderers, engines) "
                  "lose precision there; consider re-centring it",
                  path.c_str(), length((b.min + b.max) * 0.5),
                  length((b.min + b.max) * 0.5) / length(b.max - b.min));
    warn(far_msg);
  }
  return scene;
}

}  // namespace pvs_cli
