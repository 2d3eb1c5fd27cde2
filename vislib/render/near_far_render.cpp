// near_far_render.cpp: the CPU reference renderer of the near-far frame (near-far paper §3, Eq. 1;
// CloVR §3, Alg. 1) and CloVR's OVC/OFC metrics. See near_far_render.h.
#include "vislib/render/near_far_render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cassert>
#include <cmath>
#include <limits>

#include "runtime/near_far.h"
#include "vislib/base/cubemap.h"

namespace vislib {

namespace {
// State 0's vertex positions, or none for a scene without triangles (a sphere scene has no
// positions at all: `pvs view` of a sphere bake must not index them).
const std::vector<Vec3>& rest_positions(const Scene& scene) {
  static const std::vector<Vec3> none;
  return scene.positions.empty() ? none : scene.positions[0];
}
}  // namespace

namespace {

namespace nf = pvs_runtime;

nf::Point3 to_point(Vec3 v) {
  return {v.x, v.y, v.z};
}
Vec3 to_vec(nf::Point3 p) {
  return {p.x, p.y, p.z};
}

const Vec3 kNanPoint{std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::quiet_NaN()};

// Renders the triangles `ids` of `scene` with vertex v displaced to displace(v) (one new vertex
// per triangle corner), from `camera`, through render_frame; tri ids mapped back to scene ids.
// If `original` is given, it receives per pixel the hit carried back to the undisplaced triangle
// (same barycentric coordinates on the rest-pose corners), NaN where nothing is hit.
template <class Displace>
Frame render_displaced(const Scene& scene, const std::vector<uint32_t>& ids, const Camera& camera,
                       Displace displace, std::vector<Vec3>* original = nullptr) {
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
    if (original) original->assign(f.pixel_count(), kNanPoint);
    return f;
  }
  EmbreeScene rt(sub, 0.0, camera.eye);
  f = render_frame(sub, rt, camera);
  if (original) {
    original->assign(f.pixel_count(), kNanPoint);
    const auto& rest = scene.positions[0];
    tbb::parallel_for(
        tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
          for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < camera.width; ++x) {
              const size_t p = size_t(y) * size_t(camera.width) + size_t(x);
              const uint32_t k = f.tri[p];
              if (k == kNoHit) continue;
              const Vec3 d = camera_ray(camera, x, y);
              const Vec3 hit = camera.eye + d * (double(f.depth[p]) / length(d));
              const Vec3 a = sub.positions[0][3 * size_t(k)],
                         b = sub.positions[0][3 * size_t(k) + 1],
                         c = sub.positions[0][3 * size_t(k) + 2];
              const Vec3 e0 = b - a, e1 = c - a, e2 = hit - a;
              const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1);
              const double d20 = dot(e2, e0), d21 = dot(e2, e1), den = d00 * d11 - d01 * d01;
              const auto& t = scene.triangles[ids[k]];
              if (!(den > 0)) {
                (*original)[p] = rest[t[0]];
                continue;
              }
              const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
              (*original)[p] = rest[t[0]] * (1 - v - w) + rest[t[1]] * v + rest[t[2]] * w;
            }
        });
  }
  for (auto& t : f.tri)
    if (t != kNoHit) t = ids[t];
  return f;
}

