#include "cli/load_scene.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "cli/commands.h"
#include "cli/options.h"
#include "vislib/scene/scene_info.h"

namespace pvs_cli {

void add_transform_options(CLI::App* cmd, TransformArgs& args, const std::string& what) {
  cmd->add_option("--scale", args.scale, "Scale " + what + " by S (after --rotate)")
      ->check(positive());
  cmd->add_option("--rotate", args.rotate,
                  "Rotate " + what + " by DEG degrees about the axis AX,AY,AZ through the origin");
  cmd->add_option("--translate", args.translate,
                  "Move " + what + " by X,Y,Z (after --rotate and --scale)");
}

vislib::Similarity parse_transform(const TransformArgs& args) {
  vislib::Similarity sim;
  sim.scale = args.scale;
  if (!args.rotate.empty()) {
    auto r = parse_doubles(args.rotate, "--rotate", 4);
    for (double x : r)
      if (!std::isfinite(x)) throw CLI::ValidationError("--rotate", "the numbers must be finite");
    if (!(r[1] != 0 || r[2] != 0 || r[3] != 0))
      throw CLI::ValidationError("--rotate", "the axis must not be zero");
    sim.rotation = vislib::axis_angle_rotation({r[1], r[2], r[3]}, r[0]);
  }
  if (!args.translate.empty()) sim.translation = parse_vec3(args.translate, "--translate");
  if (!vislib::is_finite(sim.translation))
    throw CLI::ValidationError("--translate", "the numbers must be finite");
  return sim;
}

void transform_scene_for_cli(vislib::Scene& scene, const vislib::Similarity& sim) {
  vislib::transform_scene(scene, sim);
  const vislib::Box3 b = scene.bounds();
  if (!b.empty() && !(vislib::is_finite(b.min) && vislib::is_finite(b.max)))
    throw CLI::ValidationError("--scale",
                               "the transform moves the scene beyond the range of double");
}

std::string matrix_text(const vislib::Mat3& m) {
  std::string out;
  for (double x : m.m) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.17g", out.empty() ? "" : ",", x);
    out += buf;
  }
  return out;
}

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
                  "objects with BLEND materials, or MASK ones whose alpha can fall below the "
                  "cutoff, are see-through already; docs/scene-model.md)")
      ->delimiter(',');
  cmd->add_option("--opaque", args.opaque,
                  "Objects or glTF materials whose names match these shell patterns "
                  "(comma-separated) are kept opaque whatever their alpha mode (a cutout kept "
                  "opaque hides what is seen through its holes; docs/scene-model.md)")
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

vislib::Scene load_scene_for_cli(const std::string& path, int states, const ImportArgs& import,
                                 vislib::QuakeBsp* map) {
  if (states < 1)
    throw CLI::ValidationError("--states", "must be >= 1, got " + std::to_string(states));
  const vislib::LoadOptions options = load_options_of(import, states);
  std::vector<std::string> warnings;
  const auto t0 = std::chrono::steady_clock::now();
  vislib::Scene scene = map ? vislib::load_bsp_scene(path, options, *map, &warnings)
                            : vislib::load_scene(path, options, &warnings);
  for (const auto& w : warnings) warn(w);
  const std::vector<size_t> kept = vislib::keep_opaque(scene, import.opaque);
  for (size_t i = 0; i < kept.size(); ++i)
    if (kept[i] == 0)
      throw CLI::ValidationError("--opaque", "pattern '" + import.opaque[i] +
                                                 "' matches no object or see-through material of " +
                                                 path);
  for (const std::string& p : import.see_through)
    if (vislib::mark_see_through(scene, {p}) == 0)
      throw CLI::ValidationError("--see-through",
                                 "pattern '" + p + "' matches no object of " + path);
  const std::string see_through = vislib::see_through_warning(scene, path);
  if (!see_through.empty()) warn(see_through);
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
