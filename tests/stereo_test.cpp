// Tests of vislib/render/stereo.h: single-render stereo by reprojection (YORO).
// The oracle is independent of the reprojection: the true second eye is rendered by Embree, and a
// pixel is a true hole iff its world point is outside the source eye's image or hidden from the
// source eye (an Embree ray from the source eye towards it hits another triangle first).
#include "vislib/render/stereo.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using vislib_test::add_quad;

namespace {

// An axis-aligned box [lo, hi] as one object of 6 quads (12 triangles).
void add_box(Scene& s, Vec3 lo, Vec3 hi) {
  if (s.positions.empty()) s.positions.resize(1);
  const uint32_t base = uint32_t(s.positions[0].size());
  for (int i = 0; i < 8; ++i)
    s.positions[0].push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  const uint32_t obj = uint32_t(s.objects.size());
  s.objects.push_back({"box" + std::to_string(obj)});
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.triangles.push_back({base + uint32_t(q[0]), base + uint32_t(q[1]), base + uint32_t(q[2])});
    s.triangles.push_back({base + uint32_t(q[0]), base + uint32_t(q[2]), base + uint32_t(q[3])});
    s.triangle_object.push_back(obj);
    s.triangle_object.push_back(obj);
  }
}

// A room-like test scene: ground, back wall 6 m away, boxes and poles between 0.6 and 4 m from an
// eye at (0, 1.6, 0) looking along -z.
Scene clutter_scene() {
  Scene s;
  add_quad(s, {-20, 0, 5}, {20, 0, 5}, {20, 0, -6}, {-20, 0, -6});    // ground
  add_quad(s, {-20, 0, -6}, {20, 0, -6}, {20, 8, -6}, {-20, 8, -6});  // back wall
  add_box(s, {-0.9, 0.8, -1.6}, {-0.4, 1.4, -1.2});
  add_box(s, {0.3, 1.2, -0.9}, {0.5, 1.9, -0.6});
  add_box(s, {-0.2, 0, -3.2}, {0.6, 2.2, -2.8});
  add_box(s, {1.0, 0, -4.0}, {1.05, 3.0, -3.95});  // pole
  add_box(s, {-1.6, 0.5, -2.5}, {-1.2, 2.5, -2.2});
  add_box(s, {-0.05, 1.55, -0.75}, {0.05, 1.65, -0.65});  // small cube close to the eyes
  return s;
}

Camera head(int w = 320, int h = 240) {
  Camera c;
  c.eye = {0, 1.6, 0};
  c.forward = {0.05, -0.1, -1};
  c.width = w;
  c.height = h;
  c.vfov_degrees = 80;
  return c;
}

// 1 where the target pixel of `truth` is a true hole seen from `source_cam` (see the top).
struct Oracle {
  std::vector<uint8_t> hole, outside;
};
Oracle hole_oracle(const Frame& truth, const Camera& target, const Camera& source_cam,
                   const EmbreeScene& rt) {
  Oracle o;
  o.hole.assign(truth.pixel_count(), 0);
  o.outside.assign(truth.pixel_count(), 0);
  for (int y = 0; y < truth.height; ++y)
    for (int x = 0; x < truth.width; ++x) {
      const size_t p = size_t(y) * size_t(truth.width) + size_t(x);
      const Vec3 d = camera_ray(target, x, y);
      if (truth.tri[p] == kNoHit) {
        auto pp = camera_project_direction(source_cam, d);
        if (!pp || !in_image(source_cam, *pp)) {
          o.hole[p] = o.outside[p] = 1;
        } else if (rt.first_hit(source_cam.eye, d, 0).tri != kNoHit) {
          o.hole[p] = 1;
        }
        continue;
      }
      const Vec3 q = target.eye + d * (double(truth.depth[p]) / length(d));
      auto pp = camera_project(source_cam, q);
      if (!pp || !in_image(source_cam, *pp) || !(pp->view_depth > source_cam.z_near)) {
        o.hole[p] = o.outside[p] = 1;
        continue;
      }
      const Hit h = rt.first_hit(source_cam.eye, q - source_cam.eye, 1e-6);
      if (h.tri != kNoHit && h.tri != truth.tri[p] && h.lambda < 1 - 1e-4) o.hole[p] = 1;
    }
  return o;
}

