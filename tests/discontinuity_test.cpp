// Tests of the near-far paper's discontinuity metric delta (vislib/eval/discontinuity.h, Eqs. 7-8)
// on hand-computed cases, and of the per-pixel scene points render_near_far gives it.
#include "vislib/eval/discontinuity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scene_builders.h"
#include "vislib/eval/metrics.h"
#include "vislib/render/near_far_render.h"

namespace {

using vislib::Vec3;
using vislib_test::add_quad;

TEST(Discontinuity, SplitRowGivesHandComputedValues) {
  // Four pixels in a row whose truth positions are 0, 1, 1.5, 2.5: the right pair is shifted left
  // by half a pixel against the left pair in the truth image. Radius 1.2:
  //  p0 (0):   N = {p1 at 1.0}             ratio |0-1|/1 = 1            delta 0
  //  p1 (1):   N = {p0 at 1.0, p2 at 0.5}  ratios 1/1, 1/0.5 = 1, 2     delta 0.5
  //  p2 (1.5): N = {p1 at 0.5, p3 at 1.0}  ratios 1/0.5, 1/1 = 2, 1     delta 0.5
  //  p3 (2.5): N = {p2 at 1.0} (p1 at 1.5 is out)                       delta 0
  const std::vector<double> xy = {0, 0, 1, 0, 1.5, 0, 2.5, 0};
  const vislib::Discontinuity d = vislib::discontinuity(4, 1, xy, 1.2);
  ASSERT_EQ(d.delta.size(), 4u);
  EXPECT_DOUBLE_EQ(d.delta[0], 0.0);
  EXPECT_DOUBLE_EQ(d.delta[1], 0.5);
  EXPECT_DOUBLE_EQ(d.delta[2], 0.5);
  EXPECT_DOUBLE_EQ(d.delta[3], 0.0);
  EXPECT_EQ(d.pixels, 4u);
  EXPECT_DOUBLE_EQ(d.mean, 0.25);
  EXPECT_DOUBLE_EQ(d.mean_abs, 0.25);
  EXPECT_DOUBLE_EQ(d.max, 0.5);
  EXPECT_EQ(d.share_above_half, 0.0);  // strictly above 0.5
}

TEST(Discontinuity, ImageMagnifiedTwiceHasDeltaOneEverywhere) {
  // t(p) = p / 2: every pair is twice as far apart in the image as in the truth, so each ratio is
  // 2 and delta = 1 wherever a neighbour lies within the radius (here the 8 around each pixel).
  const int w = 5, h = 4;
  std::vector<double> xy;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) xy.push_back(x / 2.0), xy.push_back(y / 2.0);
  const vislib::Discontinuity d = vislib::discontinuity(w, h, xy, 0.8);
  EXPECT_EQ(d.pixels, size_t(w * h));
  for (double v : d.delta) EXPECT_NEAR(v, 1.0, 1e-12);
  EXPECT_NEAR(d.mean, 1.0, 1e-12);
  // Shrunk twice instead (t(p) = 2p, radius 2.5: the 8 around each pixel): ratios 1/2, delta -0.5.
  for (size_t i = 0; i < xy.size(); ++i) xy[i] *= 4;
  const vislib::Discontinuity s = vislib::discontinuity(w, h, xy, 2.5);
  EXPECT_NEAR(s.mean, -0.5, 1e-12);
  EXPECT_NEAR(s.mean_abs, 0.5, 1e-12);
  EXPECT_EQ(d.share_above_half, 1.0);
}

TEST(Discontinuity, PixelsWithoutPointOrNeighbourOrWithACoincidentOneAreHandled) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // p0 and p1 share a truth position (left out, counted), p2 has no point, p3 is alone.
  const std::vector<double> xy = {0, 0, 0, 0, nan, nan, 50, 50};
  const vislib::Discontinuity d = vislib::discontinuity(4, 1, xy, 2.0);
  EXPECT_EQ(d.pixels, 0u);
  for (double v : d.delta) EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(d.coincident_pairs, 2u);
  EXPECT_EQ(d.mean, 0.0);
}

TEST(Discontinuity, ProjectToPixelInvertsCameraRay) {
  vislib::Camera cam;
  cam.eye = {1, 2, 3};
  cam.forward = {0.3, -0.2, -1};
  cam.vfov_degrees = 70;
  cam.width = 37, cam.height = 23;
  cam.shift_x = 0.25, cam.shift_y = -0.1;
  for (int y = 0; y < cam.height; y += 5)
    for (int x = 0; x < cam.width; x += 3) {
      const auto t = vislib::project_to_pixel(cam, cam.eye + vislib::camera_ray(cam, x, y) * 7.5);
      ASSERT_TRUE(t.has_value());
      EXPECT_NEAR((*t)[0], x, 1e-9);
      EXPECT_NEAR((*t)[1], y, 1e-9);
    }
  EXPECT_FALSE(vislib::project_to_pixel(cam, cam.eye - cam.forward).has_value());
}

