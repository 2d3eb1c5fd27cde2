// scene_info.h: statistics and a hygiene report of a scene (what `pvs info` prints).
#pragma once

#include <cstddef>
#include <string>

#include "vislib/scene/scene.h"

namespace vislib {

struct SceneInfo {
  size_t triangles = 0, vertices = 0, objects = 0, states = 0, spheres = 0;
  bool dynamic = false;
  Box3 bbox;  // over all states, spheres with their radius (Scene::bounds); empty for an empty scene
  double diagonal = 0;  // length of the bbox diagonal (0 if empty)
  // From the diagonal, in file units: [0.1, 3000] "meters (likely)", (3000, 300000]
  // "centimeters (likely)", else "unknown". A guess for the reader, never used in computation.
  std::string units_guess;
  // Hygiene, in state 0 unless said otherwise.
  size_t degenerate_triangles = 0;  // a repeated index or zero area (|cross| == 0, in double)
  size_t nonfinite_vertices = 0;    // vertices with a NaN/inf coordinate in any state
  size_t duplicate_vertices = 0;    // bit-identical positions: each extra copy counts once
  size_t out_of_range_indices = 0;  // triangle corners >= vertex count (0 after a successful import)
};

// Computes the statistics. Works on any Scene, even one that breaks the scene.h contract
// (out-of-range indices are counted, never followed). Deterministic; O(V + T) expected time.
SceneInfo scene_info(const Scene& scene);

// JSON object (a string, to keep nlohmann out of this header) with the keys `triangles`,
// `vertices`, `objects`, `states`, `spheres`, `dynamic`, `bbox` ({"min":[x,y,z],"max":[x,y,z]}
// or null), `diagonal`, `units_guess`, `degenerate_triangles`, `nonfinite_vertices`,
// `duplicate_vertices`, `out_of_range_indices`. `indent` as in nlohmann::json::dump.
std::string to_json(const SceneInfo& info, int indent = 2);

}  // namespace vislib
