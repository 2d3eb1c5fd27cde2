// Tests of `pvs check` (vislib/eval/pvs_check.h): the sampled ground truth of a bake. On a
// generated city: a set holding every triangle has no miss, an empty set misses exactly what the
// eyes see, and one visible triangle removed from a full set is found and confirmed by the
// double-precision re-cast; eyes drawn inside a solid cube are drawn again and counted (and given
// up in a region the cube encloses). Through the CLI: a grid bake of a small generated city checks
// at 0 misses with --fail-on-miss (at check pixels coarser than the bake's), the same file with one
// cell's set emptied fails with exit 1 and names that cell, the JSON does not depend on the thread
// count, and bad inputs exit 2 naming the file. `pvs inspect --at` prints a cell's visible count
// once.
#include "vislib/eval/pvs_check.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pvs_format/pvs_format.h"
#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/bake/free_space.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using namespace vislib_test;
using json = nlohmann::json;

namespace {

Scene small_city() {
  CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  return generate_city(o);
}

std::vector<uint32_t> all_ids(const Scene& s) {
  std::vector<uint32_t> v(s.triangle_count());
  for (uint32_t t = 0; t < v.size(); ++t) v[t] = t;
  return v;
}

// A closed cube [-h, h]^3 with outward faces ((b - a) x (c - a) points out).
Scene cube(double h) {
  Scene s;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) {
      Vec3 n{0, 0, 0}, u{0, 0, 0}, v{0, 0, 0};
      n[axis] = sign * h;
      u[(axis + 1) % 3] = h;
      v[(axis + 2) % 3] = h;
      if (sign < 0) std::swap(u, v);
      add_quad(s, n - u - v, n + u - v, n + u + v, n - u + v);
    }
  return s;
}

PvsCheckOptions check_options(int samples, int resolution) {
  PvsCheckOptions o;
  o.samples = samples;
  o.sample.resolution = resolution;
  o.seed = 7;
  return o;
}

}  // namespace

TEST(PvsCheck, AFullSetHasNoMissAndARemovedVisibleTriangleIsFoundAndConfirmed) {
  const Scene city = small_city();
  // A street-level box at the centre crossing; eyes inside buildings are drawn again.
  const std::vector<EyeRegion> regions = {box_eye_region({{-4, 1.5, -4}, {4, 1.8, 4}})};
  PvsCheckOptions o = check_options(3, 32);
  o.in_solid = [&](Vec3 p) { return point_enclosed(city, p); };

  const PvsCheckCell full = pvs_check(city, regions, {all_ids(city)}, o).cells[0];
  EXPECT_EQ(full.eyes, 3);
  EXPECT_EQ(full.tally.rays, uint64_t(3 * 6 * 32 * 32));
  EXPECT_EQ(full.miss_rays, 0u);
  EXPECT_TRUE(full.missed.empty());

  // An empty set: every hit the re-cast sees is a miss.
  const PvsCheckCell empty = pvs_check(city, regions, {{}}, o).cells[0];
  ASSERT_FALSE(empty.missed.empty());
  EXPECT_EQ(empty.tally.rays, full.tally.rays);
  EXPECT_EQ(empty.miss_rays + empty.tally.ambiguous + empty.tally.no_hit, empty.tally.rays);
  const auto most = *std::max_element(empty.missed.begin(), empty.missed.end(),
                                      [](auto a, auto b) { return a.second < b.second; });

  // The full set without that triangle: it, and only it, is missed.
  std::vector<uint32_t> planted = all_ids(city);
  planted.erase(std::find(planted.begin(), planted.end(), most.first));
  const PvsCheckCell cell = pvs_check(city, regions, {planted}, o).cells[0];
  ASSERT_EQ(cell.missed.size(), 1u);
  EXPECT_EQ(cell.missed[0].first, most.first);
  EXPECT_GT(cell.missed[0].second, 0u);
  EXPECT_LE(cell.missed[0].second, most.second);
  EXPECT_EQ(cell.miss_rays, cell.missed[0].second);
  const PvsCheckTotals t = pvs_check_totals({{cell}});
  EXPECT_EQ(t.missed_triangles, 1u);
  EXPECT_EQ(t.cells_with_misses, 1u);
}

