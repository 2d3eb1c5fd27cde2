// Tests of `pvs bake`, `pvs merge` and `pvs inspect` as a user runs them: a bake killed with -9
// and resumed gives the same bytes as an uninterrupted one, shards merge byte-identically, thread
// counts do not change the file, and inspect/export work on a generated city.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "tests/test_support.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import.h"

extern char** environ;

using namespace vislib_test;
using json = nlohmann::json;

namespace {

// A 2 x 2 block city (866 triangles), generated once per test binary run.
const std::string& city() {
  static const std::string path = [] {
    std::string p = temp_dir("cli_bake_city") + "/city.glb";
    std::string out;
    EXPECT_EQ(run_pvs("generate city --blocks 2,2 -o " + p, &out), 0) << out;
    return p;
  }();
  return path;
}

// 16 grid cells over the middle of the city, at a small resolution.
std::string grid_bake(const std::string& out) {
  return "bake " + city() + " --box -60,0,-60,60,3,60 --grid 4,1,4 --eye-height 1.5,1.8 --res 24 -o " + out;
}

// Complete records in a checkpoint file (24-byte header, then size/cell/payload/CRC records).
int checkpoint_records(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return 0;
  std::string f = vislib::read_file(path);
  int n = 0;
  size_t at = 24;
  while (f.size() >= at + 12) {
    uint32_t size;
    std::memcpy(&size, f.data() + at, 4);
    if (f.size() < at + 12 + size) break;
    ++n;
    at += 12 + size;
  }
  return n;
}

}  // namespace

TEST(CliBake, KilledBakeResumesToTheSameBytes) {
  std::string dir = temp_dir("cli_bake_kill");
  std::string out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/whole.pvs"), &out), 0) << out;

  // Start the same bake as a child process and kill -9 it once a few cells are checkpointed.
  std::string target = dir + "/killed.pvs";
  std::vector<std::string> args = {"pvs", "bake", city(), "--box", "-60,0,-60,60,3,60", "--grid", "4,1,4",
                                   "--eye-height", "1.5,1.8", "--res", "24", "--threads", "1", "-o", target};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid;
  ASSERT_EQ(posix_spawn(&pid, VISLIB_PVS_EXE, &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
  auto start = std::chrono::steady_clock::now();
  bool finished_early = false;
  while (checkpoint_records(target + ".ckpt") < 3) {
    int status;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      finished_early = true;
      break;
    }
    ASSERT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60)) << "no checkpoint records";
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_FALSE(finished_early) << "the bake finished before it could be killed";
  kill(pid, SIGKILL);
  int status;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_FALSE(std::filesystem::exists(target)) << "a killed bake must not leave an output file";
  int saved = checkpoint_records(target + ".ckpt");
  ASSERT_GE(saved, 3);

  // Without --resume the checkpoint is protected.
  ASSERT_EQ(run_pvs(grid_bake(target), &out), 2) << out;
  EXPECT_NE(out.find("--resume"), std::string::npos) << out;
  // With --resume: the same bytes as the uninterrupted bake, and the finished cells were kept.
  ASSERT_EQ(run_pvs(grid_bake(target) + " --resume --threads 2", &out), 0) << out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("\\((\\d+) baked, (\\d+) resumed\\)"))) << out;
  EXPECT_GE(std::stoi(m[2]), saved);
  EXPECT_EQ(std::stoi(m[1]) + std::stoi(m[2]), 16);
  EXPECT_EQ(vislib::read_file(target), vislib::read_file(dir + "/whole.pvs"));
  EXPECT_FALSE(std::filesystem::exists(target + ".ckpt"));
}

TEST(CliBake, ShardsMergeByteIdenticallyAndThreadsDoNotMatter) {
  std::string dir = temp_dir("cli_bake_shards");
  std::string out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/one.pvs") + " --threads 1", &out), 0) << out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/two.pvs") + " --threads 2", &out), 0) << out;
  EXPECT_EQ(vislib::read_file(dir + "/one.pvs"), vislib::read_file(dir + "/two.pvs"));
  std::string shards;
  for (int i = 0; i < 3; ++i) {
    std::string s = dir + "/shard" + std::to_string(i) + ".pvs";
    ASSERT_EQ(run_pvs(grid_bake(s) + " --shard " + std::to_string(i) + "/3", &out), 0) << out;
    shards = s + " " + shards;
  }
  ASSERT_EQ(run_pvs("merge " + shards + "-o " + dir + "/merged.pvs", &out), 0) << out;
  EXPECT_EQ(vislib::read_file(dir + "/merged.pvs"), vislib::read_file(dir + "/one.pvs"));
  // A missing shard is an error naming the cell.
  ASSERT_EQ(run_pvs("merge " + dir + "/shard0.pvs " + dir + "/shard1.pvs -o " + dir + "/bad.pvs", &out), 2) << out;
  EXPECT_NE(out.find("absent from every shard"), std::string::npos) << out;
  EXPECT_EQ(run_pvs(grid_bake(dir + "/x.pvs") + " --shard 3/3", &out), 2) << out;
}

