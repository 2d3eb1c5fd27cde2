// Tests of `pvs bake`, `pvs merge` and `pvs inspect` as a user runs them: a bake killed with -9
// and resumed gives the same bytes as an uninterrupted one, shards merge byte-identically, thread
// counts do not change the file, and inspect/export work on a generated city.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "pvs_format/pvs_format.h"
#include "tests/test_support.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import.h"

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
  return "bake " + city() +
         " --box -60,0,-60,60,3,60 --grid 4,1,4 --eye-height 1.5,1.8 --res 24 -o " + out;
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
  const pid_t pid =
      spawn_pvs_quiet({"bake", city(), "--box", "-60,0,-60,60,3,60", "--grid", "4,1,4",
                       "--eye-height", "1.5,1.8", "--res", "24", "--threads", "1", "-o", target});
  ASSERT_GT(pid, 0);
  auto start = std::chrono::steady_clock::now();
  bool finished_early = false;
  while (checkpoint_records(target + ".ckpt") < 3) {
    int status;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      finished_early = true;
      break;
    }
    ASSERT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60))
        << "no checkpoint records";
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
  // The killed writer's temporary, and one of a writer whose pid runs now (pid 1: a pid reused
  // after a kill) touched just now: the resume holds the output's lock, so neither writer can be
  // alive, and both go. Another file's temporary stays.
  const std::string planted = dir + "/.killed.pvs.1.AbCdEfGh1234.tmp";
  const std::string other = dir + "/.whole.pvs.1.AbCdEfGh1234.tmp";
  vislib::write_file_atomic(planted, "x");
  vislib::write_file_atomic(other, "x");
  auto temps_of_target = [&] {
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      const std::string f = e.path().filename().string();
      n += f.rfind(".killed.pvs.", 0) == 0 && f.size() > 4 &&
           f.compare(f.size() - 4, 4, ".tmp") == 0;
    }
    return n;
  };
  EXPECT_GE(temps_of_target(), 1);

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
  EXPECT_EQ(temps_of_target(), 0) << "the resume left the killed bake's temporaries";
  EXPECT_TRUE(std::filesystem::exists(other));
}

TEST(CliBake, ShardsMergeByteIdenticallyAndThreadsDoNotMatter) {
  std::string dir = temp_dir("cli_bake_shards");
  std::string out;
  // -j N runs N threads (a task arena of N slots), more than the cores too; same bytes.
  for (int threads : {1, 2, 16}) {
    const std::string name = dir + "/j" + std::to_string(threads);
    ASSERT_EQ(run_pvs(grid_bake(name + ".pvs") + " --threads " + std::to_string(threads) +
                          " --json " + name + ".json",
                      &out),
              0)
        << out;
    EXPECT_EQ(nlohmann::json::parse(vislib::read_file(name + ".json"))["threads"].get<int>(),
              threads);
  }
  EXPECT_EQ(vislib::read_file(dir + "/j1.pvs"), vislib::read_file(dir + "/j2.pvs"));
  EXPECT_EQ(vislib::read_file(dir + "/j1.pvs"), vislib::read_file(dir + "/j16.pvs"));
  std::string shards;
  for (int i = 0; i < 3; ++i) {
    std::string s = dir + "/shard" + std::to_string(i) + ".pvs";
    ASSERT_EQ(run_pvs(grid_bake(s) + " --shard " + std::to_string(i) + "/3", &out), 0) << out;
    shards = s + " " + shards;
  }
  ASSERT_EQ(run_pvs("merge " + shards + "-o " + dir + "/merged.pvs", &out), 0) << out;
  EXPECT_EQ(vislib::read_file(dir + "/merged.pvs"), vislib::read_file(dir + "/j1.pvs"));
  // A missing shard is an error naming the cell.
  ASSERT_EQ(
      run_pvs("merge " + dir + "/shard0.pvs " + dir + "/shard1.pvs -o " + dir + "/bad.pvs", &out),
      2)
      << out;
  EXPECT_NE(out.find("absent from every shard"), std::string::npos) << out;
  EXPECT_EQ(run_pvs(grid_bake(dir + "/x.pvs") + " --shard 3/3", &out), 2) << out;
}

