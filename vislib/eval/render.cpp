// render.cpp: the Embree reference renderer (frames for the metrics of paper §4.3).
#include "vislib/eval/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cassert>
#include <cmath>
#include <limits>

namespace vislib {

namespace {

Vec3 normalized(Vec3 v) {
  return v * (1.0 / length(v));
}

uint64_t splitmix(uint64_t x) {
  uint64_t z = x + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

uint8_t to_byte(double v) {
  double s = std::round(v * 255.0);
  return uint8_t(s < 0 ? 0 : (s > 255 ? 255 : s));
}

// Image position of view-space coordinates (a, b) = (q.r / q.f, q.u / q.f).
PixelPosition to_pixel(const CameraBasis& b, const Camera& c, double a, double bb,
                       double view_depth) {
  PixelPosition p;
  p.x = (a / b.sx_scale - c.shift_x + 1.0) * double(c.width) * 0.5 - 0.5;
  p.y = (1.0 + c.shift_y - bb / b.sy_scale) * double(c.height) * 0.5 - 0.5;
  p.view_depth = view_depth;
  return p;
}

}  // namespace

CameraBasis camera_basis(const Camera& c) {
  assert(is_finite(c.forward) && length(c.forward) > 0);
  assert(c.vfov_degrees > 0 && c.vfov_degrees < 180);
  assert(c.width >= 1 && c.height >= 1 && c.z_near > 0);
  CameraBasis b;
  b.f = normalized(c.forward);
  Vec3 side = cross(b.f, c.up);
  assert(length(side) > 0 && "up must not be parallel to forward");
  b.r = normalized(side);
  b.u = cross(b.r, b.f);
  const double t = std::tan(c.vfov_degrees * (M_PI / 360.0));
  b.sy_scale = t;
  b.sx_scale = t * double(c.width) / double(c.height);
  return b;
}

Vec3 camera_ray(const CameraBasis& b, const Camera& c, int x, int y) {
  const double sx = (double(2 * x + 1) / double(c.width) - 1.0 + c.shift_x) * b.sx_scale;
  const double sy = (1.0 - double(2 * y + 1) / double(c.height) + c.shift_y) * b.sy_scale;
  return b.f + b.r * sx + b.u * sy;
}

Vec3 camera_ray(const Camera& camera, int x, int y) {
  assert(x >= 0 && x < camera.width && y >= 0 && y < camera.height);
  return camera_ray(camera_basis(camera), camera, x, y);
}

std::optional<PixelPosition> camera_project(const CameraBasis& b, const Camera& c, Vec3 world) {
  const Vec3 q = world - c.eye;
  const double z = dot(q, b.f);
  if (!(z > 0)) return std::nullopt;
  return to_pixel(b, c, dot(q, b.r) / z, dot(q, b.u) / z, z);
}

std::optional<PixelPosition> camera_project_direction(const CameraBasis& b, const Camera& c,
                                                      Vec3 dir) {
  const double z = dot(dir, b.f);
  if (!(z > 0)) return std::nullopt;
  return to_pixel(b, c, dot(dir, b.r) / z, dot(dir, b.u) / z,
                  std::numeric_limits<double>::infinity());
}

std::optional<PixelPosition> camera_project(const Camera& camera, Vec3 world) {
  return camera_project(camera_basis(camera), camera, world);
}

std::optional<PixelPosition> camera_project_direction(const Camera& camera, Vec3 dir) {
  return camera_project_direction(camera_basis(camera), camera, dir);
}

bool in_image(const Camera& c, const PixelPosition& p) {
  return p.x >= -0.5 && p.x < double(c.width) - 0.5 && p.y >= -0.5 && p.y < double(c.height) - 0.5;
}

std::array<uint8_t, 3> object_colour(uint32_t object) {
  const uint64_t h = splitmix(uint64_t(object));
  const double hue = double(h & 0xFFFF) / 65536.0 * 6.0;  // sector in [0, 6)
  const double sat = 0.45 + 0.35 * double((h >> 16) & 0xFF) / 255.0;
  const double val = 0.65 + 0.35 * double((h >> 24) & 0xFF) / 255.0;
  const int sector = int(hue);
  const double frac = hue - sector;
  const double p = val * (1 - sat), q = val * (1 - sat * frac), t = val * (1 - sat * (1 - frac));
  double rgb[3];
  switch (sector) {
    case 0:
      rgb[0] = val, rgb[1] = t, rgb[2] = p;
      break;
    case 1:
      rgb[0] = q, rgb[1] = val, rgb[2] = p;
      break;
    case 2:
      rgb[0] = p, rgb[1] = val, rgb[2] = t;
      break;
    case 3:
      rgb[0] = p, rgb[1] = q, rgb[2] = val;
      break;
    case 4:
      rgb[0] = t, rgb[1] = p, rgb[2] = val;
      break;
    default:
      rgb[0] = val, rgb[1] = p, rgb[2] = q;
      break;
  }
  return {to_byte(rgb[0]), to_byte(rgb[1]), to_byte(rgb[2])};
}

std::array<uint8_t, 3> shade_triangle(const Scene& scene, uint32_t tri, Vec3 dir) {
  const double len = length(dir);
  const auto c = scene.corners(tri, 0);
  const Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
  const double nl = length(normal);
  const double lambert = nl > 0 ? std::fabs(dot(normal, dir)) / (nl * len) : 0.0;
  const double sky = nl > 0 ? kRenderSky * std::fabs(normal.y) / nl : 0.0;
  const double shade =
      kRenderAmbient + (1.0 - kRenderAmbient) * std::fmin(std::fmax(lambert, sky), 1.0);
  const auto albedo = object_colour(scene.triangle_object[tri]);
  std::array<uint8_t, 3> out;
  for (int k = 0; k < 3; ++k) out[size_t(k)] = to_byte(double(albedo[size_t(k)]) / 255.0 * shade);
  return out;
}

Frame render_frame(const Scene& scene, const EmbreeScene& rt, const Camera& camera,
                   const uint8_t* allowed) {
  assert(rt.triangle_count() == scene.triangle_count());
  const CameraBasis b = camera_basis(camera);
  Frame frame;
  frame.width = camera.width;
  frame.height = camera.height;
  const size_t w = size_t(camera.width), n = frame.pixel_count();
  frame.rgb.assign(3 * n, 0);
  frame.depth.assign(n, std::numeric_limits<float>::infinity());
  frame.tri.assign(n, kNoHit);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, camera.height), [&](const tbb::blocked_range<int>& rows) {
        std::vector<Vec3> dirs(w);
        std::vector<Hit> hits(w);
        for (int y = rows.begin(); y != rows.end(); ++y) {
          for (int x = 0; x < camera.width; ++x) dirs[size_t(x)] = camera_ray(b, camera, x, y);
          rt.first_hits_among(camera.eye, dirs.data(), w, camera.z_near, allowed, hits.data());
          for (size_t x = 0; x < w; ++x) {
            const size_t p = size_t(y) * w + x;
            uint8_t* out = &frame.rgb[3 * p];
            const Hit& h = hits[x];
            if (h.tri == kNoHit) {
              out[0] = kRenderBackground[0], out[1] = kRenderBackground[1],
              out[2] = kRenderBackground[2];
              continue;
            }
            frame.tri[p] = h.tri;
            frame.depth[p] = float(h.lambda * length(dirs[x]));
            const auto c = shade_triangle(scene, h.tri, dirs[x]);
            out[0] = c[0], out[1] = c[1], out[2] = c[2];
          }
        }
      });
  return frame;
}

std::vector<uint8_t> triangle_mask(size_t triangle_count, const std::vector<uint32_t>& ids) {
  std::vector<uint8_t> mask(triangle_count, 0);
  for (uint32_t id : ids) {
    assert(id < triangle_count);
    mask[id] = 1;
  }
  return mask;
}

}  // namespace vislib
