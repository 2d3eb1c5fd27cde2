// Tests of the near-far reference renderer (vislib/render/near_far_render.h) and of `pvs view`.
#include "vislib/render/near_far_render.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "scene_builders.h"
#include "test_support.h"
#include "vislib/eval/metrics.h"
#include "vislib/render/near_region_growth.h"
#include "vislib/render/view_setup.h"
#include "vislib/scene/generate.h"

namespace {

using vislib::Vec3;
using vislib_test::add_quad;

std::vector<uint32_t> all_ids(const vislib::Scene& s) {
  std::vector<uint32_t> ids(s.triangle_count());
  for (uint32_t t = 0; t < ids.size(); ++t) ids[t] = t;
  return ids;
}

// The pixel (column, row) where point p projects in `cam` (render.h's camera convention).
std::pair<double, double> project(const vislib::Camera& cam, Vec3 p) {
  Vec3 f = cam.forward * (1.0 / length(cam.forward));
  Vec3 r = cross(f, cam.up);
  r = r * (1.0 / length(r));
  Vec3 u = cross(r, f);
  Vec3 d = p - cam.eye;
  const double t = std::tan(cam.vfov_degrees * M_PI / 360.0);
  const double sx = dot(d, r) / dot(d, f) / (t * cam.width / cam.height),
               sy = dot(d, u) / dot(d, f) / t;
  return {(sx + 1) * cam.width / 2 - 0.5, (1 - sy) * cam.height / 2 - 0.5};
}

// The lowest (largest row) pixel showing triangle `tri`, ties: the mean column of that row.
std::pair<double, double> lowest_pixel(const vislib::Frame& f, uint32_t tri) {
  for (int y = f.height - 1; y >= 0; --y) {
    double sum = 0;
    int n = 0;
    for (int x = 0; x < f.width; ++x)
      if (f.tri[size_t(y) * f.width + x] == tri) sum += x, ++n;
    if (n) return {sum / n, y};
  }
  return {-1e9, -1e9};
}

TEST(NearFarRender, EverythingNearEqualsTheFullFrame) {
  vislib::Scene s;
  add_quad(s, {-3, -1, -6}, {3, -1, -6}, {3, 2, -6}, {-3, 2, -6});
  add_quad(s, {-1, 0, -4}, {1, 0, -4}, {1, 1, -3}, {-1, 1, -3});
  add_quad(s, {-6, -1, -9}, {-2, -1, -12}, {-2, 3, -12}, {-6, 3, -9});
  vislib::Camera cam;
  cam.eye = {0.2, 0.5, 0.1};
  cam.forward = {0, 0, -1};
  cam.width = 96, cam.height = 64;
  vislib::EmbreeScene rt(s, 0.0, cam.eye);
  const vislib::Frame truth = vislib::render_frame(s, rt, cam);
  vislib::NearFarSettings set;
  set.centre = {0, 0.5, 0};
  set.r1 = 100, set.r2 = 200, set.env_size = 64;
  vislib::RegionCounts rc;
  const vislib::Frame nf = vislib::render_near_far(s, rt, all_ids(s), cam, set, &rc);
  EXPECT_EQ(rc.near, s.triangle_count());
  EXPECT_EQ(rc.intermediate + rc.far + rc.env_map, 0u);
  const vislib::FrameQuality q = vislib::frame_quality(truth, nf);
  EXPECT_EQ(q.epsilon, 0.0);
  EXPECT_EQ(q.ssim, 1.0);
  EXPECT_EQ(truth.rgb, nf.rgb);
  EXPECT_EQ(truth.tri, nf.tri);
  const vislib::ObjectCompletion c = vislib::object_completion(s, truth, nf);
  EXPECT_EQ(c.objects, 3u);
  EXPECT_EQ(c.ovc, 1.0);
  EXPECT_EQ(c.object_pixel_agreement, 1.0);
}

// A far triangle whose lowest vertex P lies exactly on the r2 cylinder, seen from an eye 2 units
// off O's axis.
struct R2Fixture {
  vislib::Scene s;
  vislib::Camera cam;
  vislib::NearFarSettings set;
  Vec3 p{0, 1.5, -20};
  R2Fixture() {
    s = vislib_test::soup({{p, {3, 6, -22}, {-3, 6, -22}}});
    cam.eye = {2, 1.5, 0};
    cam.forward = {-0.1, 0.1, -1};
    cam.width = 160, cam.height = 120;
    set.centre = {0, 1.5, 0};
    set.r1 = 5, set.r2 = 20, set.env_size = 1024;
  }
};

TEST(NearFarRender, VertexOnR2ThroughCylinderLookupLandsAtItsTruePixel) {
  R2Fixture f;
  f.set.lookup = vislib::EnvironmentLookup::CylinderR2;
  vislib::EmbreeScene rt(f.s, 0.0, f.cam.eye);
  const vislib::Frame truth = vislib::render_frame(f.s, rt, f.cam);
  vislib::RegionCounts rc;
  const vislib::Frame nf = vislib::render_near_far(f.s, rt, {0}, f.cam, f.set, &rc);
  EXPECT_EQ(rc.far, 1u);
  EXPECT_EQ(rc.env_map, 1u);
  const auto want = project(f.cam, f.p);
  const auto got_truth = lowest_pixel(truth, 0), got = lowest_pixel(nf, 0);
  // The lowest pixel centre inside a sharp tip lies up to ~2 pixels from the tip's projection.
  EXPECT_NEAR(got_truth.first, want.first, 2.0);
  EXPECT_NEAR(got_truth.second, want.second, 2.0);
  EXPECT_NEAR(got.first, got_truth.first, 1.0);
  EXPECT_NEAR(got.second, got_truth.second, 1.0);
}

TEST(NearFarRender, VertexOnR2ThroughEyeDirectionLookupLandsWhereOSeesIt) {
  // The paper's lookup: P appears from U in the direction O sees it, i.e. at U + (P - O), which is
  // where Eq. 1 morphs an intermediate vertex on r2.
  R2Fixture f;
  vislib::EmbreeScene rt(f.s, 0.0, f.cam.eye);
  const vislib::Frame nf = vislib::render_near_far(f.s, rt, {0}, f.cam, f.set);
  // Ground truth of this lookup: the full frame of the scene translated by U - O.
  vislib::Scene moved = f.s;
  for (auto& v : moved.positions[0]) v = v + (f.cam.eye - f.set.centre);
  vislib::EmbreeScene rt_moved(moved, 0.0, f.cam.eye);
  const vislib::Frame truth = vislib::render_frame(moved, rt_moved, f.cam);
  const auto want = project(f.cam, f.cam.eye + (f.p - f.set.centre));
  const auto got_truth = lowest_pixel(truth, 0), got = lowest_pixel(nf, 0);
  EXPECT_NEAR(got_truth.first, want.first, 2.0);
  EXPECT_NEAR(got_truth.second, want.second, 2.0);
  EXPECT_NEAR(got.first, got_truth.first, 1.0);
  EXPECT_NEAR(got.second, got_truth.second, 1.0);
}

// A stationary far wall at z = -8 (as seen from O at the origin) and a moving far triangle: in
// key state 0 it is behind the wall (z = -10), in state 1 in front of it (z = -6). Eq. 2 draws it
// from the eye; Eq. 3 against the wall's range from O hides it at tau = 0 and shows it at tau = 1,
// as the full-scene frame does.
TEST(NearFarRender, DynamicFarTriangleBehindAStationaryFarWallIsHidden) {
  vislib::Scene s;
  add_quad(s, {-6, -3, -8}, {6, -3, -8}, {6, 4, -8}, {-6, 4, -8});  // triangles 0, 1 (static)
  s.positions.resize(2, s.positions[0]);
  const uint32_t base = uint32_t(s.positions[0].size());
  for (double z : {-10.0, -6.0}) {
    const size_t k = z < -8 ? 0 : 1;
    for (Vec3 p : {Vec3{-0.8, 0.0, z}, Vec3{0.8, 0.0, z}, Vec3{0.0, 1.2, z}})
      s.positions[k].push_back(p);
  }
  s.objects.push_back({"mover"});
  s.triangles.push_back({base, base + 1, base + 2});  // triangle 2 (moving)
  s.triangle_object.push_back(1);
  const std::vector<uint8_t> moving = vislib::moving_triangles(s);
  ASSERT_EQ(moving, (std::vector<uint8_t>{0, 0, 1}));

  vislib::Camera cam;
  cam.eye = {0.2, 0.4, 0.1};
  cam.forward = {0, 0, -1};
  cam.width = 96, cam.height = 64;
  vislib::NearFarSettings set;
  set.centre = {0, 0.3, 0};
  set.r1 = 1, set.r2 = 2;  // the wall and the triangle are far in both states
  set.env_size = 128;
  set.dynamic = moving.data();
  size_t shown[2] = {0, 0}, in_truth[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const vislib::Scene at = vislib::scene_at(s, double(k));
    vislib::EmbreeScene rt(at, 0.0, cam.eye);
    vislib::RegionCounts rc;
    const vislib::Frame nf = vislib::render_near_far(at, rt, all_ids(at), cam, set, &rc);
    const vislib::Frame truth = vislib::render_frame(at, rt, cam);
    EXPECT_EQ(rc.far, 3u);
    EXPECT_EQ(rc.far_dynamic, 1u);
    EXPECT_EQ(rc.env_map, 2u);  // the moving triangle is never baked into the map
    for (uint32_t t : nf.tri) shown[k] += t == 2;
    for (uint32_t t : truth.tri) in_truth[k] += t == 2;
    EXPECT_EQ(rc.far_dynamic_shown, shown[k] > 0 ? 1u : 0u);
  }
  EXPECT_EQ(in_truth[0], 0u);
  EXPECT_EQ(shown[0], 0u) << "behind the wall as seen from O: Eq. 3 must hide it";
  EXPECT_GT(in_truth[1], 20u);
  EXPECT_GT(shown[1], 20u) << "in front of the wall: it must appear";
  // Its footprint is the true one shifted by Eq. 2's U - O (a few pixels at this distance).
  EXPECT_NEAR(double(shown[1]), double(in_truth[1]), 0.25 * double(in_truth[1]));
}

// A moving far triangle with no stationary far geometry behind it (the map's range is +infinity
// along its directions) passes Eq. 3 and is drawn.
TEST(NearFarRender, DynamicFarTriangleWithNothingBehindIsDrawnByEq2) {
  vislib::Scene s;
  s.positions.resize(2);
  for (Vec3 p : {Vec3{-0.8, 0.0, -10}, Vec3{0.8, 0.0, -10}, Vec3{0.0, 1.2, -10}})
    s.positions[0].push_back(p);
  for (Vec3 p : {Vec3{-0.8, 0.0, -6}, Vec3{0.8, 0.0, -6}, Vec3{0.0, 1.2, -6}})
    s.positions[1].push_back(p);
  s.objects.push_back({"mover"});
  s.triangles.push_back({0, 1, 2});
  s.triangle_object.push_back(0);
  const std::vector<uint8_t> moving = vislib::moving_triangles(s);
  vislib::Camera cam;
  cam.eye = {0.2, 0.4, 0.1};
  cam.forward = {0, 0, -1};
  cam.width = 96, cam.height = 64;
  vislib::NearFarSettings set;
  set.centre = {0, 0.3, 0};
  set.r1 = 1, set.r2 = 2;
  set.env_size = 64;
  set.dynamic = moving.data();
  const vislib::Scene at = vislib::scene_at(s, 0.0);
  vislib::EmbreeScene rt(at, 0.0, cam.eye);
  vislib::RegionCounts rc;
  const vislib::Frame nf = vislib::render_near_far(at, rt, all_ids(at), cam, set, &rc);
  EXPECT_EQ(rc.far_dynamic_shown, 1u);
}

TEST(PvsView, WritesFramesAndMetricsOnABakedCity) {
  using vislib_test::run_pvs;
  const std::string dir = vislib_test::temp_dir("pvs_view");
  std::string out;
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 -o " + dir + "/city.glb", &out), 0) << out;
  ASSERT_EQ(
      run_pvs(
          "bake " + dir +
              "/city.glb --box -10,0,-10,10,3,10 --grid 2,1,2 --eye-height 1.5,1.8 --res 32 -o " +
              dir + "/city.pvs",
          &out),
      0)
      << out;
  ASSERT_EQ(run_pvs("view " + dir + "/city.pvs --scene " + dir +
                        "/city.glb --at 5,1.6,5 --look 40,1.6,5 "
                        "--near-far 10,30 --grow --rings 4 --frame 96x64 -o " +
                        dir + "/v.png --json " + dir + "/v.json",
                    &out),
            0)
      << out;
  for (const char* name : {"/v.png", "/v_truth.png", "/v_heat.png", "/v_nomorph.png"})
    EXPECT_TRUE(std::ifstream(dir + name).good()) << name;
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(dir + "/v.json"));
  for (const char* key : {"psnr", "ssim", "epsilon", "ovc", "object_pixel_agreement", "ofc_eq2",
                          "triangles", "without_morph", "continuity"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_FALSE(j.contains("ofc"));  // one name, one meaning: CloVR's OFC is ofc_eq2
  for (const char* key : {"near", "intermediate", "far", "visible"})
    EXPECT_TRUE(j["triangles"].contains(key)) << key;
  EXPECT_EQ(j["triangles"]["near"].get<size_t>() + j["triangles"]["intermediate"].get<size_t>() +
                j["triangles"]["far"].get<size_t>(),
            j["triangles"]["visible"].get<size_t>());
  EXPECT_GE(j["ssim"].get<double>(), -1.0);
  EXPECT_LE(j["ssim"].get<double>(), 1.0);
  EXPECT_TRUE(j["without_morph"].contains("ssim"));
  // delta (Eqs. 7-8) and epsilon by pixel source, with and without the morph: the sources add up
  // to epsilon, nothing is morphed without the morph.
  for (const nlohmann::json* m : {&j, &j["without_morph"]}) {
    const nlohmann::json& q = *m;
    ASSERT_TRUE(q.contains("delta"));
    EXPECT_GE(q["delta"]["mean_abs"].get<double>(), std::fabs(q["delta"]["mean"].get<double>()));
    EXPECT_GT(q["delta"]["pixels"].get<size_t>(), 0u);
    EXPECT_EQ(q["delta"]["radius"].get<double>(), 17.0);
    EXPECT_NEAR(q["epsilon_geometry"].get<double>() + q["epsilon_morphed"].get<double>() +
                    q["epsilon_env_map"].get<double>(),
                q["epsilon"].get<double>(), 1e-12);
  }
  EXPECT_EQ(j["without_morph"]["morphed_pixels"].get<double>(), 0.0);
  // --grow: both ring sequences, merged radii a subsequence of the equal-area ones ending at r2,
  // every ring after the first injected over --frames-per-ring (default 4) frames.
  const nlohmann::json& c = j["continuity"];
  const auto equal = c["equal_area"]["radii"].get<std::vector<double>>();
  const auto merged = c["merged"]["radii"].get<std::vector<double>>();
  ASSERT_EQ(equal.size(), 4u);
  ASSERT_FALSE(merged.empty());
  EXPECT_LE(merged.size(), equal.size());
  EXPECT_DOUBLE_EQ(merged.back(), 30.0);
  for (double r : merged) EXPECT_NE(std::find(equal.begin(), equal.end(), r), equal.end()) << r;
  EXPECT_EQ(c["equal_area"]["frames"].get<size_t>(), 1 + 4 * (equal.size() - 1));
  EXPECT_EQ(c["merged"]["frames"].get<size_t>(), 1 + 4 * (merged.size() - 1));
  EXPECT_EQ(c["min_consecutive_ssim"], c["merged"]["min_consecutive_ssim"]);
  // A PVS of another scene is rejected.
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 --seed 9 -o " + dir + "/other.glb", &out), 0)
      << out;
  EXPECT_NE(run_pvs("view " + dir + "/city.pvs --scene " + dir +
                        "/other.glb --at 5,1.6,5 --look 40,1.6,5 "
                        "--near-far 10,30 --frame 32x32 -o " +
                        dir + "/w.png",
                    &out),
            0)
      << out;
}

}  // namespace

// CloVR's Eq. 2 counts footprints (pixels of an object anywhere), capped at the truth's, weighted
// by footprint; the per-object mean of per-pixel agreement (object_pixel_agreement) does
// not. A 4 x 1 frame: truth shows object 0 on 3 pixels and object 1 on 1 pixel; the test shows
// object 0 shifted by one pixel (3 pixels, 2 in place) and object 1 not at all; then object 0
// over all 4 pixels.
TEST(NearFarRender, ObjectFootprintCompletionFollowsClovrEquation2) {
  vislib::Scene s;
  vislib_test::add_quad(s, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});  // triangles 0, 1: object 0
  vislib_test::add_quad(s, {2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 1, 0});  // triangles 2, 3: object 1
  auto frame = [](std::vector<uint32_t> tri) {
    vislib::Frame f;
    f.width = int(tri.size());
    f.height = 1;
    f.tri = tri;
    f.rgb.assign(3 * tri.size(), 0);
    f.depth.assign(tri.size(), 1.0f);
    return f;
  };
  const uint32_t none = vislib::kNoHit;
  const vislib::Frame truth = frame({0, 1, 0, 2});
  // Object 0 drawn on pixels 1..3 (2 of its 3 truth pixels), object 1 missing.
  vislib::ObjectCompletion c = vislib::object_completion(s, truth, frame({none, 0, 1, 0}));
  EXPECT_DOUBLE_EQ(c.object_pixel_agreement, (2.0 / 3.0 + 0.0) / 2.0);
  EXPECT_DOUBLE_EQ(c.ofc_eq2, (3.0 + 0.0) / 4.0);  // min(3, 3) + min(0, 1) over 3 + 1
  // Object 0 grown over object 1's pixel: capped at its truth footprint.
  c = vislib::object_completion(s, truth, frame({0, 0, 0, 1}));
  EXPECT_DOUBLE_EQ(c.ofc_eq2, 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(c.object_pixel_agreement, (1.0 + 0.0) / 2.0);
}

// The setup of a near-far view of a cell (vislib/render/view_setup.h) and both growths.
TEST(ViewSetup, DefaultRadiiHoldTheCellAndTheEyeInsideR1AndR2IsTwiceR1) {
  pvs::Box box;
  box.min[0] = 0, box.min[1] = 0, box.min[2] = 0;
  box.max[0] = 6, box.max[1] = 3, box.max[2] = 8;  // half x-z diagonal 5
  const vislib::NearFarRadii r = vislib::default_near_far_radii(box, 1.0);
  EXPECT_EQ(r.r1, 6.25);
  EXPECT_EQ(r.r2, 12.5);
  EXPECT_EQ(vislib::default_near_far_radii(box, 8.0).r1, 10.0);  // the eye far off the axis
  box.max[0] = 0, box.max[2] = 0;
  EXPECT_GT(vislib::default_near_far_radii(box, 0.0).r1, 0.0);  // never zero
}

TEST(ViewSetup, CameraLookingAlongTheUpVectorGetsMinusZUp) {
  const vislib::Camera c = vislib::look_at_camera({1, 2, 3}, {1, 2, -7}, 64, 48);
  EXPECT_EQ(c.eye.z, 3);
  EXPECT_EQ(c.forward.z, -10);
  EXPECT_EQ(c.width, 64);
  EXPECT_EQ(c.height, 48);
  const vislib::Camera down = vislib::look_at_camera({0, 5, 0}, {0, 0, 0}, 64, 48);
  EXPECT_GT(length(cross(down.forward, down.up)), 0);
  EXPECT_EQ(down.up.z, -1);
}

TEST(ViewSetup, DefaultCentreLeavesABuildingForTheNearestFreeSample) {
  vislib::Scene s;  // a closed box [-1, 1]^3, faces outward
  const double a = -1, b = 1;
  add_quad(s, {a, a, a}, {b, a, a}, {b, a, b}, {a, a, b});
  add_quad(s, {a, b, a}, {a, b, b}, {b, b, b}, {b, b, a});
  add_quad(s, {a, a, a}, {a, a, b}, {a, b, b}, {a, b, a});
  add_quad(s, {b, a, a}, {b, b, a}, {b, b, b}, {b, a, b});
  add_quad(s, {a, a, a}, {a, b, a}, {b, b, a}, {b, a, a});
  add_quad(s, {a, a, b}, {b, a, b}, {b, b, b}, {a, b, b});
  auto region = [](Vec3 lo, Vec3 hi) {
    vislib::Box3 r;
    r.extend(lo);
    r.extend(hi);
    return r;
  };
  // Free centre: kept.
  const vislib::Box3 street = region({3, -0.5, 3}, {5, 0.5, 5});
  const auto kept = vislib::default_view_centre(s, street, {4, 0, 4});
  ASSERT_TRUE(kept);
  EXPECT_FALSE(kept->moved);
  EXPECT_EQ(kept->point.x, 4);
  // A region straddling the box: its centre (0.5, 0, 0.5) is inside, a free sample is not.
  const vislib::Box3 straddling = region({-0.5, -0.5, -0.5}, {1.5, 0.5, 1.5});
  const auto moved = vislib::default_view_centre(s, straddling, {0.5, 0, 0.5});
  ASSERT_TRUE(moved);
  EXPECT_TRUE(moved->moved);
  EXPECT_TRUE(moved->point.x > 1 || moved->point.z > 1) << moved->point.x << "," << moved->point.z;
  // Wholly inside: no default.
  EXPECT_FALSE(
      vislib::default_view_centre(s, region({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}), {0, 0, 0}));
}

TEST(NearRegionGrowth, BothSchedulesAreTheSeparateGrowthsWithEveryFrameReported) {
  vislib::CityOptions co;
  co.blocks_x = co.blocks_z = 2;
  const vislib::Scene s = vislib::generate_city(co);
  const std::vector<uint32_t> visible = all_ids(s);
  const vislib::Camera cam = vislib::look_at_camera({5, 1.6, 5}, {40, 1.6, 5}, 48, 32);
  const vislib::EmbreeScene rt(s, 0.0, cam.eye);
  const vislib::Frame truth = vislib::render_frame(s, rt, cam);
  const Vec3 centre{5, 1.6, 5};
  const vislib::GrowthPlan plan = vislib::plan_growth(s, visible, centre, 30, 4, -1);
  vislib::GrowthSettings g;
  g.centre = centre;
  g.env_size = 32;
  g.frames_per_ring = 2;
  std::map<std::string, size_t> frames;
  const vislib::GrowthComparison both = vislib::grow_near_region_both(
      s, rt, visible, cam, truth, plan, g,
      [&](const std::string& schedule, size_t i, const vislib::GrowthStep&, const vislib::Frame&) {
        EXPECT_EQ(i, frames[schedule]++);  // in order, from 0
      });
  const vislib::GrowthRun merged = grow_near_region(s, rt, visible, cam, truth, plan.merged, g);
  const vislib::GrowthRun equal = grow_near_region(s, rt, visible, cam, truth, plan.equal, g);
  EXPECT_EQ(both.merged.radii, merged.radii);
  EXPECT_EQ(both.equal_area.radii, equal.radii);
  ASSERT_EQ(both.equal_area.steps.size(), equal.steps.size());
  EXPECT_GT(equal.steps.size(), 1u);
  EXPECT_EQ(both.merged.min_consecutive_ssim, merged.min_consecutive_ssim);
  EXPECT_EQ(both.equal_area.min_consecutive_ssim, equal.min_consecutive_ssim);
  EXPECT_EQ(frames["merged"], merged.steps.size());
  EXPECT_EQ(frames["equal_area"], equal.steps.size());
}