struct PrecisionRecall {
  size_t mask = 0, truth = 0, both = 0;
  double precision() const { return mask ? double(both) / double(mask) : 1.0; }
  double recall() const { return truth ? double(both) / double(truth) : 1.0; }
};
PrecisionRecall compare_mask(const Reprojection& r, const Oracle& o) {
  PrecisionRecall pr;
  for (size_t p = 0; p < r.pixel_count(); ++p) {
    const bool m = r.hole[p] == HoleKind::Disocclusion || r.hole[p] == HoleKind::OutsideView;
    pr.mask += m;
    pr.truth += o.hole[p];
    pr.both += m && o.hole[p];
  }
  return pr;
}

double tri_agreement(const Frame& truth, const std::vector<uint32_t>& tri) {
  size_t same = 0;
  for (size_t p = 0; p < truth.pixel_count(); ++p) same += truth.tri[p] == tri[p];
  return double(same) / double(truth.pixel_count());
}

}  // namespace

TEST(StereoProject, InvertsCameraRayIncludingOffAxisShift) {
  Rng rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    Camera c;
    c.eye = {rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)};
    c.forward = {rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
    c.width = 17 + int(rng.uniform(0, 50));
    c.height = 13 + int(rng.uniform(0, 50));
    c.vfov_degrees = rng.uniform(20, 120);
    c.shift_x = rng.uniform(-0.3, 0.3);
    c.shift_y = rng.uniform(-0.3, 0.3);
    for (int k = 0; k < 20; ++k) {
      const int x = int(rng.uniform(0, c.width - 1e-9)), y = int(rng.uniform(0, c.height - 1e-9));
      const Vec3 d = camera_ray(c, x, y);
      auto p = camera_project(c, c.eye + d * rng.uniform(0.1, 100));
      ASSERT_TRUE(p);
      EXPECT_NEAR(p->x, x, 1e-9);
      EXPECT_NEAR(p->y, y, 1e-9);
      auto q = camera_project_direction(c, d);
      ASSERT_TRUE(q);
      EXPECT_NEAR(q->x, x, 1e-9);
      EXPECT_NEAR(q->y, y, 1e-9);
      EXPECT_TRUE(std::isinf(q->view_depth));
    }
    EXPECT_FALSE(camera_project(c, c.eye - c.forward));  // behind the eye
  }
}

TEST(StereoReproject, SameCameraReproducesTheSourceFrame) {
  Scene s = clutter_scene();
  Camera c = head(64, 48);
  EmbreeScene rt(s, 0, c.eye);
  Frame f = render_frame(s, rt, c);
  Reprojection r = reproject(f, c, c);
  EXPECT_EQ(r.holes(), 0u);
  EXPECT_EQ(r.rgb, f.rgb);
  EXPECT_EQ(r.tri, f.tri);
  for (size_t p = 0; p < f.pixel_count(); ++p) {
    EXPECT_EQ(r.source[p], p);
    if (std::isfinite(f.depth[p])) {
      EXPECT_NEAR(r.depth[p], f.depth[p], 1e-5 * f.depth[p]);
    }
  }
}

// Item 4: a pixel of the true second eye is a true hole iff its world point is hidden or outside
// the view from the source eye; the hole mask (disocclusion + outside) is scored against that.
TEST(StereoReproject, HoleMaskMatchesRayOracle) {
  Scene s = clutter_scene();
  EmbreeScene rt(s, 0, {0, 1.6, 0});
  for (double ipd : {0.065, 0.2}) {
    StereoPair eyes = stereo_pair(head(), ipd);
    for (int dir = 0; dir < 2; ++dir) {
      const Camera& src = dir == 0 ? eyes.left : eyes.right;
      const Camera& dst = dir == 0 ? eyes.right : eyes.left;
      Frame source = render_frame(s, rt, src);
      Frame truth = render_frame(s, rt, dst);
      Reprojection r = reproject(source, src, dst);
      Oracle o = hole_oracle(truth, dst, src, rt);
      PrecisionRecall pr = compare_mask(r, o);
      size_t outside_true = 0, outside_both = 0;
      for (size_t p = 0; p < r.pixel_count(); ++p) {
        outside_true += o.outside[p];
        outside_both += o.outside[p] && r.hole[p] == HoleKind::OutsideView;
      }
      std::printf(
          "ipd %.3f %s: mask %zu, oracle %zu, precision %.4f recall %.4f; outside %zu/%zu; cracks "
          "%zu\n",
          ipd, dir == 0 ? "left->right" : "right->left", pr.mask, pr.truth, pr.precision(),
          pr.recall(), outside_both, outside_true, r.count(HoleKind::Crack));
      EXPECT_GT(pr.truth, 100u);
      EXPECT_GE(pr.precision(), 0.95);
      EXPECT_GE(pr.recall(), 0.9);
      EXPECT_GE(double(outside_both), 0.95 * double(outside_true));
    }
  }
}

