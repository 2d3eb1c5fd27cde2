// ray_reference.h: the double-precision brute-force first hit (docs/visibility-math.md §8,
// "Reference" bullet): Moller-Trumbore in double over every triangle of a scene, with the margins
// that tell a stable answer from one that may differ between exact arithmetic, float and double.
// The independent answer against which Embree's float hits are re-cast: by the tests' oracles
// (tests/support/ray_oracle.h) and by `pvs vis-compare` (vis_compare.h).
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Tolerances of the reference (docs/visibility-math.md §8 "Reference"). All err towards
// "ambiguous" (a sample a check must skip, never fail).
constexpr double kReferenceBarycentric = 1e-9;  // smallest barycentric (unitless)
constexpr double kReferenceDepthGap = 1e-7;     // gap to the next hit, relative to lambda
constexpr double kReferenceNear = 1e-9;         // |lambda - z_near|, absolute (depth units)

struct OracleSample {
  uint32_t tri = kNoHit;  // first-hit triangle id, or kNoHit
  double lambda = 0;      // its depth (inf when kNoHit)
  bool ambiguous = false;
};

// One triangle the line eye + lambda*dir passes through or within the barycentric margin: its
// depth lambda (any sign) and its smallest barycentric (>= -kReferenceBarycentric; < 0 a near
// miss).
struct RayCrossing {
  uint32_t tri = 0;
  double lambda = 0, min_bary = 0;
};
// Every crossing of the line with the triangles of `scene` at animation time `tau` (vertices
// re-centred at `eye` in double), in increasing triangle id; triangles parallel to the line or
// degenerate have none. O(triangles). `dir` must be finite and non-zero. Thread-safe,
// deterministic.
std::vector<RayCrossing> ray_crossings(const Scene& scene, double tau, Vec3 eye, Vec3 dir);

// ray_crossings' answer without visiting every triangle: a bounding-volume hierarchy over the
// triangles' boxes at one animation time, each box widened by kCrossingIndexRelativePad of its
// diagonal plus kCrossingIndexScenePad of the scene's size (so that every crossing or near miss
// that the double arithmetic can report lies inside it), and the triangles too thin for that
// bound (height over longest edge at most kCrossingIndexThinness, degenerate ones included:
// their double barycentrics can land anywhere) tested on every line. The candidates then go
// through ray_crossings' own arithmetic, so the answer is the same list, in the same order.
// O(log triangles + candidates + thin triangles) per line. Immutable once built; thread-safe.
constexpr double kCrossingIndexRelativePad = 1e-3;  // of a triangle's box diagonal (unitless)
constexpr double kCrossingIndexScenePad = 1e-7;     // of 1 + the largest |coordinate| (scene units)
constexpr double kCrossingIndexThinness = 1e-3;     // height / longest edge (unitless)
class RayCrossingIndex {
 public:
  RayCrossingIndex(const Scene& scene, double tau);
  // ray_crossings(scene, tau, eye, dir), equal element for element.
  std::vector<RayCrossing> crossings(Vec3 eye, Vec3 dir) const;

 private:
  struct Node {
    Box3 box;
    uint32_t first = 0, count = 0;  // a leaf: order_[first, first + count); else count == 0
    uint32_t left = 0, right = 0;   // an inner node's children
  };
  // Lays out the subtree of order_[first, first + count) (median split on the widest axis of
  // the box centres) and returns its node.
  uint32_t build(const std::vector<Box3>& boxes, const std::vector<Vec3>& centres, uint32_t first,
                 uint32_t count);
  std::vector<Vec3> corners_;    // 3 per triangle, as ray_crossings reads them
  std::vector<uint32_t> order_;  // triangle ids, grouped by leaf
  std::vector<uint32_t> thin_;   // tested on every line
  std::vector<Node> nodes_;
};

// The exact-as-double first hit of the ray eye + lambda*dir (lambda > z_near) over every triangle
// of `scene` at animation time `tau` (Moller-Trumbore, vertices re-centred at `eye` in double).
// Ties in lambda go to the lower id. `ambiguous` is set when the winner's smallest barycentric is
// <= kReferenceBarycentric, the next hit of another triangle is within kReferenceDepthGap*lambda,
// the winner's lambda is within kReferenceNear of z_near, a triangle missed by at most
// kReferenceBarycentric lies in front of (or within the depth gap behind) the winner, or a triangle
// on the ray lies within kReferenceNear of z_near. O(triangles) per ray.
// `dir` must be finite and non-zero. Thread-safe, deterministic.
// Every triangle counts as opaque here (Object::see_through is not read); brute_force_hits is
// the reference of the see-through rule.
OracleSample brute_force_first_hit(const Scene& scene, double tau, Vec3 eye, Vec3 dir,
                                   double z_near);

// One ray under the see-through rule (docs/visibility.md "See-through triangles"): the ray
// passes through see-through triangles, recording each one, until the first opaque hit.
struct OracleRay {
  // The first opaque hit, with the ambiguity of brute_force_first_hit over the opaque triangles.
  OracleSample opaque;
  // See-through triangles hit at z_near < lambda <= opaque.lambda (a tie counts), ascending ids,
  // without those in `see_through_ambiguous`.
  std::vector<uint32_t> see_through;
  // See-through triangles whose status is not stable: hit or missed within kReferenceBarycentric,
  // within kReferenceNear of z_near, or within kReferenceDepthGap * lambda of the opaque hit. A
  // test neither requires nor refuses them.
  std::vector<uint32_t> see_through_ambiguous;
};
// The double-precision brute force of brute_force_first_hit with that rule. Thread-safe,
// deterministic; O(triangles) per ray.
OracleRay brute_force_hits(const Scene& scene, double tau, Vec3 eye, Vec3 dir, double z_near);

}  // namespace vislib
