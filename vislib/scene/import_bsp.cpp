// import_bsp.cpp: compiled Quake maps (.bsp: BSP29, BSP2, 2PSB; quake_bsp.h) as scenes.
//
// The faces bsp_face_triangles selects (model 0 by default, every model with BspModels::all;
// liquid faces kept, omitted or see-through) become objects, one per face, in map face order, named
// "face<F>_<texture>" (F = the map's face index). Each face gets its own block of vertices, its
// edge loop in stored order converted to y-up (quake_to_scene), and is fan-triangulated
// (v0, vi, vi+1): face F's triangles are bsp_face_triangles(...)[F]. Sky faces are kept as
// ordinary triangles. Units stay Quake units.
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"
#include "vislib/scene/quake_bsp.h"

namespace vislib {

Scene load_bsp(const QuakeBsp& bsp, const std::string& path, const LoadOptions& options,
               std::vector<std::string>& warnings) {
  const std::vector<BspFaceTriangles> faces = bsp_face_triangles(bsp, options);
  Scene scene;
  scene.positions.resize(1);
  auto& pos = scene.positions[0];
  size_t short_faces = 0;
  const size_t models = options.bsp_models == BspModels::all ? bsp.models.size() : 1;
  for (size_t i = 0; i < models; ++i)
    for (uint32_t k = 0; k < bsp.models[i].face_count; ++k)
      if (bsp.faces[bsp.models[i].first_face + k].edge_count < 3) ++short_faces;
  for (uint32_t f = 0; f < bsp.faces.size(); ++f) {
    if (!faces[f].imported) continue;
    const uint32_t object = uint32_t(scene.objects.size());
    const std::string texture = bsp.face_texture(f);
    scene.objects.push_back({"face" + std::to_string(f) + "_" + texture});
    // Liquids (a '*' texture) seen but not occluding, as the compiler's vis treated them.
    scene.objects.back().see_through =
        options.bsp_liquids == BspLiquids::see_through && !texture.empty() && texture[0] == '*';
    const uint32_t first = uint32_t(pos.size());
    for (uint32_t v : bsp.face_vertices(f)) {
      const auto& q = bsp.vertices[v];
      pos.push_back(quake_to_scene({double(q[0]), double(q[1]), double(q[2])}));
    }
    for (uint32_t k = 0; k < faces[f].triangle_count; ++k) {
      scene.triangles.push_back({first, first + k + 1, first + k + 2});
      scene.triangle_object.push_back(object);
    }
  }
  if (short_faces)
    warnings.push_back(path + ": " + std::to_string(short_faces) +
                       " face(s) with fewer than 3 edges skipped");
  if (scene.triangles.empty()) warnings.push_back(path + ": no faces");
  return scene;
}

}  // namespace vislib