TEST(PvsCheck, EyesInsideASolidAreDrawnAgainAndCounted) {
  const Scene box = cube(1);
  PvsCheckOptions o = check_options(16, 4);
  o.in_solid = [&](Vec3 p) { return point_enclosed(box, p); };
  // Half of this region lies inside the cube.
  const std::vector<EyeRegion> half = {box_eye_region({{-3, -0.5, -0.5}, {1, 0.5, 0.5}})};
  const PvsCheckCell c = pvs_check(box, half, {all_ids(box)}, o).cells[0];
  EXPECT_EQ(c.eyes, 16);
  EXPECT_GT(c.eyes_redrawn, 0u);
  EXPECT_EQ(c.eyes_given_up, 0);
  EXPECT_EQ(c.tally.rays, uint64_t(16 * 6 * 4 * 4));
  // Without the free-space test nothing is drawn again.
  o.in_solid = {};
  EXPECT_EQ(pvs_check(box, half, {all_ids(box)}, o).cells[0].eyes_redrawn, 0u);
  // A region the cube encloses: every draw is rejected and every eye given up.
  o.in_solid = [&](Vec3 p) { return point_enclosed(box, p); };
  const std::vector<EyeRegion> inside = {box_eye_region({{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}})};
  const PvsCheckCell d = pvs_check(box, inside, {all_ids(box)}, o).cells[0];
  EXPECT_EQ(d.eyes, 0);
  EXPECT_EQ(d.eyes_given_up, 16);
  EXPECT_EQ(d.eyes_redrawn, uint64_t(16 * kEyeRedraws));
  EXPECT_EQ(d.tally.rays, 0u);
}

namespace {

// A grid bake of a generated 2 x 2 city (16 street-level cells) at N = 64, made once. It is
// checked at N = 24: pixels coarser than the bake's, so that no triangle seen by a check pixel is
// smaller than the bake's pixels (checked at the bake's own N it has 2 miss rays on sub-pixel
// triangles).
struct CheckFixture {
  std::string dir, city, pvs;
};
const CheckFixture& fixture() {
  static const CheckFixture made = [] {
    CheckFixture f;
    f.dir = temp_dir("pvs_check_cli");
    f.city = f.dir + "/city.glb";
    f.pvs = f.dir + "/city.pvs";
    std::string out;
    EXPECT_EQ(run_pvs("generate city --blocks 2,2 -o " + f.city, &out), 0) << out;
    EXPECT_EQ(run_pvs("bake " + f.city +
                          " --box -60,0,-60,60,3,60 --grid 4,1,4 --eye-height 1.5,1.8 --res 64 "
                          "-q -o " +
                          f.pvs,
                      &out),
              0)
        << out;
    return f;
  }();
  return made;
}

}  // namespace