// Behind a 2 cm pole: Alg. 2 as printed writes the pole's depth into the hole span left of it,
// so background samples that belong there are rejected (holes poisoned); forward splatting keeps
// them.
TEST(StereoReproject, ThinPoleLeavesFarFewerHolesThanAlg2AsPrinted) {
  Scene s;
  add_quad(s, {-10, -10, -3}, {10, -10, -3}, {10, 10, -3}, {-10, 10, -3});  // wall 3 m away
  add_box(s, {-0.01, -10, -0.51}, {0.01, 10, -0.49});                       // 2 cm pole at 0.5 m
  Camera centre;
  centre.eye = {0, 0, 0};
  centre.forward = {0, 0, -1};
  centre.width = 640;
  centre.height = 480;
  centre.vfov_degrees = 60;
  EmbreeScene rt(s, 0, centre.eye);
  StereoPair eyes = stereo_pair(centre, 0.065);
  // The paper's case: right eye rendered (dominant), left eye reprojected; pixels move to +x.
  Frame source = render_frame(s, rt, eyes.right);
  Frame truth = render_frame(s, rt, eyes.left);
  Reprojection exact = reproject(source, eyes.right, eyes.left);
  Reprojection alg2 = reproject(source, eyes.right, eyes.left, Splatting::Alg2AsPrinted);
  Oracle o = hole_oracle(truth, eyes.left, eyes.right, rt);
  const int y = 240;  // a middle row; every row is alike
  auto row_holes = [&](const std::vector<HoleKind>& h) {
    int n = 0;
    for (int x = 0; x < 640; ++x) n += h[size_t(y) * 640 + size_t(x)] == HoleKind::Disocclusion;
    return n;
  };
  int oracle_row = 0, poisoned = 0;
  for (int x = 0; x < 640; ++x) {
    const size_t p = size_t(y) * 640 + size_t(x);
    oracle_row += o.hole[p] && !o.outside[p];
    poisoned += alg2.hole[p] != HoleKind::Filled && !o.hole[p];
  }
  const int he = row_holes(exact.hole), h2 = row_holes(alg2.hole);
  std::printf(
      "pole row: exact %d hole pixels, Alg. 2 as printed %d, oracle %d, poisoned by Alg. 2 %d\n",
      he, h2, oracle_row, poisoned);
  EXPECT_LE(std::abs(he - oracle_row), 1);
  EXPECT_GE(h2, 2 * he);
  EXPECT_GE(poisoned, h2 - oracle_row - 1);
  // The mirror image (left eye rendered, pixels move to -x, the scan runs right to left).
  Frame source_l = render_frame(s, rt, eyes.left);
  Reprojection exact_l = reproject(source_l, eyes.left, eyes.right);
  Reprojection alg2_l = reproject(source_l, eyes.left, eyes.right, Splatting::Alg2AsPrinted);
  const int he_l = row_holes(exact_l.hole), h2_l = row_holes(alg2_l.hole);
  std::printf("mirrored: exact %d, Alg. 2 as printed %d\n", he_l, h2_l);
  EXPECT_LE(std::abs(he_l - he), 2);
  EXPECT_GE(h2_l, 2 * he_l);
  // Where both fill a pixel, they agree (the defect is the poisoning, not the positions).
  for (size_t p = 0; p < exact.pixel_count(); ++p)
    if (exact.hole[p] == HoleKind::Filled && alg2.hole[p] == HoleKind::Filled) {
      EXPECT_EQ(exact.tri[p], alg2.tri[p]);
    }
}