TEST(CliBake, InspectSummarisesAndExportsACellOfAGeneratedCity) {
  std::string dir = temp_dir("cli_inspect");
  std::string pvs = dir + "/city.pvs", out;
  ASSERT_EQ(run_pvs("bake " + city() +
                        " --walkable --cell-size 20 --box -40,-1,-40,40,2,40 --res 24 -o " + pvs,
                    &out),
            0)
      << out;
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
  ASSERT_EQ(
      run_pvs("inspect " + pvs + " --at 0,1.6,0 --json --scene " + city() + " --export-gltf " + glb,
              &out),
      0)
      << out;
  // The cell at the centre straddles a building: inspect warns on stderr before the JSON.
  EXPECT_NE(out.find("enclosed by the scene"), std::string::npos) << out;
  ASSERT_NE(out.find('{'), std::string::npos) << out;
  json c = json::parse(out.substr(out.find('{')));
  // Walkable cells: the perimeters of the band's bottom and top (kPaperBandLevels), the region's
  // four vertical edges, then the traces of the building's walls at the band's middle
  // (wall_traces.h).
  const json& segs = c["boundary_segments"];
  ASSERT_GT(segs.size(), 12u);
  const double bottom = c["view_region"]["min"][1].get<double>(),
               top = c["view_region"]["max"][1].get<double>(), mid = 0.5 * (bottom + top);
  for (size_t k = 8; k < 12; ++k) {
    EXPECT_DOUBLE_EQ(segs[k]["from"][1].get<double>(), bottom);
    EXPECT_DOUBLE_EQ(segs[k]["to"][1].get<double>(), top);
  }
  for (size_t k = 12; k < segs.size(); ++k) {
    EXPECT_DOUBLE_EQ(segs[k]["from"][1].get<double>(), mid);
    EXPECT_DOUBLE_EQ(segs[k]["to"][1].get<double>(), mid);
  }
  // Without the scene the traces cannot be drawn, and inspect says so.
  ASSERT_EQ(run_pvs("inspect " + pvs + " --at 0,1.6,0 --json", &out), 0) << out;
  json bare = json::parse(out);
  EXPECT_EQ(bare["boundary_segments"].size(), 12u);
  EXPECT_NE(bare["wall_traces"].get<std::string>().find("--scene"), std::string::npos);
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
  ASSERT_EQ(run_pvs("bake " + city() +
                        " --walkable --cell-size 20 --box -40,-1,-40,40,2,40 --res 24 "
                        "--granularity object -o " +
                        opvs,
                    &out),
            0)
      << out;
  ASSERT_EQ(run_pvs("inspect " + opvs + " --at 0,1.6,0 --json --scene " + city() +
                        " --export-gltf " + glb,
                    &out),
            0)
      << out;
  ASSERT_NE(out.find('{'), std::string::npos) << out;
  c = json::parse(out.substr(out.find('{')));
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

// Two bakes of one output cannot run together: while another process holds OUTPUT.lock (as a
// running bake does), `pvs bake` exits 2 saying so, and touches neither output nor checkpoint.
TEST(CliBake, SecondConcurrentBakeOfTheSameOutputIsRefused) {
  std::string dir = temp_dir("cli_bake_lock");
  std::string out = dir + "/busy.pvs", text;
  {
    vislib::FileLock running(out + ".lock",
                             "the output " + out);  // this process plays the first bake
    EXPECT_EQ(run_pvs(grid_bake(out), &text), 2) << text;
    EXPECT_NE(text.find("locked by another process"), std::string::npos) << text;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out + ".ckpt"));
    EXPECT_EQ(run_pvs(grid_bake(out) + " --resume", &text), 2) << text;
  }
  // Once released (and the lock file removed), the bake runs.
  EXPECT_FALSE(std::filesystem::exists(out + ".lock"));
  EXPECT_EQ(run_pvs(grid_bake(out), &text), 0) << text;
  EXPECT_FALSE(std::filesystem::exists(out + ".lock"));
}

