// Conservative pixel footprints (footprint.h, docs/visibility-math.md §5.1): every pixel whose ray
// hits the triangle from some eye position on the segment lies in the footprint's pixel bounds and
// row spans (brute force over sampled eye positions), also for triangles cut by the near plane.
#include "vislib/kernel/footprint.h"

#include <gtest/gtest.h>

#include <cmath>

#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"

using namespace vislib;

namespace {

// True when the ray e + lambda d (lambda > 0) hits triangle abc strictly inside (barycentrics
// above 1e-9) at view depth F.(lambda d) = lambda > near (F.d = 1 for pixel directions).
bool hits(Vec3 e, Vec3 d, const Vec3 tri[3], double near) {
  Vec3 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
  Vec3 p = cross(d, e2);
  double det = dot(e1, p);
  if (std::fabs(det) < 1e-14) return false;
  Vec3 s = e - tri[0];
  double u = dot(s, p) / det;
  Vec3 q = cross(s, e1);
  double v = dot(d, q) / det;
  double lambda = dot(e2, q) / det;
  const double m = 1e-9;
  return u > m && v > m && u + v < 1 - m && lambda > near * (1 + 1e-9);
}

struct Coverage {
  int hit_pixels = 0, missed = 0;
};

// Brute force on face k: pixels hit from 33 eye positions along v0 -> v1, each checked against the
// footprint of the six eye-relative corners.
Coverage check_face(const Vec3 tri[3], Vec3 v0, Vec3 v1, int k, int n, double near) {
  const FaceAxes ax = face_axes(k, Mat3{});
  Vec3 rel[6];
  for (int i = 0; i < 3; ++i) {
    rel[i] = tri[i] - v0;
    rel[3 + i] = tri[i] - v1;
  }
  const Footprint fp = compute_footprint(rel, 6, ax, near);
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  const bool any = footprint_pixel_bounds(fp, n, x0, x1, y0, y1);
  Coverage c;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const Vec3 d = pixel_direction(ax, x, y, n);
      bool hit = false;
      for (int j = 0; j <= 32 && !hit; ++j) hit = hits(v0 + (v1 - v0) * (j / 32.0), d, tri, near);
      if (!hit) continue;
      ++c.hit_pixels;
      int rx0 = 0, rx1 = -1;
      const bool in_bounds = any && x0 <= x && x <= x1 && y0 <= y && y <= y1;
      const bool in_row = footprint_row_span(fp, n, y, rx0, rx1) && rx0 <= x && x <= rx1;
      if (!in_bounds || !in_row) ++c.missed;
    }
  return c;
}

}  // namespace

TEST(Footprint, ContainsEveryPixelARandomTriangleCoversFromTheSegment) {
  Rng rng(17);
  const int n = 24;
  int hit_pixels = 0;
  for (int trial = 0; trial < 40; ++trial) {
    Vec3 c{rng.uniform(-4, 4), rng.uniform(-4, 4), rng.uniform(-4, 4)};
    Vec3 tri[3];
    for (Vec3& p : tri) p = c + Vec3{rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2)};
    const Vec3 v0{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
    const Vec3 v1 = v0 + Vec3{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
    for (int k = 0; k < kCubeFaces; ++k) {
      Coverage cov = check_face(tri, v0, v1, k, n, 0.01);
      EXPECT_EQ(cov.missed, 0) << "trial " << trial << " face " << k;
      hit_pixels += cov.hit_pixels;
    }
  }
  EXPECT_GT(hit_pixels, 1000);  // the check is not vacuous
}

TEST(Footprint, TriangleCutByTheNearPlaneKeepsEveryCoveredPixel) {
  // Corners on both sides of the eye's near plane on face +Z (F = +z): one just in front of the
  // eye, two behind it; the eye moves sideways.
  const Vec3 tri[3] = {{0.3, 0.2, 0.5}, {-2, -1, -1}, {2, -1.5, -0.8}};
  const Vec3 v0{0, 0, 0}, v1{0.4, 0.1, 0};
  const double near = 0.05;
  int hit_pixels = 0;
  for (int k = 0; k < kCubeFaces; ++k) {
    Coverage cov = check_face(tri, v0, v1, k, 32, near);
    EXPECT_EQ(cov.missed, 0) << "face " << k;
    hit_pixels += cov.hit_pixels;
  }
  EXPECT_GT(hit_pixels, 50);
}

TEST(Footprint, TriangleBehindTheNearPlaneIsEmptyOnThatFace) {
  // Face +Z sees z > 0; the triangle lies at z in (0, near) from every eye position.
  const Vec3 tri[3] = {{0, 0, 0.01}, {1, 0, 0.02}, {0, 1, 0.015}};
  Vec3 rel[6];
  for (int i = 0; i < 3; ++i) rel[i] = rel[3 + i] = tri[i];
  const Footprint fp = compute_footprint(rel, 6, face_axes(4, Mat3{}), 0.05);
  EXPECT_TRUE(fp.empty());
  int x0, x1, y0, y1;
  EXPECT_FALSE(footprint_pixel_bounds(fp, 16, x0, x1, y0, y1));
}