TEST(StereoReproject, Alg2AsPrintedRejectsCantedEyes) {
  Camera c = head(32, 24);
  StereoPair canted = stereo_pair(c, 0.065, 2.0);
  Frame f;
  f.width = 32, f.height = 24;
  f.rgb.assign(3 * 32 * 24, 0);
  f.depth.assign(32 * 24, 1.0f);
  f.tri.assign(32 * 24, 0);
  EXPECT_THROW(reproject(f, canted.left, canted.right, Splatting::Alg2AsPrinted),
               std::invalid_argument);
  StereoPair offaxis = stereo_pair(c, 0.065, 0, 0.05);
  EXPECT_THROW(reproject(f, offaxis.left, offaxis.right, Splatting::Alg2AsPrinted),
               std::invalid_argument);
}

// Canted (toe-in) eyes and off-axis per-eye frusta need the full perspective divide; pixels then
// move both ways along x.
TEST(StereoReproject, CantedAndAsymmetricCamerasNeedTheDivide) {
  Scene s = clutter_scene();
  EmbreeScene rt(s, 0, {0, 1.6, 0});
  struct Case {
    const char* name;
    double toe_in, shift;
  };
  for (const Case& k : {Case{"canted 1 deg", 1.0, 0.0}, Case{"off-axis 0.03", 0.0, 0.03},
                        Case{"canted + off-axis", 0.5, 0.015}}) {
    StereoPair eyes = stereo_pair(head(), 0.065, k.toe_in, k.shift);
    Frame source = render_frame(s, rt, eyes.left);
    Frame truth = render_frame(s, rt, eyes.right);
    Reprojection r = reproject(source, eyes.left, eyes.right);
    size_t plus = 0, minus = 0, filled = 0, same = 0;
    for (size_t p = 0; p < r.pixel_count(); ++p) {
      if (r.hole[p] != HoleKind::Filled) continue;
      const long dx = long(p % size_t(r.width)) - long(r.source[p] % size_t(r.width));
      plus += dx > 0;
      minus += dx < 0;
      ++filled;
      same += r.tri[p] == truth.tri[p];
    }
    Oracle o = hole_oracle(truth, eyes.right, eyes.left, rt);
    PrecisionRecall pr = compare_mask(r, o);
    Reprojection rs = r;
    const ReshadeStats st = reshade(rs, s, eyes.right);
    size_t still = 0, same_reshaded = 0;
    for (size_t p = 0; p < r.pixel_count(); ++p) {
      still += r.hole[p] == HoleKind::Filled && rs.hole[p] == HoleKind::Filled;
      same_reshaded += r.hole[p] == HoleKind::Filled && rs.hole[p] == HoleKind::Filled &&
                       rs.tri[p] == truth.tri[p];
    }
    std::printf(
        "%s: moved +x %zu, -x %zu; filled %zu, same triangle %.4f; reshade: %zu unresolved, same "
        "triangle "
        "%.5f; holes precision %.4f recall %.4f\n",
        k.name, plus, minus, filled, double(same) / double(filled), st.unresolved,
        double(same_reshaded) / double(still), pr.precision(), pr.recall());
    EXPECT_GT(plus, 1000u);
    EXPECT_GT(minus, 1000u);
    EXPECT_GE(double(same) / double(filled), 0.97);
    EXPECT_GE(double(same_reshaded) / double(still), 0.999);
    EXPECT_LT(st.unresolved, filled / 100);
    EXPECT_GE(pr.precision(), 0.85);
    EXPECT_GE(pr.recall(), 0.9);
  }
}

TEST(StereoReproject, IdenticalForOneAndTwoThreads) {
  Scene s = clutter_scene();
  EmbreeScene rt(s, 0, {0, 1.6, 0});
  StereoPair eyes = stereo_pair(head(), 0.1, 1.0, 0.03);
  StereoPair parallel = stereo_pair(head(), 0.1);
  struct Out {
    Reprojection r, a2, rs;
    Frame none, median, yoro, printed, rays;
  };
  auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    Out o;
    Frame source = render_frame(s, rt, eyes.left);
    o.r = reproject(source, eyes.left, eyes.right);
    Frame ps = render_frame(s, rt, parallel.right);
    o.a2 = reproject(ps, parallel.right, parallel.left, Splatting::Alg2AsPrinted);
    o.none = patch_none(o.r);
    o.median = patch_median(o.r);
    o.yoro = patch_yoro(o.r);
    o.printed = patch_yoro(o.r, true);
    o.rs = o.r;
    reshade(o.rs, s, eyes.right);
    o.rays = patch_rays(o.rs, s, rt, eyes.right, nullptr);
    return o;
  };
  Out a = run(1), b = run(2);
  auto same_r = [](const Reprojection& x, const Reprojection& y) {
    return x.rgb == y.rgb && x.depth == y.depth && x.tri == y.tri && x.source == y.source &&
           x.hole == y.hole;
  };
  auto same_f = [](const Frame& x, const Frame& y) {
    return x.rgb == y.rgb && x.depth == y.depth && x.tri == y.tri;
  };
  EXPECT_TRUE(same_r(a.r, b.r));
  EXPECT_TRUE(same_r(a.a2, b.a2));
  EXPECT_TRUE(same_r(a.rs, b.rs));
  EXPECT_TRUE(same_f(a.none, b.none));
  EXPECT_TRUE(same_f(a.median, b.median));
  EXPECT_TRUE(same_f(a.yoro, b.yoro));
  EXPECT_TRUE(same_f(a.printed, b.printed));
  EXPECT_TRUE(same_f(a.rays, b.rays));
  EXPECT_GT(a.r.holes(), 0u);
}