// Two resumes cannot append to one checkpoint: the checkpoint is locked too, even when the two
// runs write different outputs.
TEST(CliBake, SecondResumeOfALockedCheckpointIsRefused) {
  std::string dir = temp_dir("cli_bake_ckpt_lock");
  std::string ckpt = dir + "/shared.ckpt", text;
  int fd = ::open(ckpt.c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // as a running bake holds it
  EXPECT_EQ(run_pvs(grid_bake(dir + "/other.pvs") + " --resume --checkpoint " + ckpt, &text), 2)
      << text;
  EXPECT_NE(text.find("checkpoint is locked"), std::string::npos) << text;
  EXPECT_FALSE(std::filesystem::exists(dir + "/other.pvs"));
  ::close(fd);
  EXPECT_EQ(run_pvs(grid_bake(dir + "/other.pvs") + " --resume --checkpoint " + ckpt, &text), 0)
      << text;
}

namespace {

// A sphere scene with `states` key states, plus (if `ground`) a `mesh` line naming a ground
// quad in an OBJ beside it: the paper's bouncing spheres over a ground, from the command line.
std::string sphere_scene(const std::string& dir, bool ground) {
  std::string path = dir + "/balls.spheres", out;
  EXPECT_EQ(run_pvs("generate spheres --count 40 --radius 1 --area 30 --states 3 --max-height 4 "
                    "--speed 3 -o " +
                        path,
                    &out),
            0)
      << out;
  if (!ground) return path;
  {
    std::FILE* f = std::fopen((dir + "/ground.obj").c_str(), "w");
    std::fputs("o ground\nv -20 0 -20\nv 20 0 -20\nv 20 0 20\nv -20 0 20\nf 1 3 2\nf 1 4 3\n", f);
    std::fclose(f);
  }
  std::string text = vislib::read_file(path);
  size_t at = text.find("states 3\n");
  EXPECT_NE(at, std::string::npos);
  text.insert(at + 9, "mesh ground.obj\n");
  std::string mixed = dir + "/mixed.spheres";
  std::FILE* f = std::fopen(mixed.c_str(), "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return mixed;
}

}  // namespace

// One id rule for bake, inspect and view, on a sphere scene and on a
// scene of a mesh plus spheres given from the command line (a `mesh` line in the sphere file).
TEST(CliBake, SphereAndMixedScenesBakeInspectAndViewWithOneIdUniverse) {
  std::string dir = temp_dir("cli_spheres");
  for (bool ground : {false, true}) {
    std::string scene = sphere_scene(dir, ground),
                pvs = dir + (ground ? "/mixed.pvs" : "/balls.pvs"), out;
    const unsigned tris = ground ? 2 : 0;
    ASSERT_EQ(
        run_pvs("bake " + scene +
                    " --box -8,0,-8,8,2,8 --grid 2,1,2 --eye-height 1.5,1.8 --res 16 -o " + pvs,
                &out),
        0)
        << out;
    EXPECT_EQ(out.find("ignored"), std::string::npos) << out;  // spheres are baked, not "ignored"
    ASSERT_EQ(run_pvs("inspect --json " + pvs, &out), 0) << out;
    EXPECT_EQ(json::parse(out)["universe"], tris + 40);
    ASSERT_EQ(run_pvs("inspect " + pvs + " --scene " + scene + " --cell 0 --json", &out), 0) << out;
    json c = json::parse(out);
    ASSERT_GT(c["visible_count"].get<int>(), 0) << out;
    bool sphere_id = false;
    for (unsigned id : c["visible"]) sphere_id = sphere_id || id >= tris;
    EXPECT_TRUE(sphere_id) << "a cell sees some sphere";
    // The segment command sees the same scene: triangles first, then spheres.
    ASSERT_EQ(run_pvs("segment " + scene + " --from -2,1.6,0 --to 2,1.6,0 --res 16 --json " + dir +
                          "/s.json",
                      &out),
              0)
        << out;
    json sj = json::parse(vislib::read_file(dir + "/s.json"));
    if (ground) {
      EXPECT_EQ(sj["counts"]["scene_triangles"], 2);
    }
    EXPECT_GT(sj["visible_spheres"].size(), 0u);
    std::string png = dir + "/view.png";
    ASSERT_EQ(run_pvs("view " + pvs + " --scene " + scene +
                          " --at -3,1.6,-3 --look 3,1.6,3 --near-far 3,8 --frame 32x24 -o " + png +
                          " --json -",
                      &out),
              0)
        << out;
    size_t brace = out.find('{');
    ASSERT_NE(brace, std::string::npos) << out;
    json v = json::parse(out.substr(brace));
    EXPECT_EQ(v["triangles"]["scene"], tris);
  }
}

// An animated glTF without --states warns and names the option; a scene far from
// the origin warns; `pvs info` makes no units claim.
TEST(CliBake, LoadingTrapsWarnAndNameWhatToDo) {
  VISLIB_REQUIRE_SHARED(shared);
  std::string out, box = shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf";
  ASSERT_EQ(run_pvs("info " + box, &out), 0) << out;
  EXPECT_NE(out.find("animation(s) ignored"), std::string::npos) << out;
  EXPECT_NE(out.find("--states"), std::string::npos) << out;
  EXPECT_EQ(out.find("(likely)"), std::string::npos) << out;
  ASSERT_EQ(run_pvs("info " + box + " --states 5", &out), 0) << out;
  EXPECT_EQ(out.find("animation(s) ignored"), std::string::npos) << out;
  std::string dir = temp_dir("cli_far");
  std::FILE* f = std::fopen((dir + "/far.obj").c_str(), "w");
  std::fputs("v 100000 0 0\nv 100001 0 0\nv 100000 1 0\nf 1 2 3\n", f);
  std::fclose(f);
  ASSERT_EQ(run_pvs("info " + dir + "/far.obj --json", &out), 0) << out;
  EXPECT_NE(out.find("far from the origin"), std::string::npos) << out;
  size_t brace = out.find('{');
  ASSERT_NE(brace, std::string::npos);
  EXPECT_TRUE(json::parse(out.substr(brace))["far_from_origin"].get<bool>());
}

// Long segments (--long-segments L): the summary counts the kernel runs, the
// metadata records the setting, the sets equal those of the default (edges only), and an
// out-of-range value is refused naming the option.
TEST(CliBake, LongSegmentsRunFewerSegmentsForTheSameSets) {
  std::string dir = temp_dir("cli_bake_long");
  std::string out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/long.pvs") + " --long-segments 8", &out), 0) << out;
  // 16 cells x 8 edges = 128 runs; 2 levels x 2 directions x 5 lines x 1 chain of 4 = 20 kernel
  // runs, 108 served.
  EXPECT_NE(out.find("128 from-segment runs, 108 of them served"), std::string::npos) << out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/edges.pvs"), &out), 0) << out;
  EXPECT_NE(out.find("128 from-segment runs, 48 of them served"), std::string::npos) << out;
  pvs::Reader a = pvs::Reader::from_file(dir + "/long.pvs"),
              b = pvs::Reader::from_file(dir + "/edges.pvs");
  EXPECT_NE(a.info().metadata.find("\"long_segments\":8"), std::string::npos);
  EXPECT_EQ(b.info().metadata.find("long_segments"), std::string::npos);
  for (uint32_t c = 0; c < 16; ++c) EXPECT_EQ(a.read_cell(c), b.read_cell(c)) << "cell " << c;
  EXPECT_EQ(run_pvs(grid_bake(dir + "/bad.pvs") + " --long-segments 9", &out), 2) << out;
  EXPECT_NE(out.find("--long-segments"), std::string::npos) << out;
  EXPECT_EQ(run_pvs(grid_bake(dir + "/bad.pvs") + " --long-segments 2.5", &out), 2) << out;
  EXPECT_NE(out.find("--long-segments"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad.pvs"));
}

// --long-segments auto: the pilot says what it does and what it chose, the report holds its
// counts, and the file is the one the chosen L gives.
TEST(CliBake, LongSegmentsAutoReportsItsPilotAndBakesTheChosenLength) {
  std::string dir = temp_dir("cli_bake_long_auto");
  std::string out;
  ASSERT_EQ(
      run_pvs(grid_bake(dir + "/auto.pvs") + " --long-segments auto --json " + dir + "/auto.json",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("a pilot runs a few rows of cell edges"), std::string::npos) << out;
  const size_t at = out.find("long segments: L = ");
  ASSERT_NE(at, std::string::npos) << out;
  const int parts = std::stoi(out.substr(at + 19));
  const json report = json::parse(vislib::read_file(dir + "/auto.json"));
  EXPECT_EQ(report["long_segments"]["parts"], parts);
  const json& pilot = report["long_segments"]["pilot"];
  // Rows of 4 edges: L = 8 would repeat L = 4; the pilot may stop earlier (long_segments.h).
  ASSERT_GE(pilot["candidates"].size(), 2u);
  ASSERT_LE(pilot["candidates"].size(), 3u);
  for (const json& c : pilot["candidates"]) {
    EXPECT_GT(c["covered_pairs"].get<double>(), 0) << c;
    EXPECT_EQ(c["estimated_work"].get<double>(), c["covered_pairs"].get<double>() +
                                                     4 * c["triangle_tiles"].get<double>() +
                                                     6 * c["bvh_nodes_opened"].get<double>() +
                                                     0.4 * c["primitives_bounded"].get<double>())
        << c;
  }
  ASSERT_EQ(
      run_pvs(grid_bake(dir + "/fixed.pvs") + " --long-segments " + std::to_string(parts), &out), 0)
      << out;
  EXPECT_EQ(vislib::read_file(dir + "/auto.pvs"), vislib::read_file(dir + "/fixed.pvs"));
}

// The BVH every run walks changes nothing in the file; pvs segment and pvs
// region give the same sets with and without it, and report its build time.
TEST(CliBake, TheBvhWalkGivesTheSameFileAndTheSameSets) {
  std::string dir = temp_dir("cli_bake_bvh");
  std::string out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/on.pvs") + " --runs 2", &out), 0) << out;
  ASSERT_EQ(run_pvs(grid_bake(dir + "/off.pvs") + " --runs 2 --bvh off", &out), 0) << out;
  EXPECT_EQ(vislib::read_file(dir + "/on.pvs"), vislib::read_file(dir + "/off.pvs"));
  EXPECT_EQ(run_pvs(grid_bake(dir + "/bad.pvs") + " --bvh maybe", &out), 2) << out;
  EXPECT_NE(out.find("--bvh"), std::string::npos) << out;
  std::string sets[2];
  for (int on = 0; on < 2; ++on) {
    const std::string path = dir + "/seg" + std::to_string(on) + ".json";
    ASSERT_EQ(run_pvs("segment " + city() + " --from 0,1.7,-20 --to 0,1.7,20 --res 48 --seed 3 " +
                          "--witness --bvh " + (on ? "on" : "off") + " --json " + path,
                      &out),
              0)
        << out;
    const auto j = nlohmann::json::parse(vislib::read_file(path));
    sets[on] = j["visible"].dump() + j["witnesses"].dump();
    EXPECT_EQ(j["timings"]["bvh_seconds"].get<double>() > 0, on == 1);
    // Both times whatever --bvh says, the kernel's without the build.
    EXPECT_EQ(j["bvh"].get<bool>(), on == 1);
    EXPECT_GT(j["timings"]["visibility_seconds"].get<double>(), 0);
    EXPECT_EQ(j["timings"]["bvh_and_visibility_seconds"].get<double>(),
              j["timings"]["bvh_seconds"].get<double>() +
                  j["timings"]["visibility_seconds"].get<double>());
    EXPECT_EQ(j["counts"]["bvh_nodes_opened"].get<uint64_t>() > 0, on == 1);
    // Without the tree every primitive (a fan of the city's quads, or a triangle) is bounded on
    // each of the six faces (the count the long-segment pilot weighs, long_segments.cpp).
    const uint64_t bounded = j["counts"]["primitives_bounded"].get<uint64_t>();
    if (on) {
      EXPECT_EQ(bounded, 0u);
    } else {
      EXPECT_EQ(bounded % 6, 0u);
      EXPECT_GT(bounded, 3 * j["counts"]["scene_triangles"].get<uint64_t>());
      EXPECT_LT(bounded, 6 * j["counts"]["scene_triangles"].get<uint64_t>());
    }
  }
  EXPECT_EQ(sets[0], sets[1]);
  EXPECT_GT(sets[0].size(), 100u);
}

TEST(CliBake, InspectRenderLooksAtAPointWithAFieldOfView) {
  std::string dir = temp_dir("cli_inspect_look");
  std::string pvs = dir + "/city.pvs", out;
  ASSERT_EQ(run_pvs("bake " + city() +
                        " --walkable --cell-size 20 --box -20,-1,-20,20,2,20 --res 16 -q -o " + pvs,
                    &out),
            0)
      << out;
  const std::string base =
      "inspect " + pvs + " --scene " + city() + " --at 0,1.6,0 --frame 40x30 --json -q --render ";
  ASSERT_EQ(run_pvs(base + dir + "/four", &out), 0) << out;
  // --look at a point along +x at the default 90 degrees: the first of the four views, exactly.
  ASSERT_EQ(run_pvs(base + dir + "/look --look 5,1.6,0", &out), 0) << out;
  json j = json::parse(out.substr(out.find('{')));
  ASSERT_EQ(j["render"]["views"].size(), 1u);
  EXPECT_EQ(j["render"]["vfov_degrees"], 90.0);
  EXPECT_EQ(vislib::read_file(dir + "/look/view0_full.png"),
            vislib::read_file(dir + "/four/view0_full.png"));
  EXPECT_EQ(vislib::read_file(dir + "/look/view0_pvs.png"),
            vislib::read_file(dir + "/four/view0_pvs.png"));
  // A narrower field of view is another frame.
  ASSERT_EQ(run_pvs(base + dir + "/narrow --look 5,1.6,0 --fov 40", &out), 0) << out;
  EXPECT_EQ(json::parse(out.substr(out.find('{')))["render"]["vfov_degrees"], 40.0);
  EXPECT_NE(vislib::read_file(dir + "/narrow/view0_full.png"),
            vislib::read_file(dir + "/four/view0_full.png"));
  // Looking straight up or at the eye has no horizontal direction; a field of view of 180 none.
  EXPECT_EQ(run_pvs(base + dir + "/up --look 0,9,0", &out), 2) << out;
  EXPECT_NE(out.find("--look"), std::string::npos) << out;
  EXPECT_EQ(run_pvs(base + dir + "/wide --fov 180", &out), 2) << out;
}
