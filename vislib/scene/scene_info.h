// scene_info.h: statistics and a hygiene report of a scene (what `pvs info` prints).
#pragma once

#include <cstddef>
#include <string>

#include "vislib/scene/scene.h"

namespace vislib {

struct SceneInfo {
  size_t triangles = 0, vertices = 0, objects = 0, states = 0, spheres = 0;
  // Object::see_through: objects so marked and their triangles.
  size_t see_through_objects = 0, see_through_triangles = 0;
  bool dynamic = false;
  Box3
      bbox;  // over all states, spheres with their radius (Scene::bounds); empty for an empty scene
  double diagonal = 0;  // length of the bbox diagonal (0 if empty)
  // No units claim: mesh formats record none, and a guess from the size alone was wrong on real
  // scenes (a millimetre hotel room taken for centimetres, Sauerbraten maps for metres).
  // Distance of the bbox centre from the origin, in file units, and whether that makes the scene
  // lie far from the origin (far_from_origin below).
  double origin_offset = 0;
  bool far_from_origin = false;
  // Hygiene, in state 0 unless said otherwise.
  size_t degenerate_triangles = 0;  // a repeated index or zero area (|cross| == 0, in double)
  size_t nonfinite_vertices = 0;    // vertices with a NaN/inf coordinate in any state
  size_t duplicate_vertices = 0;    // bit-identical positions: each extra copy counts once
  size_t out_of_range_indices =
      0;  // triangle corners >= vertex count (0 after a successful import)
};

// True when a scene with bounding box `bbox` lies far from the origin: its centre farther than
// kFarFromOriginDiagonals diagonals and than kFarFromOriginUnits units. vislib re-centres and
// works in double (exact enough), but float32 consumers (the Embree baseline and oracle, renderers,
// engines) lose precision there: at 1e5, float32 steps are 7.8 mm.
constexpr double kFarFromOriginDiagonals = 10;
constexpr double kFarFromOriginUnits = 1e4;
bool far_from_origin(const Box3& bbox);

// A scene of which more than this share of the triangles is see-through (unitless, in [0, 1]) is
// warned about (see_through_warning): a cell sees through them all, so an exported model whose
// every material is BLEND or MASK bakes to nearly the whole scene in every cell. Errs towards
// warning; windows, water and foliage of a real level stay well below it.
constexpr double kSeeThroughWarnShare = 0.10;

// Empty, or a warning (one line, naming the scene as `name`) when more than
// kSeeThroughWarnShare of the scene's triangles are see-through: the share, the materials
// (Object::alpha_materials) and the objects marked by name that make them so (the first few of
// each), and the option that keeps them opaque (--opaque PATTERNS).
std::string see_through_warning(const Scene& scene, const std::string& name);

// Computes the statistics. Works on any Scene, even one that breaks the scene.h contract
// (out-of-range indices are counted, never followed). Deterministic; O(V + T) expected time.
SceneInfo scene_info(const Scene& scene);

// JSON object (a string, to keep nlohmann out of this header) with the keys `triangles`,
// `vertices`, `objects`, `states`, `spheres`, `dynamic`, `bbox` ({"min":[x,y,z],"max":[x,y,z]}
// or null), `diagonal`, `origin_offset`, `far_from_origin`, `degenerate_triangles`,
// `nonfinite_vertices`, `duplicate_vertices`, `out_of_range_indices`. `indent` as in
// nlohmann::json::dump.
std::string to_json(const SceneInfo& info, int indent = 2);

}  // namespace vislib
