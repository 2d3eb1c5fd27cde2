// cubemap.cpp: random cube orientations (docs/visibility-math.md §1).
#include "vislib/base/cubemap.h"

#include <cmath>

#include "vislib/base/random.h"

namespace vislib {

Mat3 random_orientation(uint64_t seed) {
  // Uniform unit quaternion from four Gaussians (Box-Muller on our own PRNG, so the result does
  // not depend on the standard library's distributions).
  Rng rng(seed);
  double q[4];
  double s = 0;
  do {
    for (double& c : q) c = rng.normal();
    s = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  } while (s < 1e-9);
  double w = q[0] / s, x = q[1] / s, y = q[2] / s, z = q[3] / s;
  Mat3 r;
  double m[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w),     2 * (x * z + y * w),
                 2 * (x * y + z * w),     1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                 2 * (x * z - y * w),     2 * (y * z + x * w),     1 - 2 * (x * x + y * y)};
  for (int i = 0; i < 9; ++i) r.m[i] = m[i];
  return r;
}

bool is_rotation(const Mat3& R) {
  Vec3 r0{R.m[0], R.m[1], R.m[2]}, r1{R.m[3], R.m[4], R.m[5]}, r2{R.m[6], R.m[7], R.m[8]};
  auto near = [](double a, double b) { return std::fabs(a - b) <= 1e-9; };
  return near(dot(r0, r0), 1) && near(dot(r1, r1), 1) && near(dot(r2, r2), 1) &&
         near(dot(r0, r1), 0) && near(dot(r0, r2), 0) && near(dot(r1, r2), 0) &&
         near(dot(r0, cross(r1, r2)), 1);
}

}  // namespace vislib
