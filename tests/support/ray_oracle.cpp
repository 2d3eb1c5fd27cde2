// ray_oracle.cpp: the ray-cast oracle of docs/visibility-math.md §8 (Embree with ambiguity tests,
// and a double-precision brute-force reference).
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

namespace {

struct Candidate {
  uint32_t tri;
  double lambda, min_bary;
};

// Every triangle the ray passes within the barycentric margin; `which(id)` false: skipped.
template <class Which>
std::vector<Candidate> candidates_on_ray(const Scene& scene, double tau, Vec3 eye, Vec3 dir,
                                         Which which) {
  std::vector<Candidate> on_ray;
  const bool single_state = scene.positions.size() == 1;
  for (uint32_t id = 0; id < scene.triangle_count(); ++id) {
    if (!which(id)) continue;
    Vec3 p[3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t vi = scene.triangles[id][k];
      p[k] = (single_state ? scene.positions[0][vi] : scene.position_at(vi, tau)) - eye;
    }
    const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const Vec3 pv = cross(dir, e2);
    const double det = dot(e1, pv);
    if (det == 0.0 || !std::isfinite(det)) continue;  // parallel to the ray or degenerate
    const Vec3 s = -p[0];
    const Vec3 qv = cross(s, e1);
    const double u = dot(s, pv) / det, v = dot(dir, qv) / det, lambda = dot(e2, qv) / det;
    const double min_bary = std::min(std::min(u, v), 1.0 - u - v);
    if (min_bary >= -kReferenceBarycentric) on_ray.push_back({id, lambda, min_bary});
  }
  return on_ray;
}

// The first hit among `on_ray` and its ambiguity (brute_force_first_hit).
OracleSample first_of(const std::vector<Candidate>& on_ray, double z_near) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  OracleSample out;
  out.lambda = inf;
  double winner_bary = 0;
  for (const Candidate& c : on_ray)
    if (c.min_bary >= 0.0 && c.lambda > z_near && c.lambda < out.lambda)
      out.tri = c.tri, out.lambda = c.lambda, winner_bary = c.min_bary;
  if (out.tri != kNoHit) {
    if (winner_bary <= kReferenceBarycentric) out.ambiguous = true;
    if (out.lambda - z_near <= kReferenceNear) out.ambiguous = true;
  }
  const double gap_limit = out.tri == kNoHit ? inf : out.lambda * (1.0 + kReferenceDepthGap);
  for (const Candidate& c : on_ray) {
    if (c.tri == out.tri) continue;
    if (std::fabs(c.lambda - z_near) <= kReferenceNear) out.ambiguous = true;
    // Another hit (or near miss) in front of or just behind the winner.
    if (c.lambda > z_near - kReferenceNear && c.lambda <= gap_limit) out.ambiguous = true;
  }
  return out;
}

}  // namespace

OracleSample brute_force_first_hit(const Scene& scene, double tau, Vec3 eye, Vec3 dir,
                                   double z_near) {
  return first_of(candidates_on_ray(scene, tau, eye, dir, [](uint32_t) { return true; }), z_near);
}

OracleRay brute_force_hits(const Scene& scene, double tau, Vec3 eye, Vec3 dir, double z_near) {
  OracleRay out;
  out.opaque =
      first_of(candidates_on_ray(scene, tau, eye, dir,
                                 [&](uint32_t id) { return !scene.triangle_see_through(id); }),
               z_near);
  if (!scene.has_see_through()) return out;
  const double far = out.opaque.lambda;
  for (const Candidate& c : candidates_on_ray(
           scene, tau, eye, dir, [&](uint32_t id) { return scene.triangle_see_through(id); })) {
    const bool unstable = c.min_bary <= kReferenceBarycentric ||
                          std::fabs(c.lambda - z_near) <= kReferenceNear ||
                          (far < std::numeric_limits<double>::infinity() &&
                           std::fabs(c.lambda - far) <= kReferenceDepthGap * far);
    if (unstable)
      out.see_through_ambiguous.push_back(c.tri);
    else if (c.lambda > z_near && c.lambda <= far)
      out.see_through.push_back(c.tri);
  }
  return out;
}

}  // namespace vislib
