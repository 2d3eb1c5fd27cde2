// write_spheres.cpp: the sphere text format of write_spheres.h.
#include "vislib/scene/write_spheres.h"

#include <cassert>
#include <cstdio>

namespace vislib {

std::string spheres_to_text(const Scene& scene) {
  const size_t K = scene.sphere_centers.empty() ? 1 : scene.sphere_centers.size();
  std::string out = "vislib-spheres 1\n# radius, then the centre x y z in each state\nstates " +
                    std::to_string(K) + "\n";
  char buf[32];
  auto num = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.17g", v);
    out += buf;
  };
  for (size_t i = 0; i < scene.sphere_count(); ++i) {
    num(scene.sphere_radius[i]);
    for (const auto& state : scene.sphere_centers) {
      assert(state.size() == scene.sphere_count());
      for (int c = 0; c < 3; ++c) {
        out += ' ';
        num(state[i][c]);
      }
    }
    out += '\n';
  }
  return out;
}

}  // namespace vislib
