// triangle_bvh.h: a bounding volume hierarchy over the static triangles of one key state, for the
// front-to-back traversal of the tile driver (hidden work never touched).
//
// Without it, every run of the kernel computes, for each cube face, the footprint bounds of every
// triangle that can reach the face and bins them into tiles: O(triangles) per run, most of a run
// in a million-triangle city where a street sees a few thousand. With it, each tile walks the tree
// nearest node first and stops as soon as the nearest possible depth of what is left lies behind
// every pixel of the tile: the nodes behind the street's walls are never opened, and their
// triangles never get footprints. A tree of triangles gives the same visible sets, witnesses and
// pieces as no tree (the culling is exact; tested). The default tree holds the scene's fans
// (triangle_groups.h), composited as polygons: the same sets but for ties at corners
// (docs/visibility-math.md §2.6), in fewer, longer pieces.
//
// Build it once per scene and pass it in SegmentOptions::bvh to every run that uses the same scene
// and state (a bake does; `pvs segment` builds one for its run).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vislib/kernel/triangle_groups.h"
#include "vislib/scene/scene.h"

namespace vislib {

struct TriangleBvh {
  // Bounds in float, rounded outward, so that they contain every corner exactly.
  struct Node {
    float lo[3], hi[3];
    uint32_t first;  // leaf: first index into `order`; inner: index of the left child (right = +1)
    uint32_t count;  // leaf: triangle count (>= 1); inner: 0
  };
  std::vector<Node> nodes;      // nodes[0] is the root (absent when the scene has no triangles)
  std::vector<uint32_t> order;  // primitives (groups of `groups`), leaf by leaf
  // The primitives the kernel composites with this tree: the scene's fans (build_triangle_groups),
  // or, empty, its triangles (a group per triangle).
  TriangleGroups groups;
  size_t state = 0;           // the key state whose positions it bounds
  size_t triangle_count = 0;  // of the scene it was built for
  const Scene* scene = nullptr;

  // True when it was built for `scene` in key state `state` (the kernel checks it and throws
  // std::invalid_argument otherwise).
  bool matches(const Scene& s, size_t st) const {
    return scene == &s && state == st && triangle_count == s.triangle_count();
  }
};

// What a tree's primitives are: the scene's fans (the default: fewer, larger primitives, the
// same visible sets; triangle_groups.h) or its triangles.
enum class BvhPrimitives { Groups, Triangles };

// Median split on the longest axis of the primitives' box centres, at most kBvhLeafSize
// primitives a leaf. Deterministic (ties by index); O(n log n). Over the scene's fans.
constexpr uint32_t kBvhLeafSize = 4;
TriangleBvh build_triangle_bvh(const Scene& scene, size_t state = 0);
// The same over the primitives asked for.
TriangleBvh build_triangle_bvh(const Scene& scene, BvhPrimitives primitives, size_t state = 0);

// The same over the triangles `subset` only (increasing ids of `scene`; std::invalid_argument
// otherwise), with groups: the groups holding one of them: a run given this tree composites those
// triangles alone, occluders included, and reports ids of the scene. It restricts the scene
// exactly when `subset` holds every triangle the run's segment sees (bake/bsp_bound.h); empty: a
// tree with no node, through which nothing is seen.
TriangleBvh build_triangle_bvh(const Scene& scene, size_t state,
                               const std::vector<uint32_t>& subset);
// The same with the groups given (those of the tree over the whole scene: `bvh.groups`), so that a
// bake builds them once.
TriangleBvh build_triangle_bvh(const Scene& scene, size_t state,
                               const std::vector<uint32_t>& subset, const TriangleGroups& groups);

// Whether a tree serves runs on `scene`: static triangles, no spheres (the dynamic kernel bins).
inline bool bvh_applies(const Scene& scene) {
  return !scene.is_dynamic() && scene.sphere_count() == 0 && scene.triangle_count() > 0;
}

}  // namespace vislib
