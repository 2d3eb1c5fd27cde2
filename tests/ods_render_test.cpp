// Tests of the ODS renderers (vislib/render/ods_render.h) and of `pvs view --ods`.
#include "vislib/render/ods_render.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "scene_builders.h"
#include "test_support.h"
#include "vislib/eval/metrics.h"

namespace {

using pvs_runtime::Eye;
using vislib::Vec3;
using vislib_test::add_quad;

constexpr double kPi = 3.14159265358979323846;

// An axis-aligned box as 6 quads (6 objects).
void add_box(vislib::Scene& s, Vec3 lo, Vec3 hi) {
  const Vec3 a{lo.x, lo.y, lo.z}, b{hi.x, lo.y, lo.z}, c{hi.x, lo.y, hi.z}, d{lo.x, lo.y, hi.z};
  const Vec3 e{lo.x, hi.y, lo.z}, f{hi.x, hi.y, lo.z}, g{hi.x, hi.y, hi.z}, h{lo.x, hi.y, hi.z};
  add_quad(s, a, d, c, b), add_quad(s, e, f, g, h), add_quad(s, a, b, f, e);
  add_quad(s, d, h, g, c), add_quad(s, a, e, h, d), add_quad(s, b, c, g, f);
}

// A 12 x 3.2 x 12 m room (floor and ceiling in 1 m tiles, walls in 1 m strips) with boxes at
// 1.2-4 m from the centre `offset` + (0.3, 1.6, -0.2).
vislib::Scene make_room(Vec3 offset = {0, 0, 0}) {
  vislib::Scene s;
  auto o = [&](double x, double y, double z) { return Vec3{x, y, z} + offset; };
  for (int i = -6; i < 6; ++i)
    for (int j = -6; j < 6; ++j) {
      add_quad(s, o(i, 0, j), o(i, 0, j + 1), o(i + 1, 0, j + 1), o(i + 1, 0, j));
      add_quad(s, o(i, 3.2, j), o(i + 1, 3.2, j), o(i + 1, 3.2, j + 1), o(i, 3.2, j + 1));
    }
  for (int i = -6; i < 6; ++i) {
    add_quad(s, o(i, 0, -6), o(i + 1, 0, -6), o(i + 1, 3.2, -6), o(i, 3.2, -6));
    add_quad(s, o(i, 0, 6), o(i, 3.2, 6), o(i + 1, 3.2, 6), o(i + 1, 0, 6));
    add_quad(s, o(-6, 0, i), o(-6, 3.2, i), o(-6, 3.2, i + 1), o(-6, 0, i + 1));
    add_quad(s, o(6, 0, i), o(6, 0, i + 1), o(6, 3.2, i + 1), o(6, 3.2, i));
  }
  add_box(s, o(1.5, 0, 0.5), o(2.3, 1.2, 1.4));
  add_box(s, o(-2.5, 0.5, -1), o(-1.6, 2.4, -0.3));
  add_box(s, o(-0.4, 0.9, 1.4), o(0.6, 1.1, 2.0));
  add_box(s, o(0.8, 2.2, -3.8), o(2.0, 2.6, -3.0));
  add_box(s, o(-3.5, 0, 2.5), o(-2.5, 3.0, 3.5));
  return s;
}

const Vec3 kCentre{0.3, 1.6, -0.2};

std::vector<uint32_t> all_ids(const vislib::Scene& s) {
  std::vector<uint32_t> ids(s.triangle_count());
  for (uint32_t t = 0; t < ids.size(); ++t) ids[t] = t;
  return ids;
}

double agreement(const vislib::Frame& a, const vislib::Frame& b) {
  size_t same = 0;
  for (size_t p = 0; p < a.pixel_count(); ++p) same += a.tri[p] == b.tri[p];
  return double(same) / double(a.pixel_count());
}

// The ODS pixel ray written independently of runtime/ods.h: the direction from spherical
// coordinates of the pixel centre, the eye offset along normalize(forward x up) by Eq. 6 as the
// paper prints it (at the ray's latitude), with start = end read as no merging.
vislib::Frame independent_ods(const vislib::Scene& s, const vislib::EmbreeScene& rt, Vec3 centre,
                              double ipd, int sign, double start_deg, double end_deg,
                              double exponent, int w, int h) {
  vislib::Frame f;
  f.width = w, f.height = h;
  f.tri.assign(size_t(w) * h, vislib::kNoHit);
  for (int y = 0; y < h; ++y) {
    const double theta = kPi * (y + 0.5) / h;  // polar angle from +y
    const double lat = kPi / 2 - theta;
    double a = 1;
    if (start_deg != end_deg) {
      const double incl = std::fabs(lat) * 180 / kPi, ms = 90 - start_deg, me = 90 - end_deg;
      a = std::pow(1 - std::clamp((incl - ms) / (me - ms), 0.0, 1.0), exponent);
    }
    for (int x = 0; x < w; ++x) {
      const double phi = 2 * kPi * (x + 0.5) / w - kPi;  // longitude, turning right from +z
      const Vec3 d{-std::sin(theta) * std::sin(phi), std::cos(theta),
                   std::sin(theta) * std::cos(phi)};
      Vec3 fwd{d.x, 0, d.z};
      Vec3 right = cross(fwd, Vec3{0, 1, 0});
      right = right * (1.0 / length(right));
      const Vec3 eye = centre + right * (sign * 0.5 * ipd * a);
      f.tri[size_t(y) * w + x] = rt.first_hit(eye, d, vislib::kDefaultNear).tri;
    }
  }
  return f;
}

TEST(OdsRender, IndependentRayFormulaMatchesTheReference) {
  const vislib::Scene s = make_room();
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 512, set.height = 256;
  for (bool merge : {false, true}) {
    set.merge = merge ? pvs_runtime::PoleMerge{{45, 0, 3}, {30, 5, 1}} : pvs_runtime::PoleMerge{};
    for (Eye eye : {Eye::Left, Eye::Right}) {
      const vislib::Frame ref = vislib::render_ods_rays(s, rt, set, eye);
      // Independent: bottom pole parameters used for lat < 0.
      vislib::Frame ind = independent_ods(s, rt, kCentre, set.ipd, int(eye), 0, 0, 1, 512, 256);
      if (merge) {
        vislib::Frame top = independent_ods(s, rt, kCentre, set.ipd, int(eye), 45, 0, 3, 512, 256);
        vislib::Frame bottom =
            independent_ods(s, rt, kCentre, set.ipd, int(eye), 30, 5, 1, 512, 256);
        for (size_t p = 0; p < ind.pixel_count(); ++p)
          ind.tri[p] = p < ind.pixel_count() / 2 ? top.tri[p] : bottom.tri[p];
      }
      EXPECT_GE(agreement(ref, ind), 0.9999) << merge << " " << int(eye);
    }
  }
}

TEST(OdsRender, IpdZeroGivesIdenticalEyesEqualToAMonoPanorama) {
  const vislib::Scene s = make_room();
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.ipd = 0;
  set.width = 256, set.height = 128;
  const vislib::Frame l = vislib::render_ods_rays(s, rt, set, Eye::Left);
  const vislib::Frame r = vislib::render_ods_rays(s, rt, set, Eye::Right);
  EXPECT_EQ(l.tri, r.tri);
  EXPECT_EQ(l.rgb, r.rgb);
  EXPECT_EQ(l.depth, r.depth);
  // Mono: every ray from the centre.
  const vislib::Frame mono = independent_ods(s, rt, kCentre, 0, 1, 0, 0, 1, 256, 128);
  EXPECT_GE(agreement(l, mono), 0.9999);
  // And with IPD > 0 the eyes differ.
  set.ipd = 0.064;
  EXPECT_LT(agreement(vislib::render_ods_rays(s, rt, set, Eye::Left),
                      vislib::render_ods_rays(s, rt, set, Eye::Right)),
            0.999);
}

TEST(OdsRender, PoleMergingLowersLeftRightDisagreementTowardsThePoles) {
  const vislib::Scene s = make_room();
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 512, set.height = 256;
  auto curve = [&](const pvs_runtime::PoleMerge& m) {
    set.merge = m;
    return vislib::lr_disagreement_by_latitude(vislib::render_ods_rays(s, rt, set, Eye::Left),
                                               vislib::render_ods_rays(s, rt, set, Eye::Right), 5);
  };
  const auto none = curve({});
  const auto merged = curve({{45, 0, 1}, {45, 0, 1}});
  ASSERT_EQ(none.size(), 36u);
  // Without merging the eyes disagree most near the poles (the tiles straight above and below
  // turn by 2 asin(h/r_h)); with merging from 45 deg the disagreement falls to 0 at the poles.
  double none_polar = 0, merged_polar = 0;
  for (size_t b : {0, 1, 34, 35})
    none_polar += none[b].triangle_mismatch, merged_polar += merged[b].triangle_mismatch;
  EXPECT_GT(none_polar, 0.05);
  EXPECT_LT(merged_polar, 0.25 * none_polar);
  EXPECT_LE(merged[0].triangle_mismatch, none[0].triangle_mismatch);
  EXPECT_LE(merged[35].triangle_mismatch, none[35].triangle_mismatch);
  // Bands below 45 deg of latitude are not merged: identical curves there.
  for (size_t b = 9; b < 27; ++b)
    EXPECT_EQ(none[b].triangle_mismatch, merged[b].triangle_mismatch) << b;
  // Monotone fall from the start of merging to the pole (top side), allowing small noise.
  for (size_t b = 1; b < 9; ++b)
    EXPECT_LE(merged[b - 1].triangle_mismatch, merged[b].triangle_mismatch + 0.02) << b;
}

TEST(OdsRender, IdenticalForAnyThreadCount) {
  const vislib::Scene s = make_room();
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 256, set.height = 128;
  set.merge = {{45, 0, 1}, {45, 0, 1}};
  const vislib::Frame rays = vislib::render_ods_rays(s, rt, set, Eye::Left);
  const vislib::Frame raster = vislib::render_ods_raster(s, all_ids(s), set, Eye::Left, {});
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const vislib::Frame rays1 = vislib::render_ods_rays(s, rt, set, Eye::Left);
  const vislib::Frame raster1 = vislib::render_ods_raster(s, all_ids(s), set, Eye::Left, {});
  EXPECT_EQ(rays.tri, rays1.tri);
  EXPECT_EQ(rays.rgb, rays1.rgb);
  EXPECT_EQ(raster.tri, raster1.tri);
  EXPECT_EQ(raster.depth, raster1.depth);
}

// The BVH is re-centred at the panorama centre: the same room 1e5 m from the origin gives the same
// panorama (in float about the origin, 1e5 m has a 4 mm ulp: the 3.2 cm eye offset would be lost).
TEST(OdsRender, SceneFarFromTheOriginKeepsItsDisparity) {
  const Vec3 shift{1e5, 0, -1e5};
  const vislib::Scene near = make_room(), far = make_room(shift);
  vislib::EmbreeScene rt_near(near, 0.0, kCentre), rt_far(far, 0.0, kCentre + shift);
  vislib::OdsSettings set;
  set.width = 256, set.height = 128;
  for (Eye eye : {Eye::Left, Eye::Right}) {
    set.centre = kCentre;
    const vislib::Frame a = vislib::render_ods_rays(near, rt_near, set, eye);
    set.centre = kCentre + shift;
    const vislib::Frame b = vislib::render_ods_rays(far, rt_far, set, eye);
    EXPECT_GE(agreement(a, b), 0.999);
  }
}

// Coverage centroid (column, row) per triangle, for triangles away from the seam.
std::map<uint32_t, std::array<double, 3>> centroids(const vislib::Frame& f) {
  std::map<uint32_t, std::array<double, 3>> c;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const uint32_t t = f.tri[size_t(y) * f.width + x];
      if (t == vislib::kNoHit) continue;
      auto& a = c[t];
      a[0] += x + 0.5, a[1] += y + 0.5, a[2] += 1;
      if (x == 0 || x == f.width - 1) a[2] = -1e9;  // touches the seam: excluded
    }
  return c;
}

