// scene_fingerprint.cpp: the scene fingerprint of a Scene, through pvs::SceneFingerprint (the one
// implementation of the byte stream of docs/pvs-format.md, shared with the runtime's C API).
#include "vislib/scene/scene_fingerprint.h"

#include "pvs_format/pvs_format.h"

namespace vislib {

uint64_t scene_fingerprint(const Scene& scene) {
  pvs::SceneFingerprint f(scene.positions.size(), scene.vertex_count(), scene.triangle_count(),
                          scene.objects.size());
  for (const auto& state : scene.positions)
    for (const Vec3& p : state) f.add_position(p.x, p.y, p.z);
  for (size_t t = 0; t < scene.triangles.size(); ++t) {
    const auto& tri = scene.triangles[t];
    f.add_triangle(tri[0], tri[1], tri[2], scene.triangle_object[t]);
  }
  return f.value();
}

}  // namespace vislib
