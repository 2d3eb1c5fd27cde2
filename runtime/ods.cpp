// ods.cpp: omnidirectional stereo panoramas (omnidirectional-stereo.txt: Eq. 1-6, Alg. 1, §3.2),
// with the paper's errors corrected as runtime/ods.h lists. See runtime/ods.h for the contracts.
#include "runtime/ods.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <map>

namespace pvs_runtime {

namespace {

constexpr double kDeg = kOdsPi / 180.0;

Point3 sub(const Point3& a, const Point3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Point3 add_scaled(const Point3& a, const Point3& d, double s) {
  return {a.x + d.x * s, a.y + d.y * s, a.z + d.z * s};
}

// right(lon) = normalize(direction(lon, 0) x up) = (-cos lon, 0, -sin lon).
Point3 right_of(double lon) {
  return {-std::cos(lon), 0.0, -std::sin(lon)};
}

double side_factor(double inclination_deg, const PoleMergeSide& s) {
  assert(s.end_deg >= 0 && s.end_deg <= s.start_deg && s.start_deg <= 90 && s.exponent > 0);
  if (s.start_deg == s.end_deg) return 1.0;  // no merging (the paper's 0/0 at start = end)
  const double merge_start = 90.0 - s.start_deg, merge_end = 90.0 - s.end_deg;
  const double x =
      std::clamp((inclination_deg - merge_start) / (merge_end - merge_start), 0.0, 1.0);
  return std::pow(1.0 - x, s.exponent);
}

const PoleMergeSide& side_for(double lat, const PoleMerge& m) {
  return lat >= 0 ? m.top : m.bottom;
}

}  // namespace

double pole_merge_factor(double lat, const PoleMerge& merge) {
  const double incl = std::fabs(lat) / kDeg;
  return side_factor(incl, side_for(lat, merge));
}

double wrap_longitude(double lon) {
  double w = std::remainder(lon, 2.0 * kOdsPi);  // [-pi, pi]
  if (w <= -kOdsPi) w += 2.0 * kOdsPi;
  return w;
}

LonLat direction_lonlat(const Point3& d) {
  LonLat ll;
  const double horizontal = std::hypot(d.x, d.z);
  ll.lon = horizontal > 0 ? wrap_longitude(-std::atan2(d.x, d.z)) : 0.0;
  ll.lat = std::atan2(d.y, horizontal);  // = asin(d.y/|d|), well conditioned at the poles
  return ll;
}

Point3 lonlat_direction(const LonLat& ll) {
  const double c = std::cos(ll.lat);
  return {-std::sin(ll.lon) * c, std::sin(ll.lat), std::cos(ll.lon) * c};
}

std::array<double, 2> lonlat_to_pixel(const LonLat& ll, int width, int height) {
  return {(ll.lon + kOdsPi) / (2.0 * kOdsPi) * width, (kOdsPi / 2 - ll.lat) / kOdsPi * height};
}

LonLat pixel_to_lonlat(double u, double v, int width, int height) {
  return {-kOdsPi + 2.0 * kOdsPi * u / width, kOdsPi / 2 - kOdsPi * v / height};
}

Ray ods_ray(const LonLat& ll, const Point3& centre, double ipd, Eye eye, const PoleMerge& merge) {
  assert(ipd >= 0);
  const double h = 0.5 * ipd * pole_merge_factor(ll.lat, merge);
  Ray r;
  r.origin = add_scaled(centre, right_of(ll.lon), double(int(eye)) * h);
  r.direction = lonlat_direction(ll);
  return r;
}

Ray ods_pixel_ray(int x, int y, int width, int height, const Point3& centre, double ipd, Eye eye,
                  const PoleMerge& merge) {
  assert(x >= 0 && x < width && y >= 0 && y < height);
  return ods_ray(pixel_to_lonlat(x + 0.5, y + 0.5, width, height), centre, ipd, eye, merge);
}

OdsProjection ods_project_exact(const Point3& p, const Point3& centre, double ipd, Eye eye,
                                const PoleMerge& merge) {
  assert(ipd >= 0);
  OdsProjection out;
  const Point3 d = sub(p, centre);
  const double rh = std::hypot(d.x, d.z), dy = d.y, half = 0.5 * ipd;
  if (rh == 0 && dy == 0) return out;
  auto h_at = [&](double lat) { return half * pole_merge_factor(lat, merge); };
  auto lat_for = [&](double h) {
    const double q = rh * rh - h * h;
    return std::atan2(dy, q > 0 ? std::sqrt(q) : 0.0);
  };
  double lat = 0, h = 0;
  const PoleMergeSide& side = side_for(dy, merge);
  if (dy == 0) {
    lat = 0;
    h = h_at(0);
  } else if (half == 0 || side.start_deg == side.end_deg) {
    h = half;  // constant over this hemisphere (pole_merge_factor is 1 there)
    lat = lat_for(h);
  } else {
    // Fixed point of lat = g(lat) = atan2(dy, sqrt(rh^2 - h(lat)^2)); |g| falls as |lat| grows.
    lat = std::atan2(dy, rh);
    bool converged = false;
    for (int k = 0; k < 32 && !converged; ++k) {
      const double next = lat_for(h_at(lat));
      ++out.iterations;
      converged = std::fabs(next - lat) <= 1e-15;
      lat = next;
    }
    if (!converged) {
      // Bisection on t = |lat| for F(t) = t - |g(t)|, increasing; F(lo) <= 0 <= F(hi).
      const double sgn = dy > 0 ? 1.0 : -1.0;
      double lo = std::fabs(std::atan2(dy, rh)), hi = kOdsPi / 2;
      for (int k = 0; k < 200 && hi - lo > 1e-16; ++k) {
        const double mid = 0.5 * (lo + hi);
        const double f = mid - std::fabs(lat_for(h_at(sgn * mid)));
        (f < 0 ? lo : hi) = mid;
        ++out.iterations;
      }
      lat = sgn * hi;
    }
    h = h_at(lat);
  }
  out.h = h;
  if (rh == 0) {
    if (h != 0) return out;
    out.visible = true;
    out.ll = {0.0, dy > 0 ? kOdsPi / 2 : -kOdsPi / 2};
    out.range = std::fabs(dy);
    return out;
  }
  if (!(h < rh)) return out;
  const double lon_c = -std::atan2(d.x, d.z);
  out.visible = true;
  out.ll.lon = wrap_longitude(lon_c - double(int(eye)) * std::asin(h / rh));
  out.ll.lat = lat;
  out.range = std::sqrt(rh * rh - h * h + dy * dy);
  return out;
}

OdsProjection ods_project_paper(const Point3& p, const Point3& centre, double ipd, Eye eye,
                                const PoleMerge& merge) {
  assert(ipd >= 0);
  OdsProjection out;
  const Point3 forward = sub(p, centre);  // Eq. 1 from the centre camera
  const LonLat centre_ll = direction_lonlat(forward);
  out.h = 0.5 * ipd * pole_merge_factor(centre_ll.lat, merge);  // Eq. 6
  // Eq. 5: right = normalize(forward x up), up = (0, 1, 0); forward x up = (-f.z, 0, f.x).
  const double len = std::hypot(forward.x, forward.z);
  Point3 camera = centre;
  if (len > 0)
    camera = add_scaled(centre, Point3{-forward.z / len, 0.0, forward.x / len},
                        double(int(eye)) * out.h);
  const Point3 dir = sub(p, camera);  // Eq. 1 from the offset camera
  out.visible = true;
  out.ll = direction_lonlat(dir);  // Eq. 2 (all quadrants) and Eq. 3
  out.range = std::sqrt(dir.x * dir.x + dir.y * dir.y + dir.z * dir.z);
  return out;
}

double lon_dist_deg(double a_deg, double b_deg) {
  const double d = std::fabs(std::remainder(a_deg - b_deg, 360.0));
  return std::min(d, 180.0);
}

double edge_outer_level(const LonLat& a, const LonLat& b, const LonLat& mid) {
  const double alon = a.lon / kDeg, blon = b.lon / kDeg;
  const double alat = a.lat / kDeg, blat = b.lat / kDeg, mlat = mid.lat / kDeg;
  const double dlon = lon_dist_deg(alon, blon);  // line 8
  const double dlat =
      std::max({std::fabs(alat - blat), std::fabs(alat - mlat), std::fabs(blat - mlat)});  // 9
  const double max_lat = std::max({std::fabs(alat), std::fabs(blat), std::fabs(mlat)});  // line 10
  const double edge = std::hypot(dlon, 0.5 * dlat);                                      // line 11
  const double d = std::max(0.125 * edge, 1.0);                                          // line 12
  const double pole_multiplier = std::max((2.8284 / 90.0) * max_lat, 1.0);               // line 13
  return std::min(pole_multiplier * d, 64.0);                                            // line 14
}

TessLevels tessellation_levels(const std::array<LonLat, 3>& projected,
                               const std::array<LonLat, 3>& mid_projected) {
  TessLevels t;
  for (int i = 0; i < 3; ++i)  // the paper's "0 to 3" over 3 vertices: i = 0, 1, 2
    t.outer[i] = edge_outer_level(projected[(i + 1) % 3], projected[(i + 2) % 3], mid_projected[i]);
  const double max_tess = std::max({t.outer[0], t.outer[1], t.outer[2]});  // line 15
  t.inner = std::max(max_tess - 2.0, std::min(max_tess, 3.0));             // line 16
  return t;
}

double inner_level_eq4(double max_tess) {
  if (max_tess > 5) return max_tess - 2;
  if (max_tess >= 3) return 3;
  return max_tess;
}

Tessellation tessellate_triangle(const std::array<int, 3>& outer, int inner) {
  assert(outer[0] >= 1 && outer[0] <= 64 && outer[1] >= 1 && outer[1] <= 64 && outer[2] >= 1 &&
         outer[2] <= 64);
  assert(inner >= 1 && inner <= 64);
  const int n = std::max({outer[0], outer[1], outer[2], inner});
  Tessellation t;
  // Point ids: grid points keyed by their snapped position, so points that snap together merge.
  // Key: (edge or -1, k, o) for boundary points, (-1, i, j) for interior points.
  std::map<std::array<int, 4>, uint32_t> ids;
  auto point = [&](int i, int j) -> uint32_t {
    std::array<int, 4> key;
    std::array<double, 3> w;
    if (i == 0 && j == 0) {
      key = {3, 0, 0, 0}, w = {1, 0, 0};
    } else if (i == n) {
      key = {3, 1, 0, 0}, w = {0, 1, 0};
    } else if (j == n) {
      key = {3, 2, 0, 0}, w = {0, 0, 1};
    } else if (i + j == n) {  // edge opposite vertex 0: v1 -> v2, parameter w2
      const int o = outer[0], k = int(std::lround(double(j) * o / n));
      key = {0, k, o, 0}, w = {0, double(o - k) / o, double(k) / o};
    } else if (i == 0) {  // edge opposite vertex 1: v0 -> v2, parameter w2
      const int o = outer[1], k = int(std::lround(double(j) * o / n));
      key = {1, k, o, 0}, w = {double(o - k) / o, 0, double(k) / o};
    } else if (j == 0) {  // edge opposite vertex 2: v0 -> v1, parameter w1
      const int o = outer[2], k = int(std::lround(double(i) * o / n));
      key = {2, k, o, 0}, w = {double(o - k) / o, double(k) / o, 0};
    } else {
      key = {4, i, j, 0}, w = {double(n - i - j) / n, double(i) / n, double(j) / n};
    }
    // A snapped edge point at k = 0 or k = o is a corner. Edge 0 runs v1 -> v2, edge 1 v0 -> v2,
    // edge 2 v0 -> v1.
    if (key[0] <= 2 && (key[1] == 0 || key[1] == key[2])) {
      static constexpr int kFrom[3] = {1, 0, 0}, kTo[3] = {2, 2, 1};
      const int c = key[1] == 0 ? kFrom[key[0]] : kTo[key[0]];
      key = {3, c, 0, 0};
      w = {0, 0, 0};
      w[c] = 1;
    }
    auto [it, fresh] = ids.emplace(key, uint32_t(t.points.size()));
    if (fresh) t.points.push_back(w);
    return it->second;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i + j < n; ++i) {
      std::array<uint32_t, 3> up{point(i, j), point(i + 1, j), point(i, j + 1)};
      if (up[0] != up[1] && up[1] != up[2] && up[0] != up[2]) t.triangles.push_back(up);
      if (i + j < n - 1) {
        std::array<uint32_t, 3> down{point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)};
        if (down[0] != down[1] && down[1] != down[2] && down[0] != down[2])
          t.triangles.push_back(down);
      }
    }
  return t;
}

AxisCrossing axis_crossing(const std::array<Point3, 3>& v, const Point3& centre) {
  AxisCrossing a;
  // Barycentric weights of (centre.x, centre.z) in the x-z triangle, by signed areas.
  auto area = [](double ax, double az, double bx, double bz, double cx, double cz) {
    return (bx - ax) * (cz - az) - (bz - az) * (cx - ax);
  };
  const double total = area(v[0].x, v[0].z, v[1].x, v[1].z, v[2].x, v[2].z);
  if (total == 0) return a;
  const double px = centre.x, pz = centre.z;
  const double w0 = area(px, pz, v[1].x, v[1].z, v[2].x, v[2].z) / total;
  const double w1 = area(v[0].x, v[0].z, px, pz, v[2].x, v[2].z) / total;
  const double w2 = area(v[0].x, v[0].z, v[1].x, v[1].z, px, pz) / total;
  if (w0 < 0 || w1 < 0 || w2 < 0) return a;
  a.crosses = true;
  a.bary = {w0, w1, w2};
  a.point = {centre.x, w0 * v[0].y + w1 * v[1].y + w2 * v[2].y, centre.z};
  a.pole = a.point.y >= centre.y ? 1 : -1;
  return a;
}

std::vector<ProjTriangle> split_seam_pole(const std::array<ProjVertex, 3>& v, int pole,
                                          double pole_range) {
  std::vector<ProjTriangle> out;
  auto emit = [&](ProjTriangle t) {
    const double lo = std::min({t.v[0].lon, t.v[1].lon, t.v[2].lon});
    const double hi = std::max({t.v[0].lon, t.v[1].lon, t.v[2].lon});
    out.push_back(t);
    if (lo < -kOdsPi || hi > kOdsPi) {
      const double shift = lo < -kOdsPi ? 2 * kOdsPi : -2 * kOdsPi;
      for (ProjVertex& p : t.v) p.lon += shift;
      out.push_back(t);
    }
  };
  // b placed relative to a: a's centre longitude, the short way to b's, then b's eye offset.
  auto unwrap_from = [](const ProjVertex& a, ProjVertex b) {
    const double a_centre = a.lon - wrap_longitude(a.lon - a.lon_centre);
    b.lon = a_centre + wrap_longitude(b.lon_centre - a.lon_centre) +
            wrap_longitude(b.lon - b.lon_centre);
    return b;
  };
  if (pole == 0) {
    ProjTriangle t{v};
    for (int i = 1; i < 3; ++i) t.v[size_t(i)] = unwrap_from(v[0], v[size_t(i)]);
    emit(t);
    return out;
  }
  const double pole_lat = pole > 0 ? kOdsPi / 2 : -kOdsPi / 2;
  for (int e = 0; e < 3; ++e) {
    const ProjVertex a = v[size_t(e)], b = unwrap_from(a, v[size_t((e + 1) % 3)]);
    const ProjVertex pa{a.lon, pole_lat, pole_range, a.lon_centre},
        pb{b.lon, pole_lat, pole_range, b.lon_centre};
    emit(ProjTriangle{{a, b, pb}});
    emit(ProjTriangle{{a, pb, pa}});
  }
  return out;
}

bool disc_inside_box(const Point3& c, double radius, const double lo[3], const double hi[3]) {
  assert(radius >= 0);
  return c.y >= lo[1] && c.y <= hi[1] && c.x - radius >= lo[0] && c.x + radius <= hi[0] &&
         c.z - radius >= lo[2] && c.z + radius <= hi[2];
}

bool disc_touches_box(const Point3& c, double radius, const double lo[3], const double hi[3]) {
  assert(radius >= 0);
  if (c.y < lo[1] || c.y > hi[1]) return false;
  const double dx = std::max({lo[0] - c.x, 0.0, c.x - hi[0]});
  const double dz = std::max({lo[2] - c.z, 0.0, c.z - hi[2]});
  return dx * dx + dz * dz <= radius * radius;
}

}  // namespace pvs_runtime