// Largest centroid distance (pixels) over triangles with >= min_pixels in both frames and whose
// rows stay within `max_lat_deg` of the equator.
double max_centroid_error(const vislib::Frame& ref, const vislib::Frame& test, int min_pixels,
                          double max_lat_deg) {
  const auto a = centroids(ref), b = centroids(test);
  double worst = 0;
  for (const auto& [t, ca] : a) {
    auto it = b.find(t);
    if (it == b.end() || ca[2] < min_pixels || it->second[2] < min_pixels) continue;
    const double ya = ca[1] / ca[2];
    const double lat = 90 - 180 * ya / ref.height;
    if (std::fabs(lat) > max_lat_deg) continue;
    worst = std::max(worst, std::hypot(ca[0] / ca[2] - it->second[0] / it->second[2],
                                       ya - it->second[1] / it->second[2]));
  }
  return worst;
}

TEST(OdsRender, RasterExactWithinHalfAPixelOfRaysBeyondOneMetre) {
  const vislib::Scene s = make_room();  // every surface >= 1 m from the centre
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 512, set.height = 256;
  vislib::OdsRasterSettings exact;
  for (Eye eye : {Eye::Left, Eye::Right}) {
    const vislib::Frame ref = vislib::render_ods_rays(s, rt, set, eye);
    vislib::OdsRasterStats st;
    const vislib::Frame ras = vislib::render_ods_raster(s, all_ids(s), set, eye, exact, &st);
    EXPECT_EQ(st.input_triangles, s.triangle_count());
    // The floor and ceiling around the axis: the parts inside the viewing circle are seen by no
    // ray and dropped; what surrounds them is drawn up to the pole rows.
    EXPECT_GT(st.dropped_inside_circle, 0u);
    EXPECT_GE(agreement(ref, ras), 0.99);
    EXPECT_LE(max_centroid_error(ref, ras, 40, 75), 0.5);
  }
}

