// Tests of vislib/eval/render.h: camera convention, analytic depth, shading, subset frames,
// determinism.
#include "vislib/eval/render.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "tests/scene_builders.h"
#include "vislib/eval/point_visibility.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using vislib_test::add_quad;
using vislib_test::soup;

namespace {

// A 200 x 200 plane through `p` with unit normal `n` (two triangles, one object).
Scene plane(Vec3 p, Vec3 n) {
  Vec3 helper = std::fabs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 u = cross(n, helper);
  u = u * (100.0 / length(u));
  Vec3 w = cross(n, u);
  Scene s;
  add_quad(s, p - u - w, p + u - w, p + u + w, p - u + w);
  return s;
}

Camera camera(Vec3 eye, Vec3 forward, int w = 41, int h = 31) {
  Camera c;
  c.eye = eye;
  c.forward = forward;
  c.width = w;
  c.height = h;
  c.vfov_degrees = 70;
  return c;
}

}  // namespace

TEST(Render, CameraRayFollowsTheConvention) {
  const Camera c = camera({1, 2, 3}, {0, 0, -2}, 5, 3);
  // Odd sizes: the middle pixel looks exactly along forward.
  const Vec3 mid = camera_ray(c, 2, 1);
  EXPECT_DOUBLE_EQ(mid.x, 0.0);
  EXPECT_DOUBLE_EQ(mid.y, 0.0);
  EXPECT_DOUBLE_EQ(mid.z, -1.0);
  // Top-left pixel: left (-x, since right = f x up = +x) and up (+y); f.d = 1.
  const Vec3 tl = camera_ray(c, 0, 0);
  const double t = std::tan(35.0 * M_PI / 180.0);
  EXPECT_NEAR(tl.x, -(4.0 / 5.0) * t * 5.0 / 3.0, 1e-15);
  EXPECT_NEAR(tl.y, (2.0 / 3.0) * t, 1e-15);
  EXPECT_DOUBLE_EQ(tl.z, -1.0);
}

TEST(Render, DepthOfAPlaneMatchesTheAnalyticRange) {
  const Vec3 n = Vec3{0.2, 0.3, 1.0} * (1.0 / length(Vec3{0.2, 0.3, 1.0}));
  const Vec3 p{0.5, -0.25, -7.0};
  const Scene s = plane(p, n);
  const Vec3 eye{0.3, 1.1, 0.4};
  const EmbreeScene rt(s, 0.0, eye);
  const Camera c = camera(eye, {0.1, -0.2, -1.0});
  const Frame f = render_frame(s, rt, c);
  ASSERT_EQ(f.pixel_count(), size_t(41 * 31));
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const Vec3 d = camera_ray(c, x, y);
      const Vec3 u = d * (1.0 / length(d));
      const double range = dot(n, p - eye) / dot(n, u);  // eye + range * u lies on the plane
      const size_t i = size_t(y) * size_t(c.width) + size_t(x);
      ASSERT_NE(f.tri[i], kNoHit) << x << "," << y;
      EXPECT_NEAR(f.depth[i], range, 2e-6 * range) << x << "," << y;
    }
}

TEST(Render, FrontalPlaneShowsTheObjectColourAtTheCentre) {
  const Scene s = plane({0, 0, -5}, {0, 0, 1});
  const EmbreeScene rt(s, 0.0, Vec3{});
  const Camera c = camera({0, 0, 0}, {0, 0, -1});
  const Frame f = render_frame(s, rt, c);
  const size_t centre = size_t(15 * 41 + 20);
  const auto albedo = object_colour(0);
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(f.rgb[3 * centre + k], albedo[k]);  // |n.v| = 1
  // Off-centre pixels are darker (headlight Lambert), never brighter.
  for (size_t k = 0; k < 3; ++k) EXPECT_LE(f.rgb[k], albedo[k]);
  EXPECT_EQ(object_colour(12345), object_colour(12345));
  EXPECT_NE(object_colour(1), object_colour(2));
}

TEST(Render, StreetSeenFromEyeHeightKeepsMostOfItsColour) {
  // A floor 1.6 below the eye and a wall along the view direction, both seen at grazing angles
  // (|n.v| well under 0.5 in the lower and right parts of the frame): the floor is lit from above
  // (at least kRenderAmbient + (1 - kRenderAmbient) * kRenderSky = 0.74 of its colour), the wall by
  // the ambient term at least; the headlight alone left them near black (0.1 + 0.9 |n.v|).
  Scene s = plane({0, -1.6, 0}, {0, 1, 0});
  const Scene wall = plane({3, 0, 0}, {-1, 0, 0});
  add_quad(s, wall.positions[0][0], wall.positions[0][1], wall.positions[0][2],
           wall.positions[0][3]);
  const EmbreeScene rt(s, 0.0, Vec3{});
  const Frame f = render_frame(s, rt, camera({0, 0, 0}, {0, 0, -1}));
  const double floor_share = kRenderAmbient + (1 - kRenderAmbient) * kRenderSky;
  size_t floor = 0, wall_pixels = 0;
  for (size_t p = 0; p < f.pixel_count(); ++p) {
    if (f.tri[p] == kNoHit) continue;
    const bool on_floor = f.tri[p] < 2;
    (on_floor ? floor : wall_pixels) += 1;
    const double share = on_floor ? floor_share : kRenderAmbient;
    const auto albedo = object_colour(s.triangle_object[f.tri[p]]);
    for (size_t k = 0; k < 3; ++k)
      EXPECT_GE(f.rgb[3 * p + k] + 1.0, albedo[k] * share) << p;  // 8-bit rounding
  }
  EXPECT_GT(floor, 200u);
  EXPECT_GT(wall_pixels, 100u);
}

