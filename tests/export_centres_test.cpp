// pvs export --centres: every cell's near-far centre for the web client, which must be the one
// `pvs view` chooses without --centre (the oracle: pvs view's --json, cell by cell), and a PVS
// baked for another scene refused with exit 2 and no output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

using namespace vislib_test;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

json read_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

}  // namespace

TEST(ExportCentres, EveryCellsCentreIsPvsViewsChoice) {
  const std::string dir = temp_dir("export_centres");
  const std::string city = dir + "/city.glb", pvs = dir + "/city.pvs";
  std::string out;
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 -q -o " + city, &out), 0) << out;
  // 4 grid cells at a tiny resolution; their view regions' centres lie in the blocks' corners.
  ASSERT_EQ(
      run_pvs("bake " + city +
                  " --box -30,0,-30,30,3,30 --grid 2,1,2 --eye-height 1.5,1.8 --res 16 -q -o " +
                  pvs,
              &out),
      0)
      << out;
  ASSERT_EQ(run_pvs("export " + city + " -q -o " + dir + "/scene.glb --pvs " + pvs + " --centres " +
                        dir + "/centres.json",
                    &out),
            0)
      << out;
  const json c = read_json(dir + "/centres.json");
  EXPECT_EQ(c["format"], "vislib-view-centres 1");
  ASSERT_EQ(c["cell_count"], 4);
  ASSERT_EQ(c["centres"].size(), 4u);
  EXPECT_FALSE(c["moved"].empty());  // some region centre lies in a block: moved to a free point
  const char* points[] = {"-15,1.6,-15", "15,1.6,-15", "-15,1.6,15", "15,1.6,15"};
  int seen = 0;
  for (const char* p : points) {
    ASSERT_EQ(run_pvs("view " + pvs + " --scene " + city + " --at " + p +
                          " --look 0,1.6,0 --frame 16x12 --env-size 8 -q -o " + dir +
                          "/v.png --json " + dir + "/v.json",
                      &out),
              0)
        << out;
    const json v = read_json(dir + "/v.json");
    const int cell = v["cell"];
    ASSERT_GE(cell, 0);
    ASSERT_LT(cell, 4);
    EXPECT_EQ(c["centres"][cell], v["centre"]) << "cell " << cell;
    seen |= 1 << cell;
  }
  EXPECT_EQ(seen, 15);
}

TEST(ExportCentres, PvsOfAnotherSceneIsRefusedWithNoOutput) {
  const std::string dir = temp_dir("export_centres_other");
  const std::string a = dir + "/a.glb", b = dir + "/b.glb", pvs = dir + "/a.pvs";
  std::string out;
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 -q -o " + a, &out), 0) << out;
  ASSERT_EQ(run_pvs("generate city --blocks 1,2 -q -o " + b, &out), 0) << out;
  ASSERT_EQ(
      run_pvs("bake " + a + " --box -30,0,-30,30,3,30 --grid 1,1,1 --res 8 -q -o " + pvs, &out), 0)
      << out;
  EXPECT_EQ(run_pvs("export " + b + " -q -o " + dir + "/b_scene.glb --pvs " + pvs + " --centres " +
                        dir + "/b_centres.json",
                    &out),
            2)
      << out;
  EXPECT_NE(out.find(pvs), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir + "/b_scene.glb"));
  EXPECT_FALSE(fs::exists(dir + "/b_centres.json"));
  EXPECT_EQ(
      run_pvs("export " + a + " -q -o " + dir + "/a.glb2.glb --centres " + dir + "/x.json", &out),
      2)
      << out;  // --centres without --pvs
}