// Fills the pixels of `geometry` that hit nothing from `env` (see the header); if `sources` is
// given, marks them EnvironmentMap with the point the map shows along the lookup direction.
void compose(Frame& geometry, const EnvironmentMap& env, const Camera& camera,
             EnvironmentLookup lookup, double r2, PixelSources* sources = nullptr) {
  const Vec3 o = env.centre, u = camera.eye;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y != rows.end(); ++y)
          for (int x = 0; x < camera.width; ++x) {
            const size_t p = size_t(y) * size_t(camera.width) + size_t(x);
            uint8_t* out = &geometry.rgb[3 * p];
            if (geometry.tri[p] != kNoHit) continue;
            Vec3 d = camera_ray(camera, x, y);
            d = d * (1.0 / length(d));
            Vec3 look = d;
            if (lookup == EnvironmentLookup::CylinderR2) {
              // U + t d leaves the cylinder of radius r2 about O's axis (U is inside: one root t >
              // 0).
              const double ux = u.x - o.x, uz = u.z - o.z;
              const double a = d.x * d.x + d.z * d.z, b = 2 * (ux * d.x + uz * d.z),
                           c = ux * ux + uz * uz - r2 * r2;
              if (a > 0) {
                const double t = (-b + std::sqrt(std::fmax(0.0, b * b - 4 * a * c))) / (2 * a);
                look = u + d * t - o;
              }
            }
            const nf::CubePixel cp = nf::cube_pixel(to_point(look), env.size);
            const size_t q =
                (size_t(cp.face) * size_t(env.size) + size_t(cp.y)) * size_t(env.size) +
                size_t(cp.x);
            for (int k = 0; k < 3; ++k) out[k] = env.rgb[3 * q + size_t(k)];
            geometry.tri[p] = env.tri[q];
            if (env.tri[q] == kNoHit) continue;
            const double range = env.range[q];
            if (sources) {
              sources->source[p] = PixelSource::EnvironmentMap;
              sources->point[p] = o + look * (range / length(look));
            }
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

EnvironmentMap render_environment_map(const Scene& scene, const EmbreeScene& rt, Vec3 centre,
                                      int size, const uint8_t* allowed) {
  assert(size >= 1);
  EnvironmentMap env;
  env.size = size;
  env.centre = centre;
  const size_t n = size_t(kCubeFaces) * size_t(size) * size_t(size);
  env.rgb.assign(3 * n, 0);
  env.range.assign(n, std::numeric_limits<float>::infinity());
  env.tri.assign(n, kNoHit);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, kCubeFaces * size), [&](const tbb::blocked_range<int>& rows) {
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
            const auto c = shade_triangle(scene, h.tri, dirs[size_t(x)]);
            out[0] = c[0], out[1] = c[1], out[2] = c[2];
          }
        }
      });
  return env;
}

Scene scene_at(const Scene& scene, double tau) {
  Scene out;
  out.triangles = scene.triangles;
  out.triangle_object = scene.triangle_object;
  out.objects = scene.objects;
  out.sphere_radius = scene.sphere_radius;
  out.sphere_object = scene.sphere_object;
  if (!scene.positions.empty()) {
    out.positions.resize(1);
    out.positions[0].resize(scene.vertex_count());
    for (uint32_t v = 0; v < scene.vertex_count(); ++v)
      out.positions[0][v] = scene.position_at(v, tau);
  }
  if (!scene.sphere_centers.empty()) {
    out.sphere_centers.resize(1);
    out.sphere_centers[0].resize(scene.sphere_count());
    for (uint32_t k = 0; k < scene.sphere_count(); ++k)
      out.sphere_centers[0][k] = scene.sphere_center_at(k, tau);
  }
  return out;
}

std::vector<uint8_t> moving_triangles(const Scene& scene) {
  std::vector<uint8_t> moves(scene.triangle_count(), 0);
  for (size_t k = 1; k < scene.positions.size(); ++k)
    for (uint32_t t = 0; t < scene.triangle_count(); ++t)
      for (uint32_t v : scene.triangles[t])
        if (!(scene.positions[k][v] == scene.positions[0][v])) moves[t] = 1;
  return moves;
}

