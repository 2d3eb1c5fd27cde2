// import.cpp: load_scene dispatches by extension and checks what every importer must guarantee
// (finite coordinates, indices in range, one object per triangle and sphere).
#include "vislib/scene/import.h"

#include <cassert>
#include <cstdio>
#include <string>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"

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

}  // namespace

Scene load_scene(const std::string& path, const LoadOptions& options,
                 std::vector<std::string>* warnings) {
  assert(options.states >= 1);
  std::vector<std::string> local;
  std::vector<std::string>& warn = warnings ? *warnings : local;
  std::string ext = file_extension(path);
  return with_memory_stage("loading " + path, [&] {
    Scene scene;
    if (ext == ".gltf" || ext == ".glb") {
      scene = load_gltf(path, options, warn);
    } else if (ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl") {
      scene = load_mesh(path, warn);
    } else if (ext == ".spheres") {
      scene = load_spheres(path, warn);
    } else if (ext == ".bsp") {
      scene = load_bsp(path, options, warn);
    } else {
      throw InputError(path, "unsupported file format '" +
                                 (ext.empty() ? std::string("(none)") : ext) +
                                 "' (supported: .gltf .glb .obj .ply .off .stl .spheres .bsp)");
    }
    check_scene(path, scene);
    return scene;
  });
}

}  // namespace vislib
