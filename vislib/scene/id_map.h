// id_map.h: how PVS ids map to an engine's draw calls (docs/runtime.md, "Binding a PVS to the
// assets"). vislib's importers append each glTF primitive / OBJ group as a run of consecutive
// triangle ids of one object, with its vertices appended as a block; the id map lists those runs,
// so an engine that keeps one draw call per primitive can translate a cell's visible triangle ids
// (sorted) into (draw call, first index, count) ranges, and can recompute the scene fingerprint
// from its own buffers with pvs_rt_scene_fingerprint, one pvs_rt_mesh per run in this order.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vislib/scene/scene.h"

namespace vislib {

// A maximal run of consecutive triangle ids of one object.
struct IdRun {
  uint32_t object = 0;
  uint32_t first_triangle = 0, triangle_count = 0;
  // The smallest vertex block [first_vertex, first_vertex + vertex_count) its indices use.
  uint32_t first_vertex = 0, vertex_count = 0;
};

struct IdMap {
  std::vector<IdRun> runs;  // in triangle id order, covering every triangle
  // True if the runs' vertex blocks tile [0, vertex_count) in order (each starts where the one
  // before ends), i.e. each run is a mesh with its own vertices in vislib's order. Importers of
  // glTF and OBJ produce such scenes; a scene whose objects share vertices does not.
  bool vertices_tiled = true;
};

// The runs of `scene`. O(triangles). Deterministic.
IdMap id_map(const Scene& scene);

// The map as JSON: {"triangles", "vertices", "objects", "vertices_tiled", "runs": [{"object",
// "name", "first_triangle", "triangle_count", "first_vertex", "vertex_count"}, ...]}.
std::string id_map_json(const Scene& scene, const IdMap& map);

}  // namespace vislib
