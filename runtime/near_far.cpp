// near_far.cpp: continuous near-far partitioning (near-far-partitioning.txt §3, Eqs. 1-5, with
// a = r2 - r) and CloVR's progressive near region (clovr-progressive-near-region.txt §3.1,
// Alg. 1 with w = (R - r)/(R - R_n)). See runtime/near_far.h for the contracts.
#include "runtime/near_far.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace pvs_runtime {

namespace {

Point3 operator+(const Point3& a, const Point3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Point3 operator-(const Point3& a, const Point3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Point3 operator*(const Point3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(const Point3& a, const Point3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
double length(const Point3& a) {
  return std::sqrt(dot(a, a));
}
Point3 normalize(const Point3& a) {
  return a * (1.0 / length(a));
}

Point3 vertex(const float* positions, uint32_t i) {
  return {double(positions[3 * size_t(i)]), double(positions[3 * size_t(i) + 1]),
          double(positions[3 * size_t(i) + 2])};
}

// The t > 0 where u + t d leaves the vertical cylinder of radius r around o; u strictly inside.
double leave_cylinder(const Point3& u, const Point3& d, const Point3& o, double r) {
  const double ux = u.x - o.x, uz = u.z - o.z;
  const double a = d.x * d.x + d.z * d.z;
  const double b = 2.0 * (ux * d.x + uz * d.z);
  const double c = ux * ux + uz * uz - r * r;  // < 0: u inside
  assert(a > 0 && c < 0);
  const double sq = std::sqrt(b * b - 4.0 * a * c);
  // The positive root, without cancellation (c < 0 makes the roots of opposite signs).
  return b >= 0 ? (2.0 * c) / (-b - sq) : (-b + sq) / (2.0 * a);
}

}  // namespace

double axis_distance(const Point3& p, const Point3& o) {
  return std::hypot(p.x - o.x, p.z - o.z);
}

Region vertex_region(double r, double r1, double r2) {
  assert(r1 >= 0 && r1 < r2);
  if (r <= r1) return Region::Near;
  if (r >= r2) return Region::Far;
  return Region::Intermediate;
}

double morph_user_weight(double r, double r1, double r2, MorphCurve curve) {
  assert(r1 >= 0 && r1 < r2);
  if (r <= r1) return 1.0;
  if (r >= r2) return 0.0;
  const double x = (r2 - r) / (r2 - r1);  // a / (r2 - r1), a = r2 - r
  switch (curve) {
    case MorphCurve::Linear:
      return x;
    case MorphCurve::Quadratic:
      return x * x;
    case MorphCurve::SCurve:
      return x < 0.5 ? 2.0 * x * x : 1.0 - 2.0 * (x - 1.0) * (x - 1.0);
  }
  return x;
}

Point3 displace_far(const Point3& p, const Point3& u, const Point3& o) {
  return u + (p - o);
}

Point3 morph_vertex(const Point3& p, const Point3& u, const Point3& o, double r1, double r2,
                    MorphCurve curve) {
  const double r = axis_distance(p, o);
  switch (vertex_region(r, r1, r2)) {
    case Region::Near:
      return p;
    case Region::Far:
      return displace_far(p, u, o);
    case Region::Intermediate:
      break;
  }
  assert(axis_distance(u, o) < r1);
  const double wu = morph_user_weight(r, r1, r2, curve), wo = 1.0 - wu;
  const Point3 up = p - u, op = p - o;
  const double lu = length(up), lo = length(op);
  const Point3 d = normalize(up * (wu / lu) + op * (wo / lo));
  const double t = lu * wu + lo * wo;
  return u + d * t;
}

NearFarPartition partition_near_far(const float* positions, size_t vertex_count,
                                    const uint32_t* indices, size_t triangle_count,
                                    const uint8_t* dynamic, const uint32_t* ids, size_t id_count,
                                    const Point3& o, double r1, double r2) {
  assert(r1 >= 0 && r1 < r2);
  NearFarPartition out;
  for (size_t k = 0; k < id_count; ++k) {
    const uint32_t t = ids[k];
    assert(t < triangle_count);
    int near = 0, far = 0, beyond = 0;  // vertices with r <= r1, r >= r2, r > r2
    for (int j = 0; j < 3; ++j) {
      const uint32_t v = indices[3 * size_t(t) + j];
      assert(v < vertex_count);
      const double r = axis_distance(vertex(positions, v), o);
      Region g = vertex_region(r, r1, r2);
      near += g == Region::Near;
      far += g == Region::Far;
      beyond += r > r2;
    }
    const bool moves = dynamic && dynamic[t];
    if (near == 3) {
      out.near_ids.push_back(t);
    } else if (far == 3) {
      (moves ? out.far_dynamic_ids : out.far_static_ids).push_back(t);
    } else {
      out.intermediate_ids.push_back(t);
    }
    const bool geometry = !(far == 3 && !moves);
    if (geometry) out.geometry_ids.push_back(t);
    if (!moves && beyond > 0) out.environment_map_ids.push_back(t);
  }
  for (auto* v : {&out.near_ids, &out.intermediate_ids, &out.far_static_ids, &out.far_dynamic_ids,
                  &out.environment_map_ids, &out.geometry_ids})
    std::sort(v->begin(), v->end());
  return out;
}

// ---- Range cube map -------------------------------------------------------------------------

CubePixel cube_pixel(const Point3& d, int size) {
  assert(size > 0 && dot(d, d) > 0);
  const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  int face;
  if (ax >= ay && ax >= az)
    face = d.x >= 0 ? 0 : 1;
  else if (ay >= az)
    face = d.y >= 0 ? 2 : 3;
  else
    face = d.z >= 0 ? 4 : 5;
  const CubeFaceAxes& a = kCubeFaceAxes[face];
  const double m = dot(d, a.f);  // > 0
  const double sc = dot(d, a.s) / m, tc = dot(d, a.t) / m;
  auto pix = [size](double u) {
    return std::clamp(int(std::floor((u + 1.0) * 0.5 * size)), 0, size - 1);
  };
  return {face, pix(sc), pix(tc)};
}

Point3 cube_pixel_direction(int face, int x, int y, int size) {
  assert(face >= 0 && face < 6 && size > 0);
  const CubeFaceAxes& a = kCubeFaceAxes[face];
  const double sc = double(2 * x + 1) / double(size) - 1.0,
               tc = double(2 * y + 1) / double(size) - 1.0;
  return a.f + a.s * sc + a.t * tc;
}

double cube_range(const RangeCubeMap& map, const Point3& d) {
  assert(map.size > 0 && map.range);
  const CubePixel p = cube_pixel(d, map.size);
  return double(map.range[(size_t(p.face) * map.size + p.y) * map.size + p.x]);
}

bool passes_range_test(const Point3& q, const Point3& u, const RangeCubeMap& map) {
  const Point3 v = q - u;
  const double r_u = length(v);
  assert(r_u > 0);
  const double r_o = cube_range(map, v * (1.0 / r_u));
  return r_u <= r_o * (1.0 + kRangeRelativeTolerance);  // r_o = +inf: nothing stationary there
}

// ---- Progressive near region ----------------------------------------------------------------

std::vector<double> equal_area_ring_radii(double ring_area, double final_radius) {
  assert(ring_area > 0 && final_radius > 0);
  const double pi = 3.14159265358979323846;
  // Rings whose outer radius falls within a relative 1e-12 of final_radius end there.
  const double rings = pi * final_radius * final_radius / ring_area;
  const size_t count = size_t(std::max(1.0, std::ceil(rings * (1.0 - 1e-12))));
  std::vector<double> radii(count);
  for (size_t k = 1; k < count; ++k) radii[k - 1] = std::sqrt(double(k) * ring_area / pi);
  radii[count - 1] = final_radius;
  return radii;
}

std::vector<double> ring_contributions(const std::vector<double>& radii,
                                       const std::vector<double>& item_radius,
                                       const std::vector<double>& item_weight) {
  assert(item_radius.size() == item_weight.size());
  std::vector<double> sum(radii.size(), 0.0);
  for (size_t i = 0; i < item_radius.size(); ++i) {
    auto it = std::upper_bound(radii.begin(), radii.end(), item_radius[i]);  // first radius > r
    if (it != radii.end()) sum[size_t(it - radii.begin())] += item_weight[i];
  }
  return sum;
}

std::vector<double> merge_rings(const std::vector<double>& radii,
                                const std::vector<double>& contribution, double min_contribution) {
  assert(radii.size() == contribution.size());
  std::vector<double> merged;
  double acc = 0;
  for (size_t k = 0; k < radii.size(); ++k) {
    acc += contribution[k];
    if (acc >= min_contribution) {
      merged.push_back(radii[k]);
      acc = 0;
    }
  }
  if (!radii.empty() && (merged.empty() || merged.back() != radii.back())) {
    if (!merged.empty())
      merged.back() = radii.back();  // the short last group joins the one before
    else
      merged.push_back(radii.back());
  }
  return merged;
}

double injection_weight(double r, double big_r, double r_n) {
  assert(r_n >= 0 && r_n < big_r);
  if (r <= r_n) return 1.0;
  if (r >= big_r) return 0.0;
  return (big_r - r) / (big_r - r_n);
}

Point3 inject_vertex(const Point3& p, const Point3& u, const Point3& o, double big_r, double r_n) {
  const double r = axis_distance(p, o);
  if (r < r_n) return p;
  assert(axis_distance(u, o) < r_n);
  const double w = injection_weight(r, big_r, r_n);
  const Point3 d = normalize(normalize(p - u) * w + normalize(p - o) * (1.0 - w));
  return u + d * leave_cylinder(u, d, o, r);
}

ProgressivePartition partition_progressive(const float* positions, size_t vertex_count,
                                           const uint32_t* indices, size_t triangle_count,
                                           const uint32_t* triangle_object, size_t object_count,
                                           const uint32_t* ids, size_t id_count, const Point3& o,
                                           double big_r) {
  std::vector<uint8_t> near_object(object_count, 0);
  for (size_t t = 0; t < triangle_count; ++t) {
    assert(triangle_object[t] < object_count);
    for (int j = 0; j < 3; ++j) {
      const uint32_t v = indices[3 * t + j];
      assert(v < vertex_count);
      if (axis_distance(vertex(positions, v), o) < big_r) near_object[triangle_object[t]] = 1;
    }
  }
  ProgressivePartition out;
  for (size_t k = 0; k < id_count; ++k) {
    assert(ids[k] < triangle_count);
    (near_object[triangle_object[ids[k]]] ? out.near_ids : out.environment_map_ids)
        .push_back(ids[k]);
  }
  std::sort(out.near_ids.begin(), out.near_ids.end());
  std::sort(out.environment_map_ids.begin(), out.environment_map_ids.end());
  return out;
}

}  // namespace pvs_runtime
