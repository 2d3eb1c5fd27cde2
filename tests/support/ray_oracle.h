// ray_oracle.h: the ray-cast test oracle of docs/visibility-math.md §8 for the from-segment
// algorithm.
//
// Two independent first-hit answers for the ray (v(t), d) of a cubemap pixel, v(t) = v0 + t(v1-v0),
// d = pixel_direction(face_axes(face, R), x, y, n), hits at lambda > z_near:
//  - RayOracle: Embree (float) with an on-demand ambiguity test (§8 "Embree" bullet, extended by a
//    depth-gap and a near-plane test). Tests compare the cheap first_hit() with their own answer
//    and call is_ambiguous() only on a mismatch.
//  - brute_force_first_hit (vislib/eval/ray_reference.h): double-precision Moller-Trumbore over
//    every triangle with the margins of the §8 "Reference" bullet.
// An ambiguous sample is one where the answer may legitimately differ between exact arithmetic,
// float and double; an oracle must skip it, never fail it.
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/ray_reference.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Tolerances of RayOracle::is_ambiguous. All err towards "ambiguous" (skip the sample).
constexpr double kOracleDirJitter =
    1e-5;  // jitter of sc and tc (face coordinates, face = [-1,1]^2)
constexpr double kOracleTimeJitter = 1e-6;  // jitter of the segment parameter t (unitless)
constexpr double kOracleDepthGap = 1e-6;    // next surface within this gap, relative to lambda
constexpr double kOracleNearBand =
    1e-6;  // a surface within this band of z_near, relative to z_near

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

// View depth of triangle `id` (at animation time 0) along eye + lambda d, in double
// (Moller-Trumbore, barycentric margin 1e-9), when lambda > near; infinity when the ray misses it.
// For telling a witness that lies within eps_z of the first hit (a tie) from a false one.
double triangle_depth(const Scene& scene, uint32_t id, Vec3 eye, Vec3 d, double near);

}  // namespace vislib
