// ray_oracle.h: the ray-cast test oracle of docs/visibility-math.md §8 for the from-segment
// algorithm.
//
// Two independent first-hit answers for the ray (v(t), d) of a cubemap pixel, v(t) = v0 + t(v1-v0),
// d = pixel_direction(face_axes(face, R), x, y, n), hits at lambda > z_near:
//  - RayOracle: Embree (float) with an on-demand ambiguity test (§8 "Embree" bullet, extended by a
//    depth-gap and a near-plane test). Tests compare the cheap first_hit() with their own answer
//    and call is_ambiguous() only on a mismatch.
//  - brute_force_first_hit: double-precision Moller-Trumbore over every triangle with the margins
//    of the §8 "Reference" bullet, for tiny scenes.
// An ambiguous sample is one where the answer may legitimately differ between exact arithmetic,
// float and double; an oracle must skip it, never fail it.
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Tolerances of RayOracle::is_ambiguous. All err towards "ambiguous" (skip the sample).
constexpr double kOracleDirJitter =
    1e-5;  // jitter of sc and tc (face coordinates, face = [-1,1]^2)
constexpr double kOracleTimeJitter = 1e-6;  // jitter of the segment parameter t (unitless)
constexpr double kOracleDepthGap = 1e-6;    // next surface within this gap, relative to lambda
constexpr double kOracleNearBand =
    1e-6;  // a surface within this band of z_near, relative to z_near

// Tolerances of brute_force_first_hit (docs/visibility-math.md §8 "Reference").
constexpr double kReferenceBarycentric = 1e-9;  // smallest barycentric (unitless)
constexpr double kReferenceDepthGap = 1e-7;     // gap to the next hit, relative to lambda
constexpr double kReferenceNear = 1e-9;         // |lambda - z_near|, absolute (depth units)

struct OracleSample {
  uint32_t tri = kNoHit;  // first-hit triangle id, or kNoHit
  double lambda = 0;      // its depth (inf when kNoHit)
  bool ambiguous = false;
};

// The Embree oracle for one segment, orientation, resolution and near distance. Holds a reference
// to `scene`, which must outlive it (build the scene with origin v0 for best float precision).
// All queries are const, thread-safe and deterministic.
class RayOracle {
 public:
  // `n` must be >= 1, `z_near` > 0, R a rotation.
  RayOracle(const EmbreeScene& scene, Vec3 v0, Vec3 v1, const Mat3& R, int n, double z_near);

  // The eye v(t) (world) and the un-normalised direction of pixel (face, x, y).
  Vec3 eye(double t) const { return lerp(v0_, v1_, t); }
  Vec3 direction(int face, int x, int y) const { return pixel_direction(axes_[face], x, y, n_); }

  // One Embree cast: the cheap answer to compare against. 0 <= face < 6, 0 <= x, y < n.
  Hit first_hit(int face, int x, int y, double t) const;

  // True when the first hit of (face, x, y, t) is not stable: the id changes under a re-cast with
  // sc or tc jittered by +-kOracleDirJitter (8 jitters: axes and diagonals) or t by
  // +-kOracleTimeJitter; or the next-nearest other triangle along the ray lies within
  // kOracleDepthGap*lambda behind the first hit; or a surface lies within kOracleNearBand*z_near of
  // z_near (the first hit's lambda, or a hit that appears when the near distance is lowered by the
  // band). About 12 casts: call it only on a mismatch.
  bool is_ambiguous(int face, int x, int y, double t) const;

  // first_hit plus is_ambiguous.
  OracleSample sample(int face, int x, int y, double t) const;

 private:
  Vec3 direction_at(int face, double sc, double tc) const;
  const EmbreeScene& scene_;
  Vec3 v0_, v1_;
  FaceAxes axes_[kCubeFaces];
  int n_;
  double z_near_;
};

// The exact-as-double first hit of the ray eye + lambda*dir (lambda > z_near) over every triangle
// of `scene` at animation time `tau` (Moller-Trumbore, vertices re-centred at `eye` in double).
// Ties in lambda go to the lower id. `ambiguous` is set when the winner's smallest barycentric is
// <= kReferenceBarycentric, the next hit of another triangle is within kReferenceDepthGap*lambda,
// the winner's lambda is within kReferenceNear of z_near, a triangle missed by at most
// kReferenceBarycentric lies in front of (or within the depth gap behind) the winner, or a triangle
// on the ray lies within kReferenceNear of z_near. O(triangles) per ray: tiny scenes only.
// `dir` must be finite and non-zero. Thread-safe, deterministic.
// Every triangle counts as opaque here (Object::see_through is not read); brute_force_hits is
// the oracle of the see-through rule.
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
