// near_far_render.cpp: the CPU reference renderer of the near-far frame (near-far paper §3, Eq. 1;
// CloVR §3, Alg. 1) and CloVR's OVC/OFC metrics. See near_far_render.h.
#include "vislib/near_far_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cassert>
#include <cmath>
#include <limits>

#include "runtime/near_far.h"
#include "vislib/cubemap.h"

namespace vislib {

namespace {

namespace nf = pvs_runtime;

nf::Point3 to_point(Vec3 v) { return {v.x, v.y, v.z}; }
Vec3 to_vec(nf::Point3 p) { return {p.x, p.y, p.z}; }

uint8_t to_byte(double v) {
  double s = std::round(v * 255.0);
  return uint8_t(s < 0 ? 0 : (s > 255 ? 255 : s));
}

// render_frame's shading of triangle `tri` seen along `dir`.
void shade(const Scene& scene, uint32_t tri, Vec3 dir, uint8_t* out) {
  const auto c = scene.corners(tri, 0);
  const Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
  const double nl = length(normal), len = length(dir);
  const double lambert = nl > 0 ? std::fabs(dot(normal, dir)) / (nl * len) : 0.0;
  const double s = kRenderAmbient + (1.0 - kRenderAmbient) * std::fmin(lambert, 1.0);
  const auto albedo = object_colour(scene.triangle_object[tri]);
  for (int k = 0; k < 3; ++k) out[k] = to_byte(double(albedo[size_t(k)]) / 255.0 * s);
}

// Renders the triangles `ids` of `scene` with vertex v displaced to displace(v) (one new vertex
// per triangle corner), from `camera`, through render_frame; tri ids mapped back to scene ids.
template <class Displace>
Frame render_displaced(const Scene& scene, const std::vector<uint32_t>& ids, const Camera& camera,
                       Displace displace) {
  Scene sub;
  sub.positions.resize(1);
  sub.objects = scene.objects;
  sub.positions[0].reserve(3 * ids.size());
  for (uint32_t t : ids) {
    const auto& tri = scene.triangles[t];
    const uint32_t base = uint32_t(sub.positions[0].size());
    for (int k = 0; k < 3; ++k) sub.positions[0].push_back(displace(tri[size_t(k)]));
    sub.triangles.push_back({base, base + 1, base + 2});
    sub.triangle_object.push_back(scene.triangle_object[t]);
  }
  Frame f;
  if (ids.empty()) {  // nothing drawn from geometry: every pixel misses
    f.width = camera.width;
    f.height = camera.height;
    f.rgb.assign(3 * f.pixel_count(), 0);
    f.depth.assign(f.pixel_count(), std::numeric_limits<float>::infinity());
    f.tri.assign(f.pixel_count(), kNoHit);
    return f;
  }
  EmbreeScene rt(sub, 0.0, camera.eye);
  f = render_frame(sub, rt, camera);
  for (auto& t : f.tri)
    if (t != kNoHit) t = ids[t];
  return f;
}

// Fills the pixels of `geometry` that hit nothing from `env` (see the header).
void compose(Frame& geometry, const EnvironmentMap& env, const Camera& camera, EnvironmentLookup lookup,
             double r2) {
  const Vec3 o = env.centre, u = camera.eye;
  tbb::parallel_for(tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < camera.width; ++x) {
        const size_t p = size_t(y) * size_t(camera.width) + size_t(x);
        uint8_t* out = &geometry.rgb[3 * p];
        if (geometry.tri[p] != kNoHit) continue;
        Vec3 d = camera_ray(camera, x, y);
        d = d * (1.0 / length(d));
        Vec3 look = d;
        if (lookup == EnvironmentLookup::CylinderR2) {
          // U + t d leaves the cylinder of radius r2 about O's axis (U is inside: one root t > 0).
          const double ux = u.x - o.x, uz = u.z - o.z;
          const double a = d.x * d.x + d.z * d.z, b = 2 * (ux * d.x + uz * d.z), c = ux * ux + uz * uz - r2 * r2;
          if (a > 0) {
            const double t = (-b + std::sqrt(std::fmax(0.0, b * b - 4 * a * c))) / (2 * a);
            look = u + d * t - o;
          }
        }
        const nf::CubePixel cp = nf::cube_pixel(to_point(look), env.size);
        const size_t q = (size_t(cp.face) * size_t(env.size) + size_t(cp.y)) * size_t(env.size) + size_t(cp.x);
        for (int k = 0; k < 3; ++k) out[k] = env.rgb[3 * q + size_t(k)];
        geometry.tri[p] = env.tri[q];
        if (env.tri[q] == kNoHit) continue;
        const double range = env.range[q];
        if (lookup == EnvironmentLookup::EyeDirection) {
          geometry.depth[p] = float(range);
        } else {
          const double l = length(look);
          geometry.depth[p] = float(length(o + look * (range / l) - u));
        }
      }
  });
}

}  // namespace

