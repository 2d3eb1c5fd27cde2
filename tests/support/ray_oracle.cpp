// ray_oracle.cpp: the Embree ray-cast oracle of docs/visibility-math.md §8 (with ambiguity tests).
#include "tests/support/ray_oracle.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace vislib {

RayOracle::RayOracle(const EmbreeScene& scene, Vec3 v0, Vec3 v1, const Mat3& R, int n,
                     double z_near)
    : scene_(scene), v0_(v0), v1_(v1), n_(n), z_near_(z_near) {
  assert(n >= 1 && z_near > 0.0);
  for (int k = 0; k < kCubeFaces; ++k) axes_[k] = face_axes(k, R);
}

Vec3 RayOracle::direction_at(int face, double sc, double tc) const {
  const FaceAxes& a = axes_[face];
  return a.F + a.S * sc + a.T * tc;
}

Hit RayOracle::first_hit(int face, int x, int y, double t) const {
  assert(face >= 0 && face < kCubeFaces && x >= 0 && x < n_ && y >= 0 && y < n_);
  return scene_.first_hit(eye(t), direction(face, x, y), z_near_);
}

bool RayOracle::is_ambiguous(int face, int x, int y, double t) const {
  const Vec3 e = eye(t), d = direction(face, x, y);
  const Hit base = scene_.first_hit(e, d, z_near_);
  if (base.tri != kNoHit) {
    if (base.lambda <= z_near_ * (1.0 + kOracleNearBand)) return true;
    const Hit next = scene_.first_hit_excluding(e, d, z_near_, base.tri);
    if (next.tri != kNoHit && next.lambda - base.lambda <= kOracleDepthGap * base.lambda)
      return true;
  }
  // A surface just in front of the near plane (Embree decides lambda > z_near in float).
  if (scene_.first_hit(e, d, z_near_ * (1.0 - kOracleNearBand)).tri != base.tri) return true;
  const double sc = pixel_center(x, n_), tc = pixel_center(y, n_), j = kOracleDirJitter;
  static const int kJitter[8][2] = {{1, 0}, {-1, 0}, {0, 1},  {0, -1},
                                    {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  for (const auto& k : kJitter)
    if (scene_.first_hit(e, direction_at(face, sc + j * k[0], tc + j * k[1]), z_near_).tri !=
        base.tri)
      return true;
  for (double dt : {-kOracleTimeJitter, kOracleTimeJitter})
    if (scene_.first_hit(eye(t + dt), d, z_near_).tri != base.tri) return true;
  return false;
}

OracleSample RayOracle::sample(int face, int x, int y, double t) const {
  const Hit h = first_hit(face, x, y, t);
  return {h.tri, h.lambda, is_ambiguous(face, x, y, t)};
}

double triangle_depth(const Scene& scene, uint32_t id, Vec3 eye, Vec3 d, double near) {
  auto c = scene.corners(id, 0);
  Vec3 a = c[0] - eye, e1 = c[1] - c[0], e2 = c[2] - c[0], pv = cross(d, e2);
  double det = dot(e1, pv);
  if (det == 0) return INFINITY;
  double u = dot(-a, pv) / det;
  Vec3 qv = cross(-a, e1);
  double v = dot(d, qv) / det, lam = dot(e2, qv) / det;
  if (u < -1e-9 || v < -1e-9 || u + v > 1 + 1e-9 || !(lam > near)) return INFINITY;
  return lam;
}

}  // namespace vislib