Frame render_near_far(const Scene& scene, const EmbreeScene& rt,
                      const std::vector<uint32_t>& visible, const Camera& camera,
                      const NearFarSettings& s, RegionCounts* counts, PixelSources* sources) {
  assert(s.r1 >= 0 && s.r1 < s.r2 && s.env_size >= 1);
  const nf::Point3 o = to_point(s.centre), u = to_point(camera.eye);
  assert(nf::axis_distance(u, o) < s.r1);
  const auto& pos = rest_positions(scene);
  std::vector<float> pos_f(3 * pos.size());
  for (size_t v = 0; v < pos.size(); ++v) {
    pos_f[3 * v] = float(pos[v].x), pos_f[3 * v + 1] = float(pos[v].y),
              pos_f[3 * v + 2] = float(pos[v].z);
  }
  const nf::NearFarPartition part = nf::partition_near_far(
      pos_f.data(), pos.size(), scene.triangles.empty() ? nullptr : scene.triangles[0].data(),
      scene.triangle_count(), s.dynamic, visible.data(), visible.size(), o, s.r1, s.r2);
  RegionCounts rc;
  rc.near = part.near_ids.size();
  rc.intermediate = part.intermediate_ids.size();
  rc.far = part.far_static_ids.size() + part.far_dynamic_ids.size();
  rc.far_dynamic = part.far_dynamic_ids.size();
  rc.env_map = part.environment_map_ids.size();
  // Drawn from geometry with the morph: near and intermediate (geometry_ids minus the dynamic far).
  std::vector<uint32_t> geometry_ids;
  {
    const std::vector<uint8_t> far_dyn =
        triangle_mask(scene.triangle_count(), part.far_dynamic_ids);
    for (uint32_t t : part.geometry_ids)
      if (!far_dyn[t]) geometry_ids.push_back(t);
  }
  if (sources) {
    sources->source.assign(size_t(camera.width) * size_t(camera.height), PixelSource::None);
    sources->point.assign(sources->source.size(), kNanPoint);
  }
  Frame f = render_displaced(
      scene, geometry_ids, camera,
      [&](uint32_t v) {
        if (!s.morph) return pos[v];
        return to_vec(nf::morph_vertex(to_point(pos[v]), u, o, s.r1, s.r2));
      },
      sources ? &sources->point : nullptr);
  if (sources) {
    const std::vector<uint8_t> intermediate =
        triangle_mask(scene.triangle_count(), part.intermediate_ids);
    for (size_t p = 0; p < f.pixel_count(); ++p)
      if (f.tri[p] != kNoHit)
        sources->source[p] = s.morph && intermediate[f.tri[p]] ? PixelSource::MorphedGeometry
                                                               : PixelSource::Geometry;
  }
  const EnvironmentMap env = render_environment_map(
      scene, rt, s.centre, s.env_size,
      triangle_mask(scene.triangle_count(), part.environment_map_ids).data());
  if (!part.far_dynamic_ids.empty()) {
    // Eq. 2 displacement, then Eq. 3 against the map's range, then the depth test against geometry.
    std::vector<Vec3> dyn_points;
    const Frame dyn = render_displaced(
        scene, part.far_dynamic_ids, camera,
        [&](uint32_t v) { return to_vec(nf::displace_far(to_point(pos[v]), u, o)); },
        sources ? &dyn_points : nullptr);
    const nf::RangeCubeMap range{env.size, env.range.data()};
    tbb::parallel_for(
        tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
          for (int y = rows.begin(); y != rows.end(); ++y)
            for (int x = 0; x < camera.width; ++x) {
              const size_t p = size_t(y) * size_t(camera.width) + size_t(x);
              if (dyn.tri[p] == kNoHit || !(dyn.depth[p] < f.depth[p])) continue;
              Vec3 d = camera_ray(camera, x, y);
              d = d * (1.0 / length(d));
              if (!nf::passes_range_test(to_point(camera.eye + d * double(dyn.depth[p])), u, range))
                continue;
              f.tri[p] = dyn.tri[p];
              f.depth[p] = dyn.depth[p];
              if (sources) {
                sources->source[p] = PixelSource::DynamicFar;
                sources->point[p] = dyn_points[p];
              }
              for (int k = 0; k < 3; ++k) f.rgb[3 * p + size_t(k)] = dyn.rgb[3 * p + size_t(k)];
            }
        });
    std::vector<uint8_t> shown(scene.triangle_count(), 0);
    for (uint32_t t : f.tri)
      if (t != kNoHit) shown[t] = 1;
    for (uint32_t t : part.far_dynamic_ids) rc.far_dynamic_shown += shown[t];
  }
  if (counts) *counts = rc;
  compose(f, env, camera, s.lookup, s.r2, sources);
  return f;
}

