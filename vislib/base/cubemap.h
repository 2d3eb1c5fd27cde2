// cubemap.h: the binding cubemap convention (docs/visibility-math.md §1). Every kernel
// (from-segment, from-point, renderer, oracle) uses exactly these faces, pixel centres and
// directions.
//
// Faces 0..5 = +X, -X, +Y, -Y, +Z, -Z (OpenGL cube-map table). Face k has a forward axis F and the
// axes S, T along which the pixel-centre coordinates sc, tc grow. For pixel (x, y) of an N x N face
// (x = column, y = row, 0 <= x, y < N):
//   sc = (2x+1)/N - 1,  tc = (2y+1)/N - 1,  d = F + sc*S + tc*T   (not normalised: F.d = 1)
// World direction = R * d, with R the row-major cube orientation. A hit counts only at
// lambda > near along this un-normalised d, so lambda is the view-space depth.
#pragma once

#include <cstdint>

#include "runtime/near_far.h"
#include "vislib/base/vec.h"

namespace vislib {

constexpr int kCubeFaces = 6;

struct FaceAxes {
  Vec3 F, S, T;
};

// The local (unrotated) axes of face k: the runtime's table (runtime/near_far.h), its one copy.
inline FaceAxes face_axes_local(int k) {
  const pvs_runtime::CubeFaceAxes& a = pvs_runtime::kCubeFaceAxes[k];
  return {{a.f.x, a.f.y, a.f.z}, {a.s.x, a.s.y, a.s.z}, {a.t.x, a.t.y, a.t.z}};
}

// World axes of face k for orientation R.
inline FaceAxes face_axes(int k, const Mat3& R) {
  FaceAxes a = face_axes_local(k);
  return {R * a.F, R * a.S, R * a.T};
}

// Pixel-centre coordinate of column/row `i` on an N-pixel side: (2i+1)/N - 1.
inline double pixel_center(int i, int n) {
  return double(2 * i + 1) / double(n) - 1.0;
}

// World direction of pixel (x, y) of face axes `a` (F.d = 1 in the face frame).
inline Vec3 pixel_direction(const FaceAxes& a, int x, int y, int n) {
  double sc = pixel_center(x, n), tc = pixel_center(y, n);
  return a.F + a.S * sc + a.T * tc;
}

// Continuous pixel coordinate of a face coordinate u in [-1,1]: (u+1)N/2 - 1/2.
inline double pixel_coord(double u, int n) {
  return (u + 1.0) * double(n) * 0.5 - 0.5;
}

// Identity and a uniformly random rotation (from a seed; deterministic on every platform).
inline Mat3 identity_orientation() {
  return Mat3{};
}
Mat3 random_orientation(uint64_t seed);

// True when R is a rotation (orthonormal rows, det +1) to within 1e-9.
bool is_rotation(const Mat3& R);

}  // namespace vislib
