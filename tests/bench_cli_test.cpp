// Tests of `pvs bench`: a small run on a generated city writes the CSV, JSON, frames and (when
// matplotlib is there) plots; bad options exit with code 2; a Python without matplotlib only
// skips the plots, with a clear message.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"
#include "vislib/base/file_util.h"

using namespace vislib_test;
using json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

// Small settings: the whole run takes a few seconds.
const char* kSmall =
    " --box -3,1.7,-20,3,1.7,20 --res 48 --segment-runs 2 --point-runs 16 --views 2 --frame 64x48";

std::string small_city(const std::string& dir) {
  const std::string city = dir + "/city.glb";
  std::string out;
  EXPECT_EQ(run_pvs("generate city --blocks 2,2 -o " + city, &out), 0) << out;
  return city;
}

bool matplotlib_available() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
}

}  // namespace

TEST(BenchCli, SmallCityWritesJsonWithTheRequiredKeys) {
  const std::string dir = temp_dir("bench_cli");
  const std::string city = small_city(dir);
  std::string out;
  ASSERT_EQ(run_pvs("bench " + city + kSmall + " --out " + dir + "/b", &out), 0) << out;
  const json j = json::parse(vislib::read_file(dir + "/b/bench.json"));
  for (const char* key : {"equal_time_share", "equal_quality_time_ratio", "segment", "point",
                          "equal_time", "equal_quality", "timings"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(j["equal_time_share"].is_number());
  for (const char* method : {"segment", "point"})
    for (const char* key : {"epsilon", "psnr", "ssim", "found", "seconds"})
      EXPECT_TRUE(j[method].contains(key)) << method << "." << key;
  EXPECT_GE(j["segment"]["epsilon"].get<double>(), 0.0);
  EXPECT_LE(j["segment"]["ssim"].get<double>(), 1.0);
  EXPECT_EQ(j["settings"]["point_runs"], 16);
  EXPECT_EQ(j["settings"]["perimeter_segments"], 4);
  for (const char* f :
       {"growth_segment.csv", "growth_point.csv", "quality.csv", "quality_views.csv", "views.csv",
        "frames/view0_truth.png", "frames/view0_truth_depth.exr", "frames/view1_point_heat.png"})
    EXPECT_TRUE(fs::exists(dir + "/b/" + f)) << f;
  // growth_point.csv: header and one row per run.
  std::ifstream csv(dir + "/b/growth_point.csv");
  std::string line;
  int rows = -1;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 16);
  if (matplotlib_available()) {
    EXPECT_TRUE(fs::exists(dir + "/b/found_vs_seconds.png")) << out;
    EXPECT_TRUE(fs::exists(dir + "/b/epsilon_vs_seconds.png")) << out;
    EXPECT_EQ(j["files"]["plots"].size(), 3u);
  }
}

TEST(BenchCli, PythonWithoutMatplotlibSkipsOnlyThePlots) {
  const std::string dir = temp_dir("bench_cli_nompl");
  const std::string city = small_city(dir);
  // /usr/bin/python3 -S does not load site-packages, so matplotlib cannot be imported.
  const std::string python = dir + "/python-without-matplotlib";
  vislib::write_file_atomic(python, "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n");
  fs::permissions(python, fs::perms::owner_all);
  std::string out;
  ASSERT_EQ(
      run_pvs("bench " + city + kSmall + " --no-frames --python " + python + " --out " + dir + "/b",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("matplotlib"), std::string::npos) << out;
  EXPECT_NE(out.find("python3-matplotlib"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir + "/b/bench.json"));
  EXPECT_FALSE(fs::exists(dir + "/b/found_vs_seconds.png"));
  EXPECT_FALSE(fs::exists(dir + "/b/frames"));
}

TEST(BenchCli, BadOptionsExitWithCode2) {
  const std::string dir = temp_dir("bench_cli_bad");
  std::string out;
  EXPECT_EQ(run_pvs("bench " + dir + "/missing.glb --box 0,0,0,1,1,1 --out " + dir + "/b", &out), 2)
      << out;
  EXPECT_NE(out.find("missing.glb"), std::string::npos) << out;
  const std::string city = small_city(dir);
  EXPECT_EQ(run_pvs("bench " + city + " --box 1,2,3 --out " + dir + "/b", &out), 2) << out;
  EXPECT_NE(out.find("--box"), std::string::npos) << out;
  EXPECT_EQ(run_pvs("bench " + city + " --box 0,0,0,1,1,1 --frame 8x8 --out " + dir + "/b", &out),
            2)
      << out;
  EXPECT_EQ(run_pvs("bench --help", &out), 0);
  EXPECT_NE(out.find("--segment-runs"), std::string::npos);
}
