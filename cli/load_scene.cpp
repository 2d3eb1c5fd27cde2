#include "cli/load_scene.h"

#include <chrono>
#include <cstdio>

#include "cli/commands.h"
#include "cli/options.h"

namespace pvs_cli {

vislib::Scene load_scene_for_cli(const std::string& path, int states) {
  if (states < 1)
    throw CLI::ValidationError("--states", "must be >= 1, got " + std::to_string(states));
  vislib::LoadOptions options;
  options.states = states;
  std::vector<std::string> warnings;
  const auto t0 = std::chrono::steady_clock::now();
  vislib::Scene scene = vislib::load_scene(path, options, &warnings);
  for (const auto& w : warnings) warn(w);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "loaded %s: %zu triangles, %zu objects, %zu spheres, %zu key states in %.2f s",
                path.c_str(), scene.triangle_count(), scene.objects.size(), scene.sphere_count(),
                scene.state_count(),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  info(buf);
  return scene;
}

}  // namespace pvs_cli