// Item 4: `rays` + --reshade shows the true eye's triangle on >= 99.9% of the pixels (a city, a
// visible set that leaves out every third building, the truth rendered from the same set).
TEST(StereoPatch, RaysWithReshadeMatchTheTrueEyesTriangleIds) {
  CityOptions co;
  co.blocks_x = co.blocks_z = 2;
  co.block_size = 30;
  co.panel_size = 3;
  Scene s = generate_city(co);
  std::vector<uint8_t> allowed(s.triangle_count(), 1);
  for (uint32_t t = 0; t < s.triangle_count(); ++t)
    if (s.triangle_object[t] % 3 == 2) allowed[t] = 0;
  Camera c;
  c.eye = {-7, 1.7, -7};  // in the street between the blocks
  c.forward = {1, -0.05, 0.6};
  c.width = 320;
  c.height = 240;
  c.vfov_degrees = 75;
  EmbreeScene rt(s, 0, c.eye);
  for (double ipd : {0.065, 0.3}) {
    StereoPair eyes = stereo_pair(c, ipd);
    Frame source = render_frame(s, rt, eyes.left, allowed.data());
    Frame truth = render_frame(s, rt, eyes.right, allowed.data());
    Reprojection r = reproject(source, eyes.left, eyes.right);
    size_t rays = 0;
    Frame plain = patch_rays(r, s, rt, eyes.right, allowed.data(), &rays);
    reshade(r, s, eyes.right);
    size_t rays2 = 0;
    Frame fixed = patch_rays(r, s, rt, eyes.right, allowed.data(), &rays2);
    const double a = tri_agreement(truth, plain.tri), b = tri_agreement(truth, fixed.tri);
    const FrameQuality q = frame_quality(truth, fixed);
    std::printf(
        "ipd %.3f: %zu triangles, holes re-cast %zu (after reshade %zu); triangle ids: rays %.5f, "
        "rays + "
        "reshade %.5f; PSNR %.2f SSIM %.5f\n",
        ipd, s.triangle_count(), rays, rays2, a, b, q.psnr, q.ssim);
    EXPECT_GE(b, 0.999);
    EXPECT_LT(rays2, truth.pixel_count() / 4);
  }
}

// Alg. 3 walks its kernel from the far end: the farthest sample then gets 52-80% of the weight
// (Eq. 6). The fixed patcher walks from the hole's edge.
TEST(StereoPatch, YoroWeightsFavourTheSampleNextToTheHole) {
  for (int width = 5; width <= 40; ++width)
    for (double t : {0.05, 0.5, 1.0}) {
      std::vector<double> w = yoro_kernel_weights(width, t);
      double sum = 0;
      for (double v : w) sum += v;
      EXPECT_NEAR(sum, 1, 1e-12);
      EXPECT_GE(w[0], 0.515);
      EXPECT_LE(w[0], 0.801);
      for (size_t k = 1; k < w.size(); ++k) EXPECT_LT(w[k], w[k - 1]);
    }
  // A one-row image: background ramp | 4-pixel hole | foreground. The fixed patcher fills from
  // the background next to the hole; the printed order takes mostly the far end of the ramp.
  Reprojection r;
  r.width = 16, r.height = 1;
  r.rgb.assign(48, 0);
  r.depth.assign(16, 10.0f);
  r.tri.assign(16, 0);
  r.source.assign(16, 0);
  r.hole.assign(16, HoleKind::Filled);
  for (int x = 0; x < 8; ++x)
    r.rgb[3 * size_t(x)] = uint8_t(20 * x);  // red ramp, 140 next to the hole
  for (int x = 8; x < 12; ++x)
    r.hole[size_t(x)] = HoleKind::Disocclusion, r.source[size_t(x)] = kNoSource;
  for (int x = 12; x < 16; ++x)
    r.depth[size_t(x)] = 1.0f, r.rgb[3 * size_t(x) + 1] = 255;  // green foreground
  Frame fixed = patch_yoro(r), printed = patch_yoro(r, true);
  for (int x = 8; x < 12; ++x) {
    EXPECT_GE(fixed.rgb[3 * size_t(x)], 110) << x;    // near 140: the edge sample dominates
    EXPECT_LE(printed.rgb[3 * size_t(x)], 100) << x;  // pulled towards 80 (the kernel's far end)
    EXPECT_EQ(fixed.rgb[3 * size_t(x) + 1], 0) << "foreground sampled at " << x;
  }
}