EnvironmentMap render_environment_map(const Scene& scene, const EmbreeScene& rt, Vec3 centre, int size,
                                      const uint8_t* allowed) {
  assert(size >= 1);
  EnvironmentMap env;
  env.size = size;
  env.centre = centre;
  const size_t n = size_t(kCubeFaces) * size_t(size) * size_t(size);
  env.rgb.assign(3 * n, 0);
  env.range.assign(n, std::numeric_limits<float>::infinity());
  env.tri.assign(n, kNoHit);
  tbb::parallel_for(tbb::blocked_range<int>(0, kCubeFaces * size), [&](const tbb::blocked_range<int>& rows) {
    std::vector<Vec3> dirs(static_cast<size_t>(size));
    std::vector<Hit> hits(static_cast<size_t>(size));
    for (int row = rows.begin(); row != rows.end(); ++row) {
      const int face = row / size, y = row % size;
      const FaceAxes axes = face_axes_local(face);
      for (int x = 0; x < size; ++x) dirs[size_t(x)] = pixel_direction(axes, x, y, size);
      rt.first_hits_among(centre, dirs.data(), size_t(size), 0.0, allowed, hits.data());
      for (int x = 0; x < size; ++x) {
        const size_t p = size_t(row) * size_t(size) + size_t(x);
        const Hit& h = hits[size_t(x)];
        uint8_t* out = &env.rgb[3 * p];
        if (h.tri == kNoHit) {
          for (int k = 0; k < 3; ++k) out[k] = kRenderBackground[size_t(k)];
          continue;
        }
        env.tri[p] = h.tri;
        env.range[p] = float(h.lambda * length(dirs[size_t(x)]));
        shade(scene, h.tri, dirs[size_t(x)], out);
      }
    }
  });
  return env;
}

Frame render_near_far(const Scene& scene, const EmbreeScene& rt, const std::vector<uint32_t>& visible,
                      const Camera& camera, const NearFarSettings& s, RegionCounts* counts) {
  assert(s.r1 >= 0 && s.r1 < s.r2 && s.env_size >= 1);
  const nf::Point3 o = to_point(s.centre), u = to_point(camera.eye);
  assert(nf::axis_distance(u, o) < s.r1);
  const auto& pos = scene.positions[0];
  std::vector<uint32_t> geometry_ids;
  std::vector<uint8_t> env_mask(scene.triangle_count(), 0);
  std::vector<uint8_t> is_intermediate(scene.triangle_count(), 0);
  RegionCounts rc;
  for (uint32_t t : visible) {
    bool all_near = true, all_far = true, any_far = false;
    for (uint32_t v : scene.triangles[t]) {
      const nf::Region r = nf::vertex_region(nf::axis_distance(to_point(pos[v]), o), s.r1, s.r2);
      all_near = all_near && r == nf::Region::Near;
      all_far = all_far && r == nf::Region::Far;
      any_far = any_far || r == nf::Region::Far;
    }
    if (all_near) {
      ++rc.near;
      geometry_ids.push_back(t);
    } else if (all_far) {
      ++rc.far;
    } else {
      ++rc.intermediate;
      geometry_ids.push_back(t);
      is_intermediate[t] = 1;
    }
    if (any_far) {
      env_mask[t] = 1;
      ++rc.env_map;
    }
  }
  if (counts) *counts = rc;
  Frame f = render_displaced(scene, geometry_ids, camera, [&](uint32_t v) {
    if (!s.morph) return pos[v];
    return to_vec(nf::morph_vertex(to_point(pos[v]), u, o, s.r1, s.r2));
  });
  const EnvironmentMap env = render_environment_map(scene, rt, s.centre, s.env_size, env_mask.data());
  compose(f, env, camera, s.lookup, s.r2);
  return f;
}

