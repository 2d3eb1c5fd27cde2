// import.cpp: load_scene dispatches by extension and checks what every importer must guarantee
// (finite coordinates, indices in range, one object per triangle and sphere).
#include "vislib/scene/import.h"

#include <cassert>
#include <cstdio>
#include <string>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"
#include "vislib/scene/quake_bsp.h"

namespace vislib {

namespace {

std::string describe(Vec3 p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", p.x, p.y, p.z);
  return buf;
}

// Safety net behind the per-format checks: no importer may hand out a scene that breaks the
// contract of scene.h.
void check_scene(const std::string& path, const Scene& s) {
  for (size_t k = 0; k < s.positions.size(); ++k)
    for (size_t v = 0; v < s.positions[k].size(); ++v)
      if (!is_finite(s.positions[k][v]))
        throw InputError(path, "vertex " + std::to_string(v) + " (state " + std::to_string(k) +
                                   ") is not finite: " + describe(s.positions[k][v]));
  for (size_t k = 0; k < s.sphere_centers.size(); ++k)
    for (size_t i = 0; i < s.sphere_centers[k].size(); ++i)
      if (!is_finite(s.sphere_centers[k][i]))
        throw InputError(path, "sphere " + std::to_string(i) + " (state " + std::to_string(k) +
                                   ") has a non-finite centre " + describe(s.sphere_centers[k][i]));
  size_t n = s.vertex_count();
  for (size_t t = 0; t < s.triangles.size(); ++t)
    for (uint32_t i : s.triangles[t])
      if (i >= n)
        throw InputError(path, "triangle " + std::to_string(t) + " has vertex index " +
                                   std::to_string(i) + " >= vertex count " + std::to_string(n));
  assert(s.triangle_object.size() == s.triangles.size());
  assert(s.sphere_object.size() == s.sphere_radius.size());
}

// The scene `load` returns, built under the memory stage "loading PATH" and checked.
template <class F>
Scene checked_load(const std::string& path, F&& load) {
  return with_memory_stage("loading " + path, [&] {
    Scene scene = load();
    check_scene(path, scene);
    return scene;
  });
}

}  // namespace

Scene load_scene(const std::string& path, const LoadOptions& options,
                 std::vector<std::string>* warnings) {
  assert(options.states >= 1);
  std::vector<std::string> local;
  std::vector<std::string>& warn = warnings ? *warnings : local;
  std::string ext = file_extension(path);
  return checked_load(path, [&] {
    if (ext == ".gltf" || ext == ".glb") return load_gltf(path, options, warn);
    if (ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl")
      return load_mesh(path, warn);
    if (ext == ".spheres") return load_spheres(path, warn);
    if (ext == ".bsp") return load_bsp(read_quake_bsp(path), path, options, warn);
    throw InputError(path, "unsupported file format '" +
                               (ext.empty() ? std::string("(none)") : ext) +
                               "' (supported: .gltf .glb .obj .ply .off .stl .spheres .bsp)");
  });
}

Scene load_bsp_scene(const std::string& path, const LoadOptions& options, QuakeBsp& map,
                     std::vector<std::string>* warnings) {
  std::vector<std::string> local;
  std::vector<std::string>& warn = warnings ? *warnings : local;
  return checked_load(path, [&] {
    map = read_quake_bsp(path);
    return load_bsp(map, path, options, warn);
  });
}

}  // namespace vislib