// §11.3-11.4: IPD 5.0-7.5 cm, an irregular object 0.5-3 m away scaled to a constant screen size,
// 5 m in front of a wall. Holes grow with the IPD and shrink with the distance; the patched eye
// keeps SSIM >= 0.95 (the paper's threshold) except where noted.
TEST(StereoSweep, IpdAndObjectDistance) {
  double prev_distance_share = 1;
  for (double dist : {0.5, 1.0, 2.0, 3.0}) {
    // A lumpy sphere of radius 0.1 * dist (the same size on screen at every distance).
    Scene s;
    add_quad(s, {-50, -50, -dist - 5}, {50, -50, -dist - 5}, {50, 50, -dist - 5},
             {-50, 50, -dist - 5});
    const int nu = 48, nv = 24;
    const double rad = 0.1 * dist;
    s.objects.push_back({"lumpy"});
    const uint32_t base = uint32_t(s.positions[0].size());
    for (int j = 0; j <= nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const double th = M_PI * j / nv, ph = 2 * M_PI * i / nu;
        const double rr =
            rad * (1 + 0.25 * std::sin(3 * ph) * std::sin(2 * th) + 0.1 * std::cos(5 * th));
        s.positions[0].push_back({rr * std::sin(th) * std::cos(ph), rr * std::cos(th),
                                  -dist + rr * std::sin(th) * std::sin(ph)});
      }
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        auto at = [&](int ii, int jj) { return base + uint32_t(jj * nu + (ii % nu)); };
        s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        s.triangle_object.push_back(1);
        s.triangle_object.push_back(1);
      }
    Camera c;
    c.eye = {0, 0, 0};
    c.forward = {0, 0, -1};
    c.width = 320;
    c.height = 240;
    c.vfov_degrees = 60;
    EmbreeScene rt(s, 0, c.eye);
    double first_share = -1, share_65 = 0;
    for (double ipd = 0.05; ipd <= 0.0751; ipd += 0.005) {
      StereoPair eyes = stereo_pair(c, ipd);
      Frame source = render_frame(s, rt, eyes.right);
      Frame truth = render_frame(s, rt, eyes.left);
      Reprojection r = reproject(source, eyes.right, eyes.left);
      const double share = double(r.count(HoleKind::Disocclusion)) / double(r.pixel_count());
      const FrameQuality q = frame_quality(truth, patch_yoro(r));
      std::printf("distance %.1f m, IPD %.1f cm: disocclusion %.4f, yoro PSNR %.2f SSIM %.4f\n",
                  dist, ipd * 100, share, q.psnr, q.ssim);
      if (first_share < 0) first_share = share;
      if (std::fabs(ipd - 0.065) < 1e-9) share_65 = share;
      EXPECT_GE(q.ssim, 0.95);
      EXPECT_GE(q.psnr, 30.0);
      if (ipd > 0.0749) {
        EXPECT_GT(share, first_share);  // 7.5 cm leaves more holes than 5 cm
      }
    }
    EXPECT_LT(share_65, prev_distance_share);  // farther object, fewer holes (at 6.5 cm)
    prev_distance_share = share_65;
  }
}