Frame render_progressive(const Scene& scene, const EmbreeScene& rt, const std::vector<uint32_t>& visible,
                         const Camera& camera, Vec3 centre, double big_r, double near_fraction, int env_size) {
  assert(near_fraction > 0 && near_fraction < 1 && big_r > 0);
  const nf::Point3 o = to_point(centre), u = to_point(camera.eye);
  const double r_n = near_fraction * big_r;
  assert(nf::axis_distance(u, o) < r_n);
  const auto& pos = scene.positions[0];
  // An object is near when one of its visible vertices is within big_r of the axis.
  std::vector<uint8_t> near_object(scene.objects.size(), 0);
  for (uint32_t t : visible)
    for (uint32_t v : scene.triangles[t])
      if (nf::axis_distance(to_point(pos[v]), o) < big_r) near_object[scene.triangle_object[t]] = 1;
  std::vector<uint32_t> near_ids;
  std::vector<uint8_t> env_mask(scene.triangle_count(), 0);
  for (uint32_t t : visible) {
    if (near_object[scene.triangle_object[t]])
      near_ids.push_back(t);
    else
      env_mask[t] = 1;
  }
  Frame f = render_displaced(scene, near_ids, camera, [&](uint32_t v) {
    return to_vec(nf::inject_vertex(to_point(pos[v]), u, o, big_r, r_n));
  });
  const EnvironmentMap env = render_environment_map(scene, rt, centre, env_size, env_mask.data());
  compose(f, env, camera, EnvironmentLookup::EyeDirection, big_r);
  return f;
}

ObjectCompletion object_completion(const Scene& scene, const Frame& truth, const Frame& test) {
  assert(truth.pixel_count() == test.pixel_count());
  const size_t n_obj = scene.objects.size();
  std::vector<size_t> truth_pixels(n_obj, 0), covered(n_obj, 0);
  std::vector<uint8_t> in_test(n_obj, 0);
  for (size_t p = 0; p < truth.pixel_count(); ++p) {
    const uint32_t a = truth.tri[p] == kNoHit ? kNoHit : scene.triangle_object[truth.tri[p]];
    const uint32_t b = test.tri[p] == kNoHit ? kNoHit : scene.triangle_object[test.tri[p]];
    if (b != kNoHit) in_test[b] = 1;
    if (a == kNoHit) continue;
    ++truth_pixels[a];
    if (a == b) ++covered[a];
  }
  ObjectCompletion c;
  size_t seen = 0;
  double ofc_sum = 0;
  for (size_t o = 0; o < n_obj; ++o) {
    if (truth_pixels[o] == 0) continue;
    ++c.objects;
    if (in_test[o]) ++seen;
    ofc_sum += double(covered[o]) / double(truth_pixels[o]);
  }
  if (c.objects > 0) {
    c.ovc = double(seen) / double(c.objects);
    c.ofc = ofc_sum / double(c.objects);
  }
  return c;
}

}  // namespace vislib