// Close to the viewing circle the paper's Eq. 5 misplaces what the exact projection places right.
TEST(OdsRender, RasterPaperFormulaErrsNearTheViewingCircle) {
  vislib::Scene s = make_room();
  // A 4 cm card 8 cm in front of the centre, 2 cm above eye level.
  add_quad(s, kCentre + Vec3{-0.02, 0.0, 0.08}, kCentre + Vec3{0.02, 0.0, 0.08},
           kCentre + Vec3{0.02, 0.04, 0.08}, kCentre + Vec3{-0.02, 0.04, 0.08});
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 512, set.height = 256;
  const vislib::Frame ref = vislib::render_ods_rays(s, rt, set, Eye::Right);
  vislib::OdsRasterSettings paper, exact;
  paper.formula = vislib::OdsFormula::Paper;
  vislib::OdsRasterStats paper_stats;
  const vislib::Frame p =
      vislib::render_ods_raster(s, all_ids(s), set, Eye::Right, paper, &paper_stats);
  EXPECT_GT(paper_stats.pole_triangles,
            0u);  // Eq. 5 places the floor under the centre: pole strips
  EXPECT_EQ(paper_stats.dropped_inside_circle, 0u);
  const vislib::Frame e = vislib::render_ods_raster(s, all_ids(s), set, Eye::Right, exact);
  const double err_paper = max_centroid_error(ref, p, 40, 75),
               err_exact = max_centroid_error(ref, e, 40, 75);
  EXPECT_LE(err_exact, 0.5);
  EXPECT_GE(err_paper, 1.5);
}