Frame render_progressive(const Scene& scene, const EmbreeScene& rt,
                         const std::vector<uint32_t>& visible, const Camera& camera, Vec3 centre,
                         double big_r, double near_fraction, int env_size, double ring_radius) {
  assert(near_fraction > 0 && near_fraction < 1 && big_r > 0 && big_r <= ring_radius);
  const nf::Point3 o = to_point(centre), u = to_point(camera.eye);
  const double r_n = near_fraction * big_r;
  assert(nf::axis_distance(u, o) < r_n);
  const auto& pos = rest_positions(scene);
  // An object is near (received) when one of its visible vertices is within ring_radius of the
  // axis.
  std::vector<uint8_t> near_object(scene.objects.size(), 0);
  for (uint32_t t : visible)
    for (uint32_t v : scene.triangles[t])
      if (nf::axis_distance(to_point(pos[v]), o) < ring_radius)
        near_object[scene.triangle_object[t]] = 1;
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

std::vector<double> ring_visible_triangle_contribution(const Scene& scene,
                                                       const std::vector<uint32_t>& visible,
                                                       Vec3 centre,
                                                       const std::vector<double>& radii) {
  const nf::Point3 o = to_point(centre);
  const auto& pos = rest_positions(scene);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> object_radius(scene.objects.size(), inf),
      object_tris(scene.objects.size(), 0);
  for (uint32_t t : visible) {
    const uint32_t obj = scene.triangle_object[t];
    object_tris[obj] += 1;
    for (uint32_t v : scene.triangles[t])
      object_radius[obj] = std::fmin(object_radius[obj], nf::axis_distance(to_point(pos[v]), o));
  }
  std::vector<double> item_radius, item_weight;
  for (size_t obj = 0; obj < scene.objects.size(); ++obj)
    if (object_tris[obj] > 0)
      item_radius.push_back(object_radius[obj]), item_weight.push_back(object_tris[obj]);
  return nf::ring_contributions(radii, item_radius, item_weight);
}

ObjectCompletion object_completion(const Scene& scene, const Frame& truth, const Frame& test) {
  assert(truth.pixel_count() == test.pixel_count());
  const size_t n_obj = scene.objects.size();
  std::vector<size_t> truth_pixels(n_obj, 0), covered(n_obj, 0), test_pixels(n_obj, 0);
  std::vector<uint8_t> in_test(n_obj, 0);
  for (size_t p = 0; p < truth.pixel_count(); ++p) {
    const uint32_t a = truth.tri[p] == kNoHit ? kNoHit : scene.triangle_object[truth.tri[p]];
    const uint32_t b = test.tri[p] == kNoHit ? kNoHit : scene.triangle_object[test.tri[p]];
    if (b != kNoHit) {
      in_test[b] = 1;
      ++test_pixels[b];
    }
    if (a == kNoHit) continue;
    ++truth_pixels[a];
    if (a == b) ++covered[a];
  }
  ObjectCompletion c;
  size_t seen = 0;
  double agreement_sum = 0;
  size_t capped = 0, truth_total = 0;
  for (size_t o = 0; o < n_obj; ++o) {
    if (truth_pixels[o] == 0) continue;
    ++c.objects;
    if (in_test[o]) ++seen;
    agreement_sum += double(covered[o]) / double(truth_pixels[o]);
    capped += std::min(test_pixels[o], truth_pixels[o]);
    truth_total += truth_pixels[o];
  }
  if (c.objects > 0) {
    c.ovc = double(seen) / double(c.objects);
    c.object_pixel_agreement = agreement_sum / double(c.objects);
    c.ofc_eq2 = double(capped) / double(truth_total);
  }
  return c;
}

}  // namespace vislib
