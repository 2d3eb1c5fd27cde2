// scene_transform.cpp: scene_transform.h.
#include "vislib/scene/scene_transform.h"

#include <cmath>
#include <stdexcept>

#include "vislib/base/cubemap.h"

namespace vislib {

Mat3 axis_angle_rotation(Vec3 axis, double degrees) {
  const double len = std::sqrt(dot(axis, axis));
  if (!(len > 0) || !std::isfinite(len) || !std::isfinite(degrees))
    throw std::invalid_argument("rotation: the axis must be finite and non-zero, the angle finite");
  const Vec3 k = axis * (1.0 / len);
  const double a = degrees * (M_PI / 180.0), c = std::cos(a), s = std::sin(a), C = 1 - c;
  Mat3 r;
  const double m[9] = {c + k.x * k.x * C,       k.x * k.y * C - k.z * s, k.x * k.z * C + k.y * s,
                       k.y * k.x * C + k.z * s, c + k.y * k.y * C,       k.y * k.z * C - k.x * s,
                       k.z * k.x * C - k.y * s, k.z * k.y * C + k.x * s, c + k.z * k.z * C};
  for (int i = 0; i < 9; ++i) r.m[i] = m[i];
  return r;
}

Mat3 multiply(const Mat3& a, const Mat3& b) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[3 * i + j] =
          a.m[3 * i] * b.m[j] + a.m[3 * i + 1] * b.m[3 + j] + a.m[3 * i + 2] * b.m[6 + j];
  return r;
}

Vec3 apply(const Similarity& s, Vec3 p) {
  return (s.rotation * p) * s.scale + s.translation;
}

void transform_scene(Scene& scene, const Similarity& s) {
  if (!(s.scale > 0) || !std::isfinite(s.scale) || !is_rotation(s.rotation) ||
      !is_finite(s.translation))
    throw std::invalid_argument(
        "transform: needs a finite scale > 0, a rotation and a finite translation");
  for (auto& state : scene.positions)
    for (Vec3& p : state) p = apply(s, p);
  for (auto& state : scene.sphere_centers)
    for (Vec3& p : state) p = apply(s, p);
  for (double& r : scene.sphere_radius) r *= s.scale;
}

}  // namespace vislib