TEST(PvsCheckCli, AGridBakeOfASmallCityHasNoSampledMissAndTheJsonIgnoresThreads) {
  const CheckFixture& f = fixture();
  std::string out;
  ASSERT_EQ(
      run_pvs("check " + f.pvs + " " + f.city +
                  " --samples 2 --sample-res 24 --fail-on-miss -j 1 --json " + f.dir + "/j1.json",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("misses               0 rays"), std::string::npos) << out;
  ASSERT_EQ(run_pvs("check -q " + f.pvs + " " + f.city +
                        " --samples 2 --sample-res 24 -j 2 --json " + f.dir + "/j2.json",
                    &out),
            0)
      << out;
  const std::string j1 = read_file(f.dir + "/j1.json");
  EXPECT_EQ(j1, read_file(f.dir + "/j2.json"));
  const json j = json::parse(j1);
  EXPECT_EQ(j["totals"]["cells"], 16);
  EXPECT_EQ(j["totals"]["eyes"].get<int>() + j["totals"]["eyes_given_up"].get<int>(), 32);
  EXPECT_EQ(j["totals"]["miss_rays"], 0);
  EXPECT_EQ(j["resolution"], 24);
  EXPECT_EQ(j["per_cell"].size(), 16u);
  EXPECT_TRUE(j["per_triangle"].empty());
}

TEST(PvsCheckCli, ACellWithItsSetEmptiedFailsOnMissAndIsNamed) {
  const CheckFixture& f = fixture();
  pvs::Reader r = pvs::Reader::from_file(f.pvs);
  std::vector<pvs::CellSet> sets;
  for (uint32_t c = 0; c < r.cell_count(); ++c) sets.emplace_back(r.read_cell(c));
  const uint32_t planted = 5;
  sets[planted] = std::vector<uint32_t>{};
  const std::string bad = f.dir + "/planted.pvs";
  write_file_atomic(bad, pvs::write_pvs(r.info(), sets));
  std::string out, err;
  ASSERT_EQ(run_pvs_split("check " + bad + " " + f.city +
                              " --samples 2 --sample-res 24 --fail-on-miss --json -",
                          &out, &err),
            1)
      << out << err;
  EXPECT_NE(err.find("check failed"), std::string::npos) << err;
  const json j = json::parse(out);
  EXPECT_GT(j["totals"]["miss_rays"].get<int>(), 0);
  EXPECT_EQ(j["totals"]["cells_with_misses"], 1);
  for (const json& c : j["per_cell"])
    EXPECT_EQ(c["missed"].empty(), c["cell"] != planted) << c.dump();
  for (const json& t : j["per_triangle"]) EXPECT_EQ(t["cells"], json::array({planted}));
  // Without --fail-on-miss the same file exits 0 with its summary.
  EXPECT_EQ(run_pvs("check " + bad + " " + f.city + " --samples 2 --sample-res 24", &out), 0)
      << out;
  EXPECT_NE(out.find("in 1 cell\n"), std::string::npos) << out;
}

TEST(PvsCheckCli, BadInputsExitWithCode2AndNameTheFile) {
  const CheckFixture& f = fixture();
  std::string out;
  const std::string missing = f.dir + "/missing.pvs";
  EXPECT_EQ(run_pvs("check " + missing + " " + f.city, &out), 2) << out;
  EXPECT_NE(out.find(missing), std::string::npos) << out;
  const std::string garbage = f.dir + "/garbage.pvs";
  write_file_atomic(garbage, "not a pvs file at all");
  EXPECT_EQ(run_pvs("check " + garbage + " " + f.city, &out), 2) << out;
  EXPECT_NE(out.find(garbage), std::string::npos) << out;
  const std::string other = f.dir + "/other.glb";
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 --seed 2 -o " + other, &out), 0) << out;
  EXPECT_EQ(run_pvs("check " + f.pvs + " " + other, &out), 2) << out;
  EXPECT_NE(out.find(f.pvs), std::string::npos) << out;
  EXPECT_NE(out.find("fingerprints differ"), std::string::npos) << out;
  const std::string no_scene = f.dir + "/no_scene.glb";
  EXPECT_EQ(run_pvs("check " + f.pvs + " " + no_scene, &out), 2) << out;
  EXPECT_NE(out.find(no_scene), std::string::npos) << out;
}

TEST(CliInspect, AtPrintsTheVisibleCountOnce) {
  const CheckFixture& f = fixture();
  std::string out;
  ASSERT_EQ(run_pvs("inspect " + f.pvs + " --scene " + f.city + " --at 0,1.6,0", &out), 0) << out;
  std::istringstream lines(out);
  int visible = 0;
  for (std::string line; std::getline(lines, line);)
    if (line.find("visible") != std::string::npos) ++visible;
  EXPECT_EQ(visible, 1) << out;
  EXPECT_NE(out.find("  visible: "), std::string::npos) << out;
}