// Static tessellation 1 (none) bends no edge: long edges far from the equator go wrong, which
// Alg. 1's dynamic levels fix.
TEST(OdsRender, DynamicTessellationBeatsNoTessellation) {
  const vislib::Scene s = make_room();
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 512, set.height = 256;
  const vislib::Frame ref = vislib::render_ods_rays(s, rt, set, Eye::Left);
  vislib::OdsRasterSettings none, dynamic;
  none.static_level = 1;
  vislib::OdsRasterStats sn, sd;
  const double a_none =
      agreement(ref, vislib::render_ods_raster(s, all_ids(s), set, Eye::Left, none, &sn));
  const double a_dyn =
      agreement(ref, vislib::render_ods_raster(s, all_ids(s), set, Eye::Left, dynamic, &sd));
  EXPECT_GT(a_dyn, a_none);
  EXPECT_GE(a_dyn, 0.99);
  EXPECT_GT(sd.tessellated, sn.tessellated);
}

TEST(OdsRender, SeamIsContinuousInBothMethods) {
  const vislib::Scene s = make_room();
  vislib::EmbreeScene rt(s, 0.0, kCentre);
  vislib::OdsSettings set;
  set.centre = kCentre;
  set.width = 512, set.height = 256;
  for (const vislib::Frame& f : {vislib::render_ods_rays(s, rt, set, Eye::Left),
                                 vislib::render_ods_raster(s, all_ids(s), set, Eye::Left, {})}) {
    const vislib::SeamContinuity c = vislib::seam_continuity(f);
    EXPECT_LE(c.seam_triangle_mismatch, 3 * c.typical_triangle_mismatch + 0.01);
    EXPECT_LE(c.seam_mean_abs_rgb, 3 * c.typical_mean_abs_rgb + 1);
  }
}

nlohmann::json read_json(const std::string& path) {
  return nlohmann::json::parse(std::ifstream(path));
}

