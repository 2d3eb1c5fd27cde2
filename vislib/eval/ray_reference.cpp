// ray_reference.cpp: the double-precision brute-force first hit of docs/visibility-math.md §8
// ("Reference" bullet).
#include "vislib/eval/ray_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vislib {

namespace {

using Candidate = RayCrossing;

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

std::vector<RayCrossing> ray_crossings(const Scene& scene, double tau, Vec3 eye, Vec3 dir) {
  return candidates_on_ray(scene, tau, eye, dir, [](uint32_t) { return true; });
}

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
