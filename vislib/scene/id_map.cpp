// id_map.cpp: runs of consecutive triangle ids of one object (id_map.h).
#include "vislib/scene/id_map.h"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace vislib {

IdMap id_map(const Scene& scene) {
  IdMap map;
  uint32_t next_vertex = 0;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    const uint32_t ob = scene.triangle_object[t];
    if (map.runs.empty() || map.runs.back().object != ob) {
      IdRun run;
      run.object = ob;
      run.first_triangle = t;
      run.first_vertex = UINT32_MAX;
      map.runs.push_back(run);
    }
    IdRun& run = map.runs.back();
    ++run.triangle_count;
    const auto& tri = scene.triangles[t];
    const uint32_t lo = std::min({tri[0], tri[1], tri[2]}), hi = std::max({tri[0], tri[1], tri[2]});
    const uint32_t end = run.first_vertex == UINT32_MAX
                             ? hi + 1
                             : std::max(run.first_vertex + run.vertex_count, hi + 1);
    run.first_vertex = std::min(run.first_vertex, lo);
    run.vertex_count = end - run.first_vertex;
  }
  for (IdRun& run : map.runs) {
    if (run.first_vertex != next_vertex) map.vertices_tiled = false;
    next_vertex = run.first_vertex + run.vertex_count;
  }
  if (next_vertex != scene.vertex_count()) map.vertices_tiled = false;
  return map;
}

std::string id_map_json(const Scene& scene, const IdMap& map) {
  nlohmann::json runs = nlohmann::json::array();
  for (const IdRun& r : map.runs)
    runs.push_back({{"object", r.object},
                    {"name", scene.objects[r.object].name},
                    {"first_triangle", r.first_triangle},
                    {"triangle_count", r.triangle_count},
                    {"first_vertex", r.first_vertex},
                    {"vertex_count", r.vertex_count}});
  nlohmann::json j = {{"triangles", scene.triangle_count()},  {"vertices", scene.vertex_count()},
                      {"objects", scene.objects.size()},      {"states", scene.positions.size()},
                      {"vertices_tiled", map.vertices_tiled}, {"runs", runs}};
  return j.dump(1) + "\n";
}

}  // namespace vislib