TEST(PvsViewOds, WritesPanoramasAndMetricsOnABakedCity) {
  using vislib_test::run_pvs;
  const std::string dir = vislib_test::temp_dir("pvs_view_ods");
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
  const std::string base =
      "view " + dir + "/city.pvs --scene " + dir + "/city.glb --ods --ods-size 128 ";
  ASSERT_EQ(run_pvs(base + "--at 5,1.6,5 --pole-merge 45,0,1 -o " + dir + "/o.png --json " + dir +
                        "/o.json",
                    &out),
            0)
      << out;
  for (const char* name :
       {"/o.png", "/o_left.png", "/o_right.png", "/o_anaglyph.png", "/o_truth.png"})
    EXPECT_TRUE(std::ifstream(dir + name).good()) << name;
  nlohmann::json j = read_json(dir + "/o.json")["ods"];
  for (const char* eye : {"left", "right"}) {
    for (const char* key : {"epsilon", "psnr", "ssim", "triangle_mismatch"})
      EXPECT_TRUE(j[eye].contains(key)) << key;
    // The cell's PVS panorama against the full-scene one: the PVS misses (almost) nothing.
    EXPECT_LE(j[eye]["triangle_mismatch"].get<double>(), 1e-3) << eye;
    EXPECT_TRUE(j["seam"][eye].contains("triangle_mismatch"));
  }
  EXPECT_EQ(j["lr_disagreement_by_latitude"].size(), 36u);
  EXPECT_EQ(j["lr_disagreement_by_latitude"][0]["triangle_mismatch"].get<double>(),
            0.0);  // merged at the pole
  EXPECT_EQ(j["cells_used"].size(), 1u);
  EXPECT_TRUE(j["disc_in_cell_view_region"].get<bool>());
  EXPECT_TRUE(j["disc_covered"].get<bool>());
  EXPECT_EQ(j["counts"]["left"]["rays"].get<size_t>(), 128u * 64u);
  EXPECT_DOUBLE_EQ(j["pole_merge"]["top"]["start_deg"].get<double>(), 45.0);

  // A disc across the corner of four cells: the union of the cells it touches.
  ASSERT_EQ(run_pvs(base + "--at 0.01,1.6,0.02 --ods-method raster-exact -o " + dir +
                        "/c.png --json " + dir + "/c.json",
                    &out),
            0)
      << out;
  j = read_json(dir + "/c.json")["ods"];
  EXPECT_FALSE(j["disc_in_cell_view_region"].get<bool>());
  EXPECT_EQ(j["cells_used"].size(), 4u);
  EXPECT_TRUE(j["disc_covered"].get<bool>());
  EXPECT_GT(j["counts"]["left"]["tessellated"].get<size_t>(), 0u);
  for (const char* eye : {"left", "right"})
    EXPECT_LE(j["truth_against_rays"][eye]["triangle_mismatch"].get<double>(), 0.01) << eye;

  // Bad options: exit 2, nothing written.
  EXPECT_EQ(run_pvs(base + "--at 5,1.6,5 --pole-merge 10,20,1 -o " + dir + "/bad.png", &out), 2)
      << out;
  EXPECT_EQ(
      run_pvs(base + "--at 5,1.6,5 --ods-size 130 --ods-method nope -o " + dir + "/bad.png", &out),
      2)
      << out;
  EXPECT_FALSE(std::ifstream(dir + "/bad.png").good());
  // Without --ods, --look is still required.
  EXPECT_EQ(run_pvs("view " + dir + "/city.pvs --scene " + dir + "/city.glb --at 5,1.6,5 -o " +
                        dir + "/n.png",
                    &out),
            2)
      << out;
}

// One walkable 8 m cell on the hill at the town's (-36, -36) corner, and an eye inside its view
// region (eye band 2.4-6.8 m there).
constexpr const char* TOWN_BAKE = "--walkable --box -40,-10,-40,-32,20,-32 --cell-size 8";
constexpr const char* TOWN_EYE = "-36,4,-36";

TEST(PvsViewOds, TruckTownCellAgainstTheFullScene) {
  VISLIB_REQUIRE_SHARED(shared);
  using vislib_test::run_pvs;
  const std::string dir = vislib_test::temp_dir("pvs_view_ods_town");
  const std::string town = shared + "/scenes/godot_truck_town/town_model.gltf";
  std::string out;
  ASSERT_EQ(
      run_pvs("bake " + town + " " + std::string(TOWN_BAKE) + " --res 64 -o " + dir + "/town.pvs",
              &out),
      0)
      << out;
  ASSERT_EQ(run_pvs("view " + dir + "/town.pvs --scene " + town + " --at " + std::string(TOWN_EYE) +
                        " --ods --ods-size 256 --pole-merge 45,0,3 -o " + dir + "/t.png --json " +
                        dir + "/t.json",
                    &out),
            0)
      << out;
  const nlohmann::json j = read_json(dir + "/t.json")["ods"];
  EXPECT_TRUE(j["disc_covered"].get<bool>());
  EXPECT_LT(j["triangles"]["visible"].get<size_t>(), j["triangles"]["scene"].get<size_t>());
  for (const char* eye : {"left", "right"})
    EXPECT_LE(j[eye]["triangle_mismatch"].get<double>(), 2e-3) << eye;
}

}  // namespace