// Item 3: `pvs view --stereo` on a baked city, the head on a cell boundary so that the eyes lie in
// two cells (their union is rendered); the fallback; Alg. 2; bad options.
TEST(StereoCli, ViewStereoWritesThePairTheHoleMaskAndTheJsonBlock) {
  using nlohmann::json;
  const std::string dir = vislib_test::temp_dir("stereo_cli");
  const std::string city = dir + "/city.glb", pvs = dir + "/city.pvs";
  std::string out;
  ASSERT_EQ(vislib_test::run_pvs("generate city --blocks 2,2 -o " + city, &out), 0) << out;
  ASSERT_EQ(vislib_test::run_pvs(
                "bake " + city + " --box -60,0,-60,60,3,60 --grid 2,1,1 --res 24 -o " + pvs, &out),
            0)
      << out;
  const std::string view =
      "view " + pvs + " --scene " + city +
      " --at 0,1.6,-20 --look 0.5,1.5,-100 --near-far 40,60 --frame 160x120 -o " + dir +
      "/f.png --json " + dir + "/m.json";
  auto load = [&] {
    std::ifstream in(dir + "/m.json");
    return json::parse(in);
  };
  ASSERT_EQ(
      vislib_test::run_pvs(view + " --stereo yoro --ipd 0.065 --dominant left --patch yoro", &out),
      0)
      << out;
  json j = load()["stereo"];
  EXPECT_EQ(j["cells"].size(), 2u) << j.dump(1);  // x = 0 is a cell boundary: one eye on each side
  EXPECT_TRUE(j["eyes"]["left"]["rendered"].get<bool>());
  EXPECT_FALSE(j["eyes"]["right"]["rendered"].get<bool>());
  EXPECT_TRUE(
      j["eyes"]["left"]["method_error"]["psnr"].is_null());  // the rendered eye is the truth
  EXPECT_GT(j["eyes"]["right"]["holes"]["share"].get<double>(), 0.0);
  EXPECT_GT(j["eyes"]["right"]["method_error"]["ssim"].get<double>(), 0.9);
  EXPECT_EQ(j["rays"]["both_eyes"].get<size_t>(), 2u * 160 * 120);
  EXPECT_EQ(j["rays"]["cast"].get<size_t>(), 160u * 120);
  for (const auto& [k, v] : j["images"].items())
    EXPECT_TRUE(std::filesystem::exists(v.get<std::string>())) << k;

  ASSERT_EQ(
      vislib_test::run_pvs(view + " --stereo true --patch rays --reshade --dominant right", &out),
      0)
      << out;
  j = load()["stereo"];
  EXPECT_LT(j["eyes"]["left"]["method_error"]["triangle_mismatch"].get<double>(), 0.001);
  EXPECT_GT(j["rays"]["cast"].get<size_t>(), 160u * 120);

  ASSERT_EQ(vislib_test::run_pvs(view + " --stereo yoro --max-hole-share 0", &out), 0) << out;
  j = load()["stereo"];
  EXPECT_TRUE(j["eyes"]["right"]["fallback"].get<bool>());
  EXPECT_TRUE(j["eyes"]["right"]["method_error"]["psnr"].is_null());
  EXPECT_EQ(j["rays"]["cast"].get<size_t>(), 2u * 160 * 120);

  ASSERT_EQ(vislib_test::run_pvs(view + " --stereo alg2 --dominant centre --patch median", &out), 0)
      << out;
  j = load()["stereo"];
  EXPECT_EQ(j["splatting"], "alg2_as_printed");
  EXPECT_FALSE(j["eyes"]["left"]["rendered"].get<bool>());
  EXPECT_FALSE(j["eyes"]["right"]["rendered"].get<bool>());
  EXPECT_EQ(j["cells"].size(), 2u);

  EXPECT_EQ(vislib_test::run_pvs(view + " --stereo yoro --ipd -1", &out), 2) << out;
  EXPECT_EQ(vislib_test::run_pvs(view + " --stereo maybe", &out), 2) << out;
  EXPECT_EQ(vislib_test::run_pvs(view + " --stereo yoro --patch telea", &out), 2) << out;
  // An eye outside every cell: the baked boxes end at x = 60.
  EXPECT_EQ(vislib_test::run_pvs(
                "view " + pvs + " --scene " + city +
                    " --at 59.99,1.6,-20 --look 59.99,1.6,-100 --near-far 40,60 --frame 32x24 -o " +
                    dir + "/g.png --stereo yoro --ipd 0.2",
                &out),
            2)
      << out;
  EXPECT_NE(out.find("in no cell"), std::string::npos) << out;
}