TEST(CliBake, InspectSummarisesAndExportsACellOfAGeneratedCity) {
  std::string dir = temp_dir("cli_inspect");
  std::string pvs = dir + "/city.pvs", out;
  ASSERT_EQ(run_pvs("bake " + city() + " --walkable --cell-size 20 --box -40,-1,-40,40,2,40 --res 24 -o " + pvs, &out), 0) << out;
  ASSERT_EQ(run_pvs("inspect --json " + pvs, &out), 0) << out;
  json s = json::parse(out);
  const unsigned cells = s["cells"];
  EXPECT_EQ(cells, 16u);  // 4 x 4 columns of street level, roofs are outside the box
  EXPECT_EQ(s["universe"], 866);
  uint64_t blocks = 0, counted = 0;
  for (auto& [name, m] : s["compression"].items()) {
    blocks += m["bytes"].get<uint64_t>();
    counted += m["cells"].get<uint64_t>();
  }
  EXPECT_EQ(blocks, s["bytes"]["blocks"].get<uint64_t>());
  EXPECT_EQ(counted, cells);
  unsigned hist = 0;
  for (unsigned h : s["histogram"]["cells"]) hist += h;
  EXPECT_EQ(hist, cells);
  EXPECT_EQ(s["metadata"]["resolution"], 24);

  // One cell, by point, with the scene: export the visible triangles and read them back.
  std::string glb = dir + "/cell.glb";
  ASSERT_EQ(run_pvs("inspect " + pvs + " --at 0,1.6,0 --json --scene " + city() + " --export-gltf " + glb, &out), 0) << out;
  json c = json::parse(out);
  EXPECT_EQ(c["boundary_segments"].size(), 8u);
  EXPECT_GT(c["visible_count"].get<int>(), 0);
  EXPECT_EQ(c["visible"].size(), c["visible_count"].get<size_t>());
  vislib::Scene exported = vislib::load_scene(glb);
  EXPECT_EQ(exported.triangle_count(), c["visible_count"].get<size_t>());
  vislib::Scene full = vislib::load_scene(city());
  const auto ids = c["visible"].get<std::vector<uint32_t>>();
  for (size_t i = 0; i < ids.size(); i += 7) {
    auto a = exported.corners(uint32_t(i)), b = full.corners(ids[i]);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(float(a[k].x), float(b[k].x));
  }
  // Text output names the cell and its share.
  ASSERT_EQ(run_pvs("inspect " + pvs + " --cell 3", &out), 0) << out;
  EXPECT_NE(out.find("cell 3 of 16"), std::string::npos) << out;
  EXPECT_NE(out.find("visible:"), std::string::npos) << out;

  // Object granularity: whole objects are exported.
  std::string opvs = dir + "/objects.pvs";
  ASSERT_EQ(run_pvs("bake " + city() + " --walkable --cell-size 20 --box -40,-1,-40,40,2,40 --res 24 --granularity object -o " + opvs, &out), 0) << out;
  ASSERT_EQ(run_pvs("inspect " + opvs + " --at 0,1.6,0 --json --scene " + city() + " --export-gltf " + glb, &out), 0) << out;
  c = json::parse(out);
  EXPECT_EQ(c["granularity"], "object");
  EXPECT_EQ(vislib::load_scene(glb).objects.size(), c["visible_count"].get<size_t>());
  EXPECT_GE(vislib::load_scene(glb).triangle_count(), c["visible_count"].get<size_t>());
}

TEST(CliBake, InspectRejectsAnotherScenesPvsAndDamagedFiles) {
  std::string dir = temp_dir("cli_inspect_bad");
  std::string pvs = dir + "/city.pvs", out;
  ASSERT_EQ(run_pvs(grid_bake(pvs), &out), 0) << out;
  std::string other = dir + "/other.glb";
  ASSERT_EQ(run_pvs("generate city --blocks 2,2 --seed 2 -o " + other, &out), 0) << out;
  ASSERT_EQ(run_pvs("inspect " + pvs + " --cell 0 --scene " + other, &out), 2) << out;
  EXPECT_NE(out.find("another scene"), std::string::npos) << out;
  std::string bytes = vislib::read_file(pvs);
  bytes[bytes.size() / 2] ^= 1;
  vislib::write_file_atomic(dir + "/damaged.pvs", bytes);
  ASSERT_EQ(run_pvs("inspect " + dir + "/damaged.pvs", &out), 2) << out;
  EXPECT_NE(out.find("checksum mismatch"), std::string::npos) << out;
  EXPECT_NE(out.find("damaged.pvs"), std::string::npos) << out;
}