// A ground plane of 2 x 2 quads from z = +4 to z = -80, seen from an eye 3 units off the centre O.
vislib::Scene ground() {
  vislib::Scene s;
  for (int i = -10; i < 10; ++i)
    for (int k = -40; k < 2; ++k)
      add_quad(s, {2.0 * i, 0, 2.0 * k}, {2.0 * i + 2, 0, 2.0 * k}, {2.0 * i + 2, 0, 2.0 * k + 2},
               {2.0 * i, 0, 2.0 * k + 2});
  return s;
}

TEST(NearFarRender, SourcePointsOfAnAllNearFrameGiveZeroDiscontinuity) {
  const vislib::Scene s = ground();
  vislib::Camera cam;
  cam.eye = {0.5, 1.5, 0.3};
  cam.forward = {0.1, -0.3, -1};
  cam.width = 80, cam.height = 60;
  vislib::EmbreeScene rt(s, 0.0, cam.eye);
  vislib::NearFarSettings set;
  set.centre = {0, 1.5, 0};
  set.r1 = 500, set.r2 = 1000, set.env_size = 32;
  std::vector<uint32_t> ids(s.triangle_count());
  for (uint32_t t = 0; t < ids.size(); ++t) ids[t] = t;
  vislib::PixelSources src;
  const vislib::Frame nf = vislib::render_near_far(s, rt, ids, cam, set, nullptr, &src);
  size_t geometry = 0;
  for (size_t p = 0; p < nf.pixel_count(); ++p) {
    EXPECT_EQ(src.source[p] == vislib::PixelSource::Geometry, nf.tri[p] != vislib::kNoHit);
    geometry += src.source[p] == vislib::PixelSource::Geometry;
    if (nf.tri[p] != vislib::kNoHit) {
      EXPECT_NEAR(src.point[p].y, 0.0, 1e-5);  // on the ground
    }
  }
  EXPECT_GT(geometry, nf.pixel_count() / 2);
  const vislib::Discontinuity d = vislib::frame_discontinuity(cam, src.point, 5.0);
  EXPECT_EQ(d.pixels, geometry);
  EXPECT_LT(d.max, 1e-4);  // the hit points lie on the pixel rays: t(p) = p up to float depths
}

TEST(NearFarRender, MorphLowersTheDiscontinuityOfTheFarGround) {
  // Without the morph the far ground, looked up in the map rendered from O, is displaced by the
  // 3-unit eye offset against the intermediate ground drawn from the eye: a seam at r2. The Eq. 1
  // morph joins them, so the seam's large delta values vanish.
  const vislib::Scene s = ground();
  vislib::Camera cam;
  cam.eye = {3, 1.5, 0};
  cam.forward = {0, -0.25, -1};
  cam.width = 96, cam.height = 72;
  vislib::EmbreeScene rt(s, 0.0, cam.eye);
  vislib::NearFarSettings set;
  set.centre = {0, 1.5, 0};
  set.r1 = 6, set.r2 = 14, set.env_size = 256;
  std::vector<uint32_t> ids(s.triangle_count());
  for (uint32_t t = 0; t < ids.size(); ++t) ids[t] = t;
  vislib::PixelSources with, without;
  vislib::RegionCounts rc;
  vislib::render_near_far(s, rt, ids, cam, set, &rc, &with);
  ASSERT_GT(rc.intermediate, 0u);
  ASSERT_GT(rc.far, 0u);
  set.morph = false;
  vislib::render_near_far(s, rt, ids, cam, set, nullptr, &without);
  size_t env = 0;
  for (auto k : with.source) env += k == vislib::PixelSource::EnvironmentMap;
  EXPECT_GT(env, 0u);
  const vislib::Discontinuity dm = vislib::frame_discontinuity(cam, with.point, 5.0);
  const vislib::Discontinuity dn = vislib::frame_discontinuity(cam, without.point, 5.0);
  // The seam: without the morph, pixels torn apart at r2 (delta > 0.5, up to 3.6 measured); with
  // it, none beyond the morph's own stretch (max 0.51 measured). The mean drops less: both frames
  // share the environment map's own warp (far points seen from O, neighbours farther apart or
  // closer in the frame than from the eye by up to |U - O| / r2 ~ 20%).
  EXPECT_GT(dn.share_above_half, 0.01);
  EXPECT_LT(dm.share_above_half, dn.share_above_half / 20);
  EXPECT_GT(dn.max, 3 * dm.max);
  EXPECT_GT(dn.mean, dm.mean);
}

}  // namespace
