// ray_reference.cpp: the double-precision brute-force first hit of docs/visibility-math.md §8
// ("Reference" bullet).
#include "vislib/eval/ray_reference.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace vislib {

namespace {

using Candidate = RayCrossing;

// The crossing of the line eye + lambda*dir with the triangle of corners p (re-centred at the
// eye): false when the line is parallel to it, it is degenerate, or it misses by more than the
// barycentric margin.
inline bool crossing_of(const Vec3 p[3], Vec3 dir, uint32_t id, Candidate& out) {
  const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Vec3 pv = cross(dir, e2);
  const double det = dot(e1, pv);
  if (det == 0.0 || !std::isfinite(det)) return false;  // parallel to the ray or degenerate
  const Vec3 s = -p[0];
  const Vec3 qv = cross(s, e1);
  const double u = dot(s, pv) / det, v = dot(dir, qv) / det, lambda = dot(e2, qv) / det;
  const double min_bary = std::min(std::min(u, v), 1.0 - u - v);
  if (!(min_bary >= -kReferenceBarycentric)) return false;
  out = {id, lambda, min_bary};
  return true;
}

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
    Candidate c;
    if (crossing_of(p, dir, id, c)) on_ray.push_back(c);
  }
  return on_ray;
}

// True when the line eye + t*dir (any t) meets `box`.
inline bool line_meets(const Box3& box, Vec3 eye, Vec3 dir) {
  double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0.0) {
      if (eye[a] < box.min[a] || eye[a] > box.max[a]) return false;
      continue;
    }
    double t0 = (box.min[a] - eye[a]) / dir[a], t1 = (box.max[a] - eye[a]) / dir[a];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
    if (lo > hi) return false;
  }
  return true;
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

RayCrossingIndex::RayCrossingIndex(const Scene& scene, double tau) {
  const size_t n = scene.triangle_count();
  const bool single_state = scene.positions.size() == 1;
  corners_.resize(3 * n);
  double largest = 0;
  for (uint32_t id = 0; id < n; ++id)
    for (int k = 0; k < 3; ++k) {
      const uint32_t vi = scene.triangles[id][k];
      const Vec3 q = single_state ? scene.positions[0][vi] : scene.position_at(vi, tau);
      corners_[3 * size_t(id) + size_t(k)] = q;
      for (int a = 0; a < 3; ++a)
        if (std::isfinite(q[a])) largest = std::max(largest, std::fabs(q[a]));
    }
  const double scene_pad = kCrossingIndexScenePad * (1.0 + largest);
  std::vector<Box3> boxes(n);
  std::vector<Vec3> centres(n);
  for (uint32_t id = 0; id < n; ++id) {
    const Vec3* p = &corners_[3 * size_t(id)];
    const Vec3 e1 = p[1] - p[0], e2 = p[2] - p[0], e3 = p[2] - p[1];
    const double longest2 = std::max({dot(e1, e1), dot(e2, e2), dot(e3, e3)});
    const double twice_area = length(cross(e1, e2));
    // height / longest edge = twice_area / longest^2; NaN or inf corners count as thin too.
    if (!(twice_area > kCrossingIndexThinness * longest2) || !std::isfinite(twice_area)) {
      thin_.push_back(id);
      continue;
    }
    Box3 b;
    for (int k = 0; k < 3; ++k) b.extend(p[k]);
    const double pad = kCrossingIndexRelativePad * length(b.max - b.min) + scene_pad;
    b.min = b.min - Vec3{pad, pad, pad};
    b.max = b.max + Vec3{pad, pad, pad};
    boxes[id] = b;
    centres[id] = (b.min + b.max) * 0.5;
    order_.push_back(id);
  }
  if (!order_.empty()) build(boxes, centres, 0, uint32_t(order_.size()));
}

uint32_t RayCrossingIndex::build(const std::vector<Box3>& boxes, const std::vector<Vec3>& centres,
                                 uint32_t first, uint32_t count) {
  constexpr uint32_t kLeafTriangles = 4;
  const uint32_t node = uint32_t(nodes_.size());
  nodes_.push_back({});
  Box3 box, centre_box;
  for (uint32_t i = first; i < first + count; ++i) {
    box.extend(boxes[order_[i]].min);
    box.extend(boxes[order_[i]].max);
    centre_box.extend(centres[order_[i]]);
  }
  nodes_[node].box = box;
  const Vec3 extent = centre_box.max - centre_box.min;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  if (count <= kLeafTriangles || !(extent[axis] > 0)) {
    nodes_[node].first = first;
    nodes_[node].count = count;
    return node;
  }
  const uint32_t half = count / 2;
  const auto begin = order_.begin() + first;
  std::nth_element(begin, begin + half, begin + count, [&](uint32_t x, uint32_t y) {
    return centres[x][axis] < centres[y][axis] || (centres[x][axis] == centres[y][axis] && x < y);
  });
  const uint32_t left = build(boxes, centres, first, half);
  const uint32_t right = build(boxes, centres, first + half, count - half);
  nodes_[node].left = left;
  nodes_[node].right = right;
  return node;
}

std::vector<RayCrossing> RayCrossingIndex::crossings(Vec3 eye, Vec3 dir) const {
  std::vector<uint32_t> ids;  // from the tree; thin_ (sorted) is merged in below
  if (!nodes_.empty()) {
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& nd = nodes_[stack[--top]];
      if (!line_meets(nd.box, eye, dir)) continue;
      if (nd.count > 0) {
        ids.insert(ids.end(), order_.begin() + nd.first, order_.begin() + nd.first + nd.count);
      } else {
        assert(top + 2 <= 64);
        stack[top++] = nd.right;
        stack[top++] = nd.left;
      }
    }
  }
  std::sort(ids.begin(), ids.end());
  std::vector<RayCrossing> out;
  auto test = [&](uint32_t id) {
    const Vec3 p[3] = {corners_[3 * size_t(id)] - eye, corners_[3 * size_t(id) + 1] - eye,
                       corners_[3 * size_t(id) + 2] - eye};
    Candidate c;
    if (crossing_of(p, dir, id, c)) out.push_back(c);
  };
  size_t i = 0, j = 0;  // in increasing id, as ray_crossings
  while (i < ids.size() || j < thin_.size())
    test(j == thin_.size() || (i < ids.size() && ids[i] < thin_[j]) ? ids[i++] : thin_[j++]);
  return out;
}
}  // namespace vislib