TEST(Render, EmptySceneIsAllBackground) {
  Scene s;
  const EmbreeScene rt(s, 0.0, Vec3{});
  const Frame f = render_frame(s, rt, camera({0, 0, 0}, {1, 0, 0}));
  for (size_t p = 0; p < f.pixel_count(); ++p) {
    EXPECT_EQ(f.tri[p], kNoHit);
    EXPECT_TRUE(std::isinf(f.depth[p]));
    for (size_t k = 0; k < 3; ++k) EXPECT_EQ(f.rgb[3 * p + k], kRenderBackground[k]);
  }
}

TEST(Render, SubsetWithoutATriangleShowsTheBackgroundWhereItWas) {
  // id 0: a small triangle in front (nothing behind it); ids 1-2: a wall to the right.
  Scene s = soup({{Vec3{-1.5, -1, -4}, Vec3{-0.5, -1, -4}, Vec3{-1, 1, -4}}});
  add_quad(s, {0.5, -2, -6}, {3, -2, -6}, {3, 2, -6}, {0.5, 2, -6});
  const EmbreeScene rt(s, 0.0, Vec3{});
  const Camera c = camera({0, 0, 0}, {0, 0, -1});
  const Frame full = render_frame(s, rt, c);
  const auto mask = triangle_mask(s.triangle_count(), {1, 2});
  const Frame sub = render_frame(s, rt, c, mask.data());
  size_t removed = 0;
  for (size_t p = 0; p < full.pixel_count(); ++p) {
    if (full.tri[p] == 0) {
      ++removed;
      EXPECT_EQ(sub.tri[p], kNoHit);
      EXPECT_TRUE(std::isinf(sub.depth[p]));
      for (size_t k = 0; k < 3; ++k) EXPECT_EQ(sub.rgb[3 * p + k], kRenderBackground[k]);
    } else {
      EXPECT_EQ(sub.tri[p], full.tri[p]);
      EXPECT_EQ(sub.depth[p], full.depth[p]);
      for (size_t k = 0; k < 3; ++k) EXPECT_EQ(sub.rgb[3 * p + k], full.rgb[3 * p + k]);
    }
  }
  EXPECT_GT(removed, 10u);
}

TEST(Render, SubsetOfTheFramesOwnTrianglesReproducesTheFullFrameExactly) {
  CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  o.panel_size = 3;  // many small facade triangles with shared edges
  const Scene s = generate_city(o);
  const EmbreeScene rt(s, 0.0, Vec3{0, 1.7, 0});
  for (const Vec3& dir : {Vec3{0.3, -0.05, -1}, Vec3{1, 0.2, 0.1}, Vec3{-0.7, 0.1, 0.6}}) {
    Camera c = camera({0.5, 1.7, 3}, dir, 160, 120);
    const Frame full = render_frame(s, rt, c);
    const auto all = std::vector<uint8_t>(s.triangle_count(), 1);
    const auto own = triangle_mask(s.triangle_count(), visible_set(full.tri));
    for (const auto* mask : {&all, &own}) {
      const Frame sub = render_frame(s, rt, c, mask->data());
      EXPECT_EQ(sub.tri, full.tri);
      EXPECT_EQ(sub.depth, full.depth);
      EXPECT_EQ(sub.rgb, full.rgb);
    }
  }
}

TEST(Render, SameFrameWithOneAndTwoThreads) {
  CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  o.panel_size = 4;
  const Scene s = generate_city(o);
  Frame f[2];
  for (int threads = 1; threads <= 2; ++threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    const EmbreeScene rt(s, 0.0, Vec3{0, 1.7, 0});
    f[threads - 1] = render_frame(s, rt, camera({0.5, 1.7, 3}, {0.2, 0, -1}, 120, 90));
  }
  EXPECT_EQ(f[0].tri, f[1].tri);
  EXPECT_EQ(f[0].depth, f[1].depth);
  EXPECT_EQ(f[0].rgb, f[1].rgb);
}

TEST(Render, NearPlaneClipsByViewDepth) {
  // A wall at view depth 0.05 in front of one at 3: with z_near 0.1 the far wall shows.
  Scene s;
  add_quad(s, {-1, -1, -0.05}, {1, -1, -0.05}, {1, 1, -0.05}, {-1, 1, -0.05});
  add_quad(s, {-9, -9, -3}, {9, -9, -3}, {9, 9, -3}, {-9, 9, -3});
  const EmbreeScene rt(s, 0.0, Vec3{});
  Camera c = camera({0, 0, 0}, {0, 0, -1});
  c.z_near = 0.01;
  EXPECT_LT(render_frame(s, rt, c).tri[15 * 41 + 20], 2u);
  c.z_near = 0.1;
  EXPECT_GE(render_frame(s, rt, c).tri[15 * 41 + 20], 2u);
}
