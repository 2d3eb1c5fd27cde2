// Tests of the bake (library): byte-identical output for any thread count, shards merged into
// the same bytes, edges shared between cells computed once, an eye band swept at more heights
// than its bottom and top seeing what eyes between them see, resume from a
// checkpoint (including one torn at any byte), refusal of another bake's checkpoint, and the scene
// fingerprint and subset the PVS relies on.
#include "vislib/bake/bake.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/bake/bake_eta.h"
#include "vislib/bake/bake_report.h"
#include "vislib/bake/cell_set.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/checkpoint.h"
#include "vislib/bake/long_segments.h"
#include "vislib/bake/scene_subset.h"
#include "vislib/bake/wall_traces.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/ray_reference.h"
#include "vislib/kernel/segment_run_cache.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/import.h"
#include "vislib/scene/scene_fingerprint.h"

using namespace vislib;
using vislib_test::temp_dir;

namespace {

Scene small_city() {
  CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  return generate_city(o);
}

// A grid of nx x 1 x nz cells over the square [-half, half]^2 (y 0..3), eye band `band`.
ViewCells city_grid(double half, int nx, int nz, EyeBand band = EyeBand{1.5, 1.8}) {
  Box3 box;
  box.extend({-half, 0, -half});
  box.extend({half, 3, half});
  return grid_cells(box, nx, 1, nz, band);
}

ViewCells small_grid() {
  return city_grid(30, 3, 3);
}

BakeSettings settings() {
  BakeSettings s;
  s.region.segment.resolution = 24;
  s.region.runs = 1;
  s.region.seed = 3;
  return s;
}

std::string bake_bytes(const Scene& scene, const ViewCells& cells, const BakeSettings& s,
                       const std::string& path, Shard shard = {}, int threads = 0) {
  std::unique_ptr<tbb::global_control> limit;
  if (threads)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  threads);
  bake(scene, cells, s, shard, {path, path + ".ckpt", false});
  EXPECT_FALSE(std::filesystem::exists(path + ".ckpt"))
      << "the checkpoint must be gone after success";
  return read_file(path);
}

}  // namespace

TEST(Bake, OutputIsByteIdenticalForOneAndTwoThreads) {
  Scene scene = small_city();
  std::string dir = temp_dir("bake_threads");
  std::string one = bake_bytes(scene, small_grid(), settings(), dir + "/one.pvs", {}, 1);
  std::string two = bake_bytes(scene, small_grid(), settings(), dir + "/two.pvs", {}, 2);
  EXPECT_EQ(one, two);
  pvs::Reader r = pvs::Reader::from_memory(one);
  EXPECT_EQ(r.cell_count(), 9u);
  EXPECT_EQ(r.info().universe, scene.triangle_count());
  EXPECT_EQ(r.info().scene_fingerprint, scene_fingerprint(scene));
  // Each cell holds what bake_cell computes.
  for (uint32_t c = 0; c < 9; ++c)
    EXPECT_EQ(r.read_cell(c), bake_cell(scene, r.info().layout, c, settings()));
}

TEST(Bake, ShardsMergeIntoTheSingleBakeByteForByte) {
  Scene scene = small_city();
  std::string dir = temp_dir("bake_shards");
  std::string whole = bake_bytes(scene, small_grid(), settings(), dir + "/whole.pvs");
  std::vector<pvs::Reader> shards;
  for (uint32_t i = 0; i < 4; ++i) {
    std::string bytes = bake_bytes(scene, small_grid(), settings(),
                                   dir + "/s" + std::to_string(i) + ".pvs", {i, 4});
    shards.push_back(pvs::Reader::from_memory(bytes));
    EXPECT_TRUE(shards.back().info().partial);
  }
  std::swap(shards[0], shards[3]);  // order does not matter
  EXPECT_EQ(pvs::merge_pvs(shards), whole);
}

TEST(Bake, ObjectGranularityStoresObjectsOfTheVisibleTriangles) {
  Scene scene = small_city();
  BakeSettings s = settings();
  s.granularity = Granularity::Object;
  std::string dir = temp_dir("bake_objects");
  pvs::Reader r = pvs::Reader::from_memory(bake_bytes(scene, small_grid(), s, dir + "/o.pvs"));
  EXPECT_EQ(r.info().granularity, pvs::Granularity::Object);
  EXPECT_EQ(r.info().universe, scene.objects.size());
  EXPECT_EQ(r.read_cell(4), objects_of(scene, bake_cell(scene, r.info().layout, 4, settings())));
}

TEST(Bake, SeeThroughBuildingsOnlyAddToEachCellsSet) {
  Scene scene = small_city();
  Scene glass = scene;
  for (size_t o = 1; o < glass.objects.size(); o += 2) glass.objects[o].see_through = true;
  ASSERT_GT(glass.see_through_triangle_count(), 0u);
  const ViewCells cells = small_grid();
  size_t opaque_total = 0, glass_total = 0;
  for (uint32_t c = 0; c < cells.layout.cell_count(); ++c) {
    const std::vector<uint32_t> a = bake_cell(scene, cells.layout, c, settings());
    const std::vector<uint32_t> b = bake_cell(glass, cells.layout, c, settings());
    EXPECT_TRUE(std::includes(b.begin(), b.end(), a.begin(), a.end())) << "cell " << c;
    opaque_total += a.size();
    glass_total += b.size();
  }
  EXPECT_GT(glass_total, opaque_total);  // something behind the glass buildings is seen
}

TEST(Bake, ResumeFromACheckpointGivesTheSameBytes) {
  Scene scene = small_city();
  ViewCells cells = small_grid();
  std::string dir = temp_dir("bake_resume");
  std::string whole = bake_bytes(scene, cells, settings(), dir + "/whole.pvs");
  // A checkpoint as a killed bake leaves it: some cells done, a torn record at the end.
  pvs::FileInfo info = bake_file_info(scene, cells, settings());
  std::string ckpt = dir + "/resumed.pvs.ckpt";
  {
    Checkpoint cp(ckpt, bake_key(info, {}), 9, false);
    for (uint32_t c : {4u, 0u, 7u}) cp.append(c, bake_cell(scene, cells.layout, c, settings()));
  }
  std::string bytes = read_file(ckpt);
  write_file_atomic(ckpt, bytes + bytes.substr(24, 7));  // half a record
  BakeReport rep = bake(scene, cells, settings(), {}, {dir + "/resumed.pvs", ckpt, true});
  EXPECT_EQ(rep.resumed, 3u);
  EXPECT_EQ(rep.baked, 6u);
  EXPECT_EQ(read_file(dir + "/resumed.pvs"), whole);
  EXPECT_FALSE(std::filesystem::exists(ckpt));
}

TEST(Bake, CheckpointOfAnotherBakeIsRefused) {
  Scene scene = small_city();
  std::string dir = temp_dir("bake_other");
  std::string ckpt = dir + "/x.pvs.ckpt";
  { Checkpoint cp(ckpt, 12345, 9, false); }
  try {
    bake(scene, small_grid(), settings(), {}, {dir + "/x.pvs", ckpt, true});
    FAIL() << "resumed another bake's checkpoint";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another bake"), std::string::npos) << e.what();
  }
  // A shard's checkpoint is another bake too.
  pvs::FileInfo info = bake_file_info(scene, small_grid(), settings());
  EXPECT_NE(bake_key(info, {0, 2}), bake_key(info, {1, 2}));
  EXPECT_NE(bake_key(info, {0, 1}), bake_key(info, {0, 2}));
}

TEST(Checkpoint, TornAtAnyByteKeepsEveryCompleteRecord) {
  std::string dir = temp_dir("checkpoint_torn");
  std::string path = dir + "/c.ckpt";
  std::vector<std::vector<uint32_t>> sets = {{1, 2, 3}, {}, {7, 100, 4000}, {5}};
  std::vector<size_t> ends;  // file size after each record
  {
    Checkpoint cp(path, 99, 10, false);
    ends.push_back(std::filesystem::file_size(path));
    for (uint32_t i = 0; i < sets.size(); ++i) {
      cp.append(2 * i, sets[i]);
      ends.push_back(std::filesystem::file_size(path));
    }
  }
  const std::string full = read_file(path);
  for (size_t n = 0; n <= full.size(); ++n) {
    write_file_atomic(path, full.substr(0, n));
    std::vector<std::optional<std::vector<uint32_t>>> got;
    auto cp = std::make_unique<Checkpoint>(path, 99, 10, true, &got, 5000);
    size_t complete = 0;
    while (complete + 1 < ends.size() && ends[complete + 1] <= n) ++complete;
    if (n < ends[0]) complete = 0;
    EXPECT_EQ(cp->recovered_records(), complete) << "cut at " << n;
    for (size_t i = 0; i < complete; ++i) EXPECT_EQ(got[2 * i], sets[i]) << "cut at " << n;
    // Appending after the cut continues a valid file.
    cp->append(9, {42});
    cp.reset();  // release the checkpoint (and its lock) before reopening it
    std::vector<std::optional<std::vector<uint32_t>>> again;
    Checkpoint reread(path, 99, 10, true, &again, 5000);
    EXPECT_EQ(reread.recovered_records(), complete + 1) << "cut at " << n;
    EXPECT_EQ(again[9], (std::vector<uint32_t>{42}));
  }
}

TEST(Checkpoint, DamagedLastRecordIsDropped) {
  std::string dir = temp_dir("checkpoint_damaged");
  std::string path = dir + "/c.ckpt";
  {
    Checkpoint cp(path, 5, 4, false);
    cp.append(0, {1});
    cp.append(1, {2});
  }
  std::string f = read_file(path);
  f[f.size() - 6] ^= 0x10;  // inside the second record
  write_file_atomic(path, f);
  std::vector<std::optional<std::vector<uint32_t>>> got;
  Checkpoint cp(path, 5, 4, true, &got);
  EXPECT_EQ(cp.recovered_records(), 1u);
  EXPECT_TRUE(got[0]);
  EXPECT_FALSE(got[1]);
  EXPECT_GT(cp.discarded_bytes(), 0u);
  EXPECT_EQ(cp.dropped_records(), 1u);
}

namespace {

// A checkpoint of 38 records (cells 0..37 of 40, sets of varying size), as bytes; `ends[i]` is
// the file size after record i.
std::string checkpoint_of_38(const std::string& path, std::vector<size_t>& ends,
                             std::vector<std::vector<uint32_t>>& sets) {
  sets.clear();
  ends.clear();
  {
    Checkpoint cp(path, 77, 40, false);
    for (uint32_t c = 0; c < 38; ++c) {
      std::vector<uint32_t> ids;
      for (uint32_t i = 0; i < 3 + (c * 7) % 20; ++i) ids.push_back(c + 10 * i);
      cp.append(c, ids);
      sets.push_back(ids);
      ends.push_back(std::filesystem::file_size(path));
    }
  }
  return read_file(path);
}

}  // namespace

// One flipped byte at a quarter of a 38-record checkpoint drops only the damaged record (skipped by
// its size field), never the valid records after it, whatever byte of it is hit, and appending
// continues after the last record.
TEST(Checkpoint, FlippedByteAtAQuarterKeepsEveryOtherRecord) {
  std::string dir = temp_dir("checkpoint_flip");
  std::string path = dir + "/c.ckpt";
  std::vector<size_t> ends;
  std::vector<std::vector<uint32_t>> sets;
  const std::string full = checkpoint_of_38(path, ends, sets);
  const size_t quarter = full.size() / 4;
  size_t hit = 0;  // the record holding byte `quarter`
  while (ends[hit] <= quarter) ++hit;
  const size_t rec_start = hit == 0 ? 24 : ends[hit - 1];
  // The byte at a quarter, then every byte of that record (size field, cell id, payload, CRC).
  std::vector<size_t> where = {quarter};
  for (size_t b = rec_start; b < ends[hit]; ++b) where.push_back(b);
  for (size_t at : where) {
    std::string f = full;
    f[at] ^= 0x5a;
    write_file_atomic(path, f);
    std::vector<std::optional<std::vector<uint32_t>>> got;
    auto cp = std::make_unique<Checkpoint>(path, 77, 40, true, &got, 1000);
    EXPECT_EQ(cp->recovered_records(), 37u) << "byte " << at;
    EXPECT_EQ(cp->dropped_records(), 1u) << "byte " << at;
    EXPECT_EQ(cp->discarded_bytes(), ends[hit] - rec_start) << "byte " << at;
    for (uint32_t c = 0; c < 38; ++c) {
      if (c == hit) {
        EXPECT_FALSE(got[c]) << "byte " << at;
      } else {
        ASSERT_TRUE(got[c]) << "byte " << at << " cell " << c;
        EXPECT_EQ(*got[c], sets[c]);
      }
    }
    // The damaged cell is baked again and appended; a second reopen finds all 38.
    cp->append(uint32_t(hit), sets[hit]);
    cp.reset();  // release the checkpoint (and its lock) before reopening it
    std::vector<std::optional<std::vector<uint32_t>>> again;
    Checkpoint reread(path, 77, 40, true, &again, 1000);
    EXPECT_EQ(reread.recovered_records(), 38u) << "byte " << at;
    EXPECT_EQ(again[hit], sets[hit]);
  }
}

TEST(Checkpoint, SecondOpenOfTheSameCheckpointIsRefused) {
  std::string dir = temp_dir("checkpoint_lock");
  std::string path = dir + "/c.ckpt";
  Checkpoint first(path, 1, 4, false);
  first.append(0, {1});
  EXPECT_THROW(Checkpoint(path, 1, 4, true), InputError);
  EXPECT_THROW(Checkpoint(path, 1, 4, false), InputError);
  // The refused opens did not truncate or cut the holder's file: both records are there.
  first.append(1, {2});
  std::string bytes = read_file(path);
  EXPECT_EQ(bytes.size(), std::filesystem::file_size(path));
  EXPECT_GT(bytes.size(), 24u + 2 * 12);
  first.remove();
  EXPECT_FALSE(std::filesystem::exists(path));
}

// The streamed output (blocks written as cells finish, index patched at the end) holds exactly the
// bytes pvs::write_pvs gives for every cell's set, for the whole bake and for a shard.
TEST(Bake, StreamedFileEqualsWritePvsOfEveryCellsSet) {
  Scene scene = small_city();
  ViewCells cells = small_grid();
  std::string dir = temp_dir("bake_stream");
  pvs::FileInfo info = bake_file_info(scene, cells, settings());
  std::vector<pvs::CellSet> sets(cells.layout.cell_count());
  for (uint32_t c = 0; c < sets.size(); ++c)
    sets[c] = bake_cell(scene, cells.layout, c, settings());
  EXPECT_EQ(bake_bytes(scene, cells, settings(), dir + "/all.pvs", {}, 2),
            pvs::write_pvs(info, sets));
  info.partial = true;
  for (uint32_t c = 0; c < sets.size(); ++c)
    if (!in_shard(c, {1, 3})) sets[c].reset();
  EXPECT_EQ(bake_bytes(scene, cells, settings(), dir + "/s1.pvs", {1, 3}, 2),
            pvs::write_pvs(info, sets));
}

TEST(Bake, RefusedWhileAnotherBakeHoldsTheOutputLock) {
  Scene scene = small_city();
  std::string dir = temp_dir("bake_lock");
  std::string out = dir + "/x.pvs";
  {
    FileLock other(out + ".lock", "the output");
    EXPECT_THROW(bake(scene, small_grid(), settings(), {}, {out, out + ".ckpt", false}),
                 InputError);
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  bake(scene, small_grid(), settings(), {}, {out, out + ".ckpt", false});
  EXPECT_TRUE(std::filesystem::exists(out));
}

TEST(SceneFingerprint, ChangesWithAnyVertexIndexOrObjectButNotWithNames) {
  Scene a = small_city();
  uint64_t f = scene_fingerprint(a);
  EXPECT_EQ(scene_fingerprint(small_city()), f);
  Scene b = a;
  b.positions[0][17].y = std::nextafter(b.positions[0][17].y, 1e9);
  EXPECT_NE(scene_fingerprint(b), f);
  b = a;
  std::swap(b.triangles[3][0], b.triangles[3][1]);
  EXPECT_NE(scene_fingerprint(b), f);
  b = a;
  b.triangle_object[5] = (b.triangle_object[5] + 1) % uint32_t(b.objects.size());
  EXPECT_NE(scene_fingerprint(b), f);
  b = a;
  b.objects[0].name = "renamed";
  EXPECT_EQ(scene_fingerprint(b), f);
}

TEST(SceneSubset, KeepsExactlyTheSetAtEachGranularity) {
  Scene s = small_city();
  std::vector<uint32_t> tris = {0, 5, 300, 301};
  Scene t = scene_subset(s, tris, Granularity::Triangle);
  ASSERT_EQ(t.triangle_count(), 4u);
  for (size_t i = 0; i < tris.size(); ++i) EXPECT_EQ(t.corners(uint32_t(i)), s.corners(tris[i]));
  std::vector<uint32_t> objs = objects_of(s, tris);
  Scene o = scene_subset(s, objs, Granularity::Object);
  EXPECT_EQ(o.objects.size(), objs.size());
  size_t expect = 0;
  for (uint32_t obj : s.triangle_object)
    expect += std::binary_search(objs.begin(), objs.end(), obj);
  EXPECT_EQ(o.triangle_count(), expect);
  EXPECT_EQ(o.objects[0].name, s.objects[objs[0]].name);
}

TEST(BakeReportJson, StatesTheRunTheCellsTimingsAndTheFileSizes) {
  using nlohmann::json;
  const Scene scene = small_city();
  const std::string dir = temp_dir("bake_report");
  const BakeReport r =
      bake(scene, small_grid(), settings(), Shard{}, {dir + "/c.pvs", dir + "/c.ckpt", false});
  BakeRunInfo info;
  info.scene = "city.glb";
  info.output = dir + "/c.pvs";
  info.preset = "draft";
  info.resolution = 24;
  info.runs = 1;
  info.setup_seconds = 0.5;
  const std::string text = bake_report_json(info, r);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const json j = json::parse(text);
  EXPECT_EQ(j["scene"], "city.glb");
  EXPECT_EQ(j["cells"], 9);
  EXPECT_EQ(j["shard_cells"], 9);
  EXPECT_EQ(j["baked"], 9);
  EXPECT_EQ(j["resumed"], 0);
  EXPECT_EQ(j["shard"], json::array({0, 1}));
  EXPECT_EQ(j["preset"]["name"], "draft");
  EXPECT_TRUE(j["preset"]["cell_size"].is_null());  // a grid given by its counts
  EXPECT_EQ(j["bytes"]["file"].get<uint64_t>(), std::filesystem::file_size(dir + "/c.pvs"));
  EXPECT_EQ(j["cell_seconds"].size(), 9u);
  double sum = 0;
  for (const json& s : j["cell_seconds"]) sum += s.get<double>();
  EXPECT_DOUBLE_EQ(j["timings"]["kernel_seconds"].get<double>(), sum);
  EXPECT_EQ(kernel_seconds(r), sum);
  EXPECT_EQ(j["timings"]["setup_seconds"], 0.5);
  // The threads of the caller's arena, and where their time went.
  EXPECT_EQ(j["threads"].get<int>(), tbb::this_task_arena::max_concurrency());
  ASSERT_EQ(j["cell_cpu_seconds"].size(), 9u);
  double cpu = 0;
  for (const json& s : j["cell_cpu_seconds"]) {
    EXPECT_GE(s.get<double>(), 0);
    cpu += s.get<double>();
  }
  EXPECT_GT(cpu, 0);
  const json& t = j["timings"];
  EXPECT_GT(t["process_cpu_seconds"].get<double>(), 0);
  EXPECT_GT(t["cells_seconds"].get<double>(), 0);
  EXPECT_LE(t["shared_wait_seconds"].get<double>(), t["cells_seconds"].get<double>());
  for (const char* k :
       {"cells_cpu_seconds", "progress_seconds", "checkpoint_seconds", "writing_seconds"})
    EXPECT_GE(t[k].get<double>(), 0) << k;
  // Phase by phase: every thread's time counted once, so the pipeline's phases and idle add up
  // to threads x bake_seconds (wall) and to the process's CPU seconds (within the timers' rounding
  // of 1 ns per reading).
  const json& ph = t["phases"];
  double wall_sum = 0, cpu_sum = 0;
  for (const char* k : {"runs", "shared_waits", "merge", "cell", "progress", "checkpoint", "encode",
                        "write", "helping", "bound_trees", "idle"}) {
    ASSERT_TRUE(ph.contains(k)) << k;
    EXPECT_GE(ph[k]["wall_seconds"].get<double>(), 0) << k;
    EXPECT_GE(ph[k]["cpu_seconds"].get<double>(), 0) << k;
    wall_sum += ph[k]["wall_seconds"].get<double>();
    cpu_sum += ph[k]["cpu_seconds"].get<double>();
  }
  EXPECT_GT(ph["runs"]["wall_seconds"].get<double>(), 0);
  EXPECT_GT(ph["runs"]["cpu_seconds"].get<double>(), 0);
  EXPECT_GT(ph["encode"]["wall_seconds"].get<double>(), 0);
  EXPECT_GE(ph["bvh"]["wall_seconds"].get<double>(), 0);
  EXPECT_GE(ph["pilot"]["wall_seconds"].get<double>(), 0);
  const double thread_seconds = j["threads"].get<int>() * t["bake_seconds"].get<double>();
  EXPECT_NEAR(wall_sum, thread_seconds, 1e-3 + 1e-6 * thread_seconds);
  EXPECT_GE(cpu_sum, t["process_cpu_seconds"].get<double>() - 1e-3);
  info.cell_size = 8;
  EXPECT_EQ(json::parse(bake_report_json(info, r))["preset"]["cell_size"], 8.0);
}

// The progress carries the expected work of the cells (bake_eta.h): its total is that of every
// cell to bake, and all of it is done by the last call.
TEST(Bake, ProgressCountsTheExpectedWorkOfTheCells) {
  const Scene scene = small_city();
  const std::string dir = temp_dir("bake_work");
  const ViewCells cells = small_grid();
  std::vector<BakeProgress> calls;
  bake(scene, cells, settings(), Shard{}, {dir + "/c.pvs", dir + "/c.ckpt", false},
       [&](const BakeProgress& p) { calls.push_back(p); });
  const uint32_t n = cells.layout.cell_count();
  double total = 0;
  for (double w : expected_cell_work(cells.layout, std::vector<uint8_t>(n, 1), 1, true)) total += w;
  ASSERT_GE(calls.size(), 2u);
  EXPECT_EQ(calls.front().work_done, 0);
  EXPECT_DOUBLE_EQ(calls.front().work_total, total);
  EXPECT_EQ(calls.back().done, n);
  EXPECT_NEAR(calls.back().work_done, total, 1e-9 * total);
  for (size_t i = 1; i < calls.size(); ++i) EXPECT_LE(calls[i].work_done, total * (1 + 1e-9)) << i;
}

TEST(CellSet, ReadCellViewSetFindsThePointsCellOrSaysWhyNot) {
  const Scene scene = small_city();
  const std::string dir = temp_dir("cell_set");
  const std::string all = dir + "/all.pvs", even = dir + "/even.pvs";
  bake(scene, small_grid(), settings(), Shard{}, {all, all + ".ckpt", false});
  bake(scene, small_grid(), settings(), Shard{0, 2}, {even, even + ".ckpt", false});
  pvs::Reader r = pvs::Reader::from_file(all);
  const Vec3 p{1, 1.6, 1};  // inside the middle cell (4) of the 3 x 3 grid over [-30, 30]
  const CellViewSet v = read_cell_view_set(all, scene, p);
  ASSERT_EQ(v.where.status, PointCell::Found);
  EXPECT_EQ(v.where.cell, 4u);
  EXPECT_EQ(v.triangles, visible_triangles(scene, r.read_cell(4), Granularity::Triangle));
  EXPECT_FALSE(v.triangles.empty());
  EXPECT_EQ(v.centre.x, 0);
  EXPECT_DOUBLE_EQ(v.centre.y, 1.65);
  EXPECT_EQ(v.view_region.min.y, 1.5);
  EXPECT_EQ(read_cell_view_set(all, scene, {100, 1.6, 0}).where.status, PointCell::NoCell);
  // Cell 4 is not in shard 0/2 (cells 0, 2, 4, ... are; 4 % 2 == 0), cell 3 is absent.
  EXPECT_EQ(read_cell_view_set(even, scene, p).where.status, PointCell::Found);
  const CellViewSet odd = read_cell_view_set(even, scene, {-20, 1.6, 0});
  EXPECT_EQ(odd.where.status, PointCell::Absent);
  EXPECT_EQ(odd.where.cell, 3u);
  EXPECT_TRUE(odd.triangles.empty());
  // Another scene: refused by the fingerprint, naming the file.
  Scene other = scene;
  other.positions[0][0].x += 1;
  try {
    read_cell_view_set(all, other, p);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), all);
  }
}

TEST(CellSet, UnionOfSetsIsEveryTriangleOfAnySetAscending) {
  Scene s = small_city();
  const uint32_t tris = uint32_t(s.triangle_count());
  s.sphere_radius = {1.0};
  s.sphere_centers = {{Vec3{0, 50, 0}}};
  s.sphere_object = {0};
  // Triangle ids: the sphere's id (tris) is left out; duplicates and order do not matter.
  EXPECT_EQ(visible_triangles_union(s, {{7, 3, tris}, {3, 1}, {}}, Granularity::Triangle),
            (std::vector<uint32_t>{1, 3, 7}));
  // Object ids: every triangle of those objects.
  const uint32_t a = s.triangle_object[0], b = s.triangle_object[tris - 1];
  std::vector<uint32_t> expect;
  for (uint32_t t = 0; t < tris; ++t)
    if (s.triangle_object[t] == a || s.triangle_object[t] == b) expect.push_back(t);
  EXPECT_EQ(visible_triangles_union(s, {{b}, {a, b}}, Granularity::Object), expect);
  EXPECT_EQ(visible_triangles_union(s, {{b}, {a}}, Granularity::Object),
            visible_triangles(s, a < b ? std::vector<uint32_t>{a, b} : std::vector<uint32_t>{b, a},
                              Granularity::Object));
}

// Shared edges: run 0 of an edge common to two cells is computed once
// (segment_run_cache.h), and the file is byte-identical to a bake that computes every cell alone.
TEST(BakeSharedSegments, SetsEqualBakingEachCellAloneWithFewerRuns) {
  const Scene scene = small_city();
  const ViewCells cells = small_grid();
  BakeSettings s;
  s.region.segment.resolution = 16;
  s.region.runs = 2;  // run 1 is a per-cell random orientation: never shared
  s.region.seed = 5;
  s.long_segments = 1;  // edges only (BakeLongSegments tests the chains)
  const std::string dir = temp_dir("bake_shared_segments");
  tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);

  BakeSettings alone = s;
  alone.share_segments = false;
  const BakeReport a = bake(scene, cells, alone, {}, {dir + "/alone.pvs", "", false});
  const BakeReport b = bake(scene, cells, s, {}, {dir + "/shared.pvs", "", false});
  EXPECT_EQ(read_file(dir + "/alone.pvs"), read_file(dir + "/shared.pvs"));

  // 9 cells x 2 rectangles x 4 edges x 2 runs = 144 runs. Run 0 of the 72 edges covers
  // 2 levels x (3 x 4 + 4 x 3) = 48 distinct edges: 24 are served from the cache.
  EXPECT_EQ(a.segment_runs_computed, 144u);
  EXPECT_EQ(a.segment_runs_shared, 0u);
  EXPECT_EQ(b.segment_runs_computed, 120u);
  EXPECT_EQ(b.segment_runs_shared, 24u);
  // Each cell also equals bake_cell, which shares nothing.
  pvs::Reader r = pvs::Reader::from_file(dir + "/shared.pvs");
  for (uint32_t c = 0; c < 9; ++c)
    EXPECT_EQ(r.read_cell(c), bake_cell(scene, r.info().layout, c, alone)) << "cell " << c;
}

TEST(BakeSharedSegments, ShardsShareOnlyTheirOwnCellsAndMergeToTheSameBytes) {
  const Scene scene = small_city();
  const ViewCells cells = city_grid(30, 4, 1);
  BakeSettings s;
  s.region.segment.resolution = 16;
  s.long_segments = 1;  // edges only (BakeLongSegments merges shards of long segments)
  const std::string dir = temp_dir("bake_shared_shards");
  bake(scene, cells, s, {}, {dir + "/whole.pvs", "", false});
  std::vector<pvs::Reader> shards;
  uint64_t shared = 0;
  for (uint32_t i = 0; i < 2; ++i) {
    const std::string path = dir + "/s" + std::to_string(i) + ".pvs";
    // Shard i holds cells i and i + 2 of a row of 4: they share no edge.
    shared += bake(scene, cells, s, {i, 2}, {path, "", false}).segment_runs_shared;
    shards.push_back(pvs::Reader::from_file(path));
  }
  EXPECT_EQ(shared, 0u);
  EXPECT_EQ(pvs::merge_pvs(shards), read_file(dir + "/whole.pvs"));
}

TEST(SegmentRunCache, ConcurrentCallersComputeOnceAndTheEntryIsFreedAfterItsLastUse) {
  SegmentRunCache cache;
  const Vec3 a{0, 1.5, 0}, b{1, 1.5, 0};
  for (int i = 0; i < 3; ++i) cache.expect(a, b);
  std::atomic<int> computations{0};
  auto compute = [&](Vec3, Vec3, const std::vector<double>&) {
    ++computations;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // others arrive meanwhile
    SegmentResult r;
    r.visible = {7, 9};
    return r;
  };
  std::vector<std::thread> threads;
  std::atomic<int> right{0};
  for (int i = 0; i < 3; ++i)
    threads.emplace_back([&] {
      if (cache.get(a, b, compute)->visible == std::vector<uint32_t>{7, 9}) ++right;
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(computations.load(), 1);
  EXPECT_EQ(right.load(), 3);
  EXPECT_EQ(cache.runs_computed(), 1u);
  EXPECT_EQ(cache.runs_shared(), 2u);
  EXPECT_EQ(cache.entries_held(), 0u);
  // A fourth, unannounced use computes again; -0.0 is another segment than +0.0 (bitwise keys).
  bool computed = false;
  cache.get(a, b, compute, &computed);
  EXPECT_TRUE(computed);
  cache.expect({-0.0, 1.5, 0}, b);
  cache.expect({-0.0, 1.5, 0}, b);
  cache.get(a, b, compute, &computed);
  EXPECT_TRUE(computed);
  EXPECT_EQ(cache.entries_held(), 1u);
  EXPECT_EQ(computations.load(), 3);
}

TEST(SegmentRunCache, AnExceptionReachesEveryWaitingCaller) {
  SegmentRunCache cache;
  const Vec3 a{0, 0, 0}, b{0, 0, 1};
  cache.expect(a, b);
  cache.expect(a, b);
  auto failing = [](Vec3, Vec3, const std::vector<double>&) -> SegmentResult {
    throw std::runtime_error("kernel failed");
  };
  EXPECT_THROW(cache.get(a, b, failing), std::runtime_error);
  EXPECT_THROW(cache.get(a, b, failing), std::runtime_error);
  EXPECT_EQ(cache.entries_held(), 0u);
}

// Long segments: end-to-end edges on one line form chains of at most max_parts;
// one computation per chain, split at the junctions, each edge gets its part.
TEST(SegmentRunCache, ChainsOfEdgesEndToEndRunOnceAndHandEachEdgeItsPart) {
  SegmentRunCache cache;
  std::vector<std::pair<Vec3, Vec3>> segs;
  for (int i = 0; i < 5; ++i) segs.push_back({{double(i), 1.5, 2}, {double(i + 1), 1.5, 2}});
  segs.push_back({{0, 1.5, 7}, {1, 1.5, 7}});   // alone on its line: no chain
  segs.push_back({{9, 1.5, 2}, {10, 1.5, 2}});  // same line, not touching: no chain
  cache.plan_chains(segs, 3);
  EXPECT_EQ(cache.chains_planned(), 2u);  // [0, 3] and [3, 5]
  for (const auto& [a, b] : segs) cache.expect(a, b);
  std::vector<std::pair<Vec3, Vec3>> runs;
  std::vector<std::vector<double>> splits;
  auto compute = [&](Vec3 a, Vec3 b, const std::vector<double>& s) {
    runs.push_back({a, b});
    splits.push_back(s);
    SegmentResult r;
    if (s.empty()) r.visible = {uint32_t(10 * a.x)};
    for (size_t i = 0; !s.empty() && i <= s.size(); ++i)
      r.visible_parts.push_back({uint32_t(10 * a.x + i)});
    return r;
  };
  std::vector<uint32_t> got;
  for (const auto& [a, b] : segs) got.push_back(cache.get(a, b, compute)->visible.at(0));
  EXPECT_EQ(got, (std::vector<uint32_t>{0, 1, 2, 30, 31, 0, 90}));
  ASSERT_EQ(runs.size(), 4u);
  EXPECT_EQ(runs[0].first.x, 0.0);
  EXPECT_EQ(runs[0].second.x, 3.0);
  EXPECT_EQ(splits[0], (std::vector<double>{1.0 / 3, 2.0 / 3}));
  EXPECT_EQ(splits[1], (std::vector<double>{0.5}));
  EXPECT_TRUE(splits[2].empty());
  EXPECT_EQ(cache.runs_computed(), 4u);
  EXPECT_EQ(cache.runs_shared(), 3u);
  EXPECT_EQ(cache.entries_held(), 0u);
}

// An 8 x 8 grid of 8 m cells over the small city, N = 16, for the long-segment bakes.
ViewCells long_grid() {
  return city_grid(32, 8, 8, EyeBand{1.5, 1.75});
}
BakeSettings long_settings(int long_segments) {
  BakeSettings s;
  s.region.segment.resolution = 16;
  s.long_segments = long_segments;
  return s;
}

TEST(BakeLongSegments, SetsEqualBakingEachCellAloneWithFarFewerRuns) {
  const Scene scene = small_city();
  const ViewCells cells = long_grid();
  const BakeSettings s = long_settings(4);
  const std::string dir = temp_dir("bake_long_segments");
  tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  const BakeReport r = bake(scene, cells, s, {}, {dir + "/long.pvs", "", false});
  // 64 cells x 8 edges = 512 uses; 2 levels x 2 directions x 9 lines x 2 chains of 4 = 72 runs.
  EXPECT_EQ(r.segment_runs_computed, 72u);
  EXPECT_EQ(r.segment_runs_shared, 512u - 72u);
  BakeSettings alone = s;
  alone.share_segments = false;
  pvs::Reader long_file = pvs::Reader::from_file(dir + "/long.pvs");
  EXPECT_NE(long_file.info().metadata.find("\"long_segments\":4"), std::string::npos);
  for (uint32_t c = 0; c < 64; ++c)
    EXPECT_EQ(long_file.read_cell(c), bake_cell(scene, long_file.info().layout, c, alone))
        << "cell " << c;
  // Shards plan the same chains (from every cell of the layout), so they merge to the same bytes.
  std::vector<pvs::Reader> shards;
  for (uint32_t i = 0; i < 3; ++i) {
    const std::string path = dir + "/s" + std::to_string(i) + ".pvs";
    bake(scene, cells, s, {i, 3}, {path, "", false});
    shards.push_back(pvs::Reader::from_file(path));
  }
  EXPECT_EQ(pvs::merge_pvs(shards), read_file(dir + "/long.pvs"));
}

TEST(LongSegmentChoice, PicksTheLongestLengthFivePercentCheaperThanEveryShorterOne) {
  auto pick = [](std::vector<double> costs) {
    std::vector<LongSegmentCandidate> c;
    for (size_t i = 0; i < costs.size(); ++i) {
      c.emplace_back();
      c.back().parts = 1 << i;
      c.back().cost = costs[i];
    }
    return pick_long_segments(c);
  };
  EXPECT_EQ(pick({100, 95, 80, 79}), 4);  // 95 is not 5% below 100; 79 not 5% below 80
  EXPECT_EQ(pick({100, 120, 85, 70}), 8);
  EXPECT_EQ(pick({100, 96, 120, 95}), 1);  // 95 is not 5% below 96
  EXPECT_EQ(pick({100, 94}), 2);
  EXPECT_EQ(pick({100}), 1);
}

TEST(SegmentRunCache, StretchesEndToEndAreMaximalAndIndependentOfTheSegmentsOrder) {
  std::vector<SegmentEnds> segs;
  for (int i = 0; i < 5; ++i) segs.push_back({{double(i), 1.5, 0}, {double(i + 1), 1.5, 0}});
  segs.push_back({{7, 1.5, 0}, {8, 1.5, 0}});  // alone on its line: no stretch
  segs.push_back({{0, 1.5, 2}, {0, 1.5, 3}});  // along z
  segs.push_back({{0, 1.5, 3}, {0, 1.5, 4}});
  segs.push_back({{2, 1.5, 0}, {3, 1.5, 0}});  // a duplicate counts once
  segs.push_back({{0, 1.5, 0}, {1, 1.5, 1}});  // not axis-parallel
  const std::vector<std::vector<SegmentEnds>> got = segments_end_to_end(segs);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].size(), 5u);
  EXPECT_EQ(got[0].front().first.x, 0.0);
  EXPECT_EQ(got[0].back().second.x, 5.0);
  EXPECT_EQ(got[1].size(), 2u);
  EXPECT_EQ(got[1].front().first.z, 2.0);
  std::vector<SegmentEnds> reversed(segs.rbegin(), segs.rend());
  EXPECT_EQ(segments_end_to_end(reversed), got);
}

// The pilot's choice follows the kernel's counts: many small cells over a large scene chain (a
// run costs far less than its length times an edge's), a few large cells over a small scene do
// not (a longer run holds more pieces per pixel and culls less). Bakes of such scenes measure
// the same way (docs/performance.md, "Choosing L").
TEST(LongSegmentChoice, ChainsSmallCellsOfALargeCityAndNotLargeCellsOfASmallOne) {
  CityOptions big;
  big.seed = 1;
  big.target_triangles = 100000;
  big.auto_blocks = true;
  const Scene large = generate_city(big);
  const TriangleBvh tree = build_triangle_bvh(large, 0);
  SegmentOptions o;
  o.resolution = 64;
  o.bvh = &tree;
  std::vector<SegmentEnds> row;  // 2 m cells along a street at eye height
  for (int i = 0; i < 8; ++i) row.push_back({{-8.0 + 2 * i, 1.5, 0}, {-6.0 + 2 * i, 1.5, 0}});
  const LongSegmentChoice chained = choose_long_segments(large, row, o);
  ASSERT_GE(chained.candidates.size(), 3u);
  EXPECT_EQ(chained.stretches_sampled, 1);
  EXPECT_EQ(chained.resolution, 64);  // the bake's own
  EXPECT_GT(chained.parts, 1);
  EXPECT_LT(chained.candidates[2].cost, chained.candidates[0].cost);

  // The quick start's case: 24 m cells over the 20K-triangle default city.
  const Scene small = load_scene(std::string(VISLIB_SOURCE_DIR) + "/data/city.glb");
  SegmentOptions so;
  so.resolution = 128;  // the quick start's
  std::vector<SegmentEnds> wide;
  for (int i = 0; i < 4; ++i)
    wide.push_back({{-96.0 + 24 * i, 1.6, 0.5}, {-72.0 + 24 * i, 1.6, 0.5}});
  const LongSegmentChoice alone = choose_long_segments(small, wide, so);
  // L = 2 costs more than L = 1, so the pilot stops there.
  ASSERT_EQ(alone.candidates.size(), 2u);
  EXPECT_EQ(alone.parts, 1);
  EXPECT_GE(alone.candidates[1].cost, alone.candidates[0].cost);
}

TEST(BakeLongSegmentsAuto, GivesTheBytesOfTheChosenLengthOnEveryShardAndThreadCount) {
  const Scene scene = small_city();
  const ViewCells cells = long_grid();
  const BakeSettings s = long_settings(0);  // auto
  const std::string dir = temp_dir("bake_long_auto");
  const BakeReport r = bake(scene, cells, s, {}, {dir + "/auto.pvs", "", false});
  ASSERT_GE(r.long_segment_choice.candidates.size(), 2u);
  EXPECT_EQ(r.long_segments, r.long_segment_choice.parts);
  BakeSettings fixed = s;
  fixed.long_segments = r.long_segments;
  const std::string autob = read_file(dir + "/auto.pvs");
  // The pilot's runs of the chosen L are handed to the bake (SegmentRunCache::provide) and count
  // as its own: the same runs, the same bytes.
  const BakeReport rf = bake(scene, cells, fixed, {}, {dir + "/fixed.pvs", "", false});
  EXPECT_EQ(read_file(dir + "/fixed.pvs"), autob);
  EXPECT_EQ(r.segment_runs_computed, rf.segment_runs_computed);
  EXPECT_EQ(r.segment_runs_shared, rf.segment_runs_shared);
  EXPECT_EQ(bake_bytes(scene, cells, s, dir + "/one.pvs", {}, 1), autob);
  std::vector<pvs::Reader> shards;
  for (uint32_t i = 0; i < 2; ++i) {
    const std::string path = dir + "/s" + std::to_string(i) + ".pvs";
    bake_bytes(scene, cells, s, path, {i, 2}, 2);
    shards.push_back(pvs::Reader::from_file(path));
  }
  EXPECT_EQ(pvs::merge_pvs(shards), autob);
  const std::string meta = pvs::Reader::from_memory(autob).info().metadata;
  EXPECT_EQ(meta.find("\"long_segments\":") != std::string::npos, r.long_segments > 1);
  const nlohmann::json j = nlohmann::json::parse(bake_report_json({}, r));
  EXPECT_EQ(j["long_segments"]["parts"], r.long_segments);
  EXPECT_EQ(j["long_segments"]["pilot"]["candidates"].size(),
            r.long_segment_choice.candidates.size());
  // Nothing to choose in a dynamic scene: no pilot, no long segments.
  GrassOptions go;
  go.size = 8;
  go.density = 2;
  go.states = 2;
  const Scene grass = generate_grass(go);
  const BakeReport g = bake(grass, city_grid(4, 2, 2), s, {}, {dir + "/grass.pvs", "", false});
  EXPECT_EQ(g.long_segments, 1);
  EXPECT_TRUE(g.long_segment_choice.candidates.empty());
}

TEST(SegmentRunCache, AProvidedRunIsHandedOutWithoutComputingItAgain) {
  SegmentRunCache cache;
  std::vector<SegmentEnds> segs;
  for (int i = 0; i < 4; ++i) segs.push_back({{double(i), 1.5, 0}, {double(i + 1), 1.5, 0}});
  cache.plan_chains(segs, 2);  // chains [0, 2] and [2, 4], each split at 0.5
  for (const auto& [a, b] : segs) cache.expect(a, b);
  cache.expect({9, 1.5, 0}, {9, 1.5, 1});  // a single segment
  SegmentResult chain;
  chain.visible = {7, 8};
  chain.visible_parts = {{7}, {8}};
  SegmentResult single;
  single.visible = {5};
  cache.provide({0, 1.5, 0}, {2, 1.5, 0}, {0.5}, chain);
  cache.provide({2, 1.5, 0}, {4, 1.5, 0}, {0.25}, chain);  // other splits: not that chain
  cache.provide({9, 1.5, 0}, {9, 1.5, 1}, {}, single);
  cache.provide({5, 1.5, 0}, {6, 1.5, 0}, {}, single);  // nobody expects it
  EXPECT_EQ(cache.runs_computed(), 2u);
  int computations = 0;
  auto compute = [&](Vec3, Vec3, const std::vector<double>& s) {
    ++computations;
    SegmentResult r;
    for (size_t i = 0; i <= s.size(); ++i) r.visible_parts.push_back({uint32_t(100 + i)});
    return r;
  };
  bool computed = false;
  EXPECT_EQ(cache.get(segs[1].first, segs[1].second, compute, &computed)->visible,
            std::vector<uint32_t>{8});
  EXPECT_TRUE(computed);  // the first use takes the provided run as its own
  EXPECT_EQ(cache.get(segs[0].first, segs[0].second, compute, &computed)->visible,
            std::vector<uint32_t>{7});
  EXPECT_FALSE(computed);
  EXPECT_EQ(cache.get({9, 1.5, 0}, {9, 1.5, 1}, compute, &computed)->visible,
            std::vector<uint32_t>{5});
  EXPECT_TRUE(computed);
  EXPECT_EQ(computations, 0);
  EXPECT_EQ(cache.get(segs[2].first, segs[2].second, compute)->visible, std::vector<uint32_t>{100});
  EXPECT_EQ(computations, 1);
  EXPECT_EQ(cache.runs_computed(), 3u);
  EXPECT_EQ(cache.runs_shared(), 1u);  // the chain's second use
}

TEST(SegmentRunCache, ConcurrentUsesOfAChainComputeItOnceAndReleaseEveryPart) {
  SegmentRunCache cache;
  std::vector<std::pair<Vec3, Vec3>> segs;
  for (int i = 0; i < 3; ++i) segs.push_back({{0, 1.5, double(i)}, {0, 1.5, double(i + 1)}});
  cache.plan_chains(segs, 8);
  ASSERT_EQ(cache.chains_planned(), 1u);
  for (int k = 0; k < 2; ++k)
    for (const auto& [a, b] : segs) cache.expect(a, b);
  std::atomic<int> computations{0};
  auto compute = [&](Vec3, Vec3, const std::vector<double>& s) {
    ++computations;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // others arrive meanwhile
    SegmentResult r;
    for (size_t i = 0; i <= s.size(); ++i) r.visible_parts.push_back({uint32_t(i)});
    return r;
  };
  std::atomic<int> right{0};
  std::vector<std::thread> threads;
  for (int k = 0; k < 6; ++k)
    threads.emplace_back([&, k] {
      const auto& [a, b] = segs[size_t(k % 3)];
      if (cache.get(a, b, compute)->visible == std::vector<uint32_t>{uint32_t(k % 3)}) ++right;
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(computations.load(), 1);
  EXPECT_EQ(right.load(), 6);
  EXPECT_EQ(cache.entries_held(), 0u);
  // A seventh use, not announced, runs the chain again.
  bool computed = false;
  EXPECT_EQ(cache.get(segs[1].first, segs[1].second, compute, &computed)->visible,
            std::vector<uint32_t>{1});
  EXPECT_TRUE(computed);
  EXPECT_EQ(computations.load(), 2);
}

// Options of the band tests' cell runs (N = 128, one orientation), and whether a run's set holds
// the quad whose first triangle is `quad`.
RegionOptions band_test_options() {
  RegionOptions o;
  o.segment.resolution = 128;
  o.runs = 1;
  o.seed = 3;
  return o;
}
bool sees_quad(const CellVisibility& v, uint32_t quad) {
  return std::binary_search(v.triangles.begin(), v.triangles.end(), quad) ||
         std::binary_search(v.triangles.begin(), v.triangles.end(), quad + 1);
}

TEST(BandLevels, AnEdgeAtMidBandSeesThroughSlitsThatTheBottomAndTopPerimetersCannot) {
  // Two walls across z (at 5 and 10) with a slit at y 1.4..1.6 each, and a target behind them at
  // the slits' height. The cell's eye band is y 1..2 over [-1, 1]^2: a line from y 1 (or 2)
  // through both slits would need a slope in [0.4, 0.6] / d1 and in [0.4, 0.6] / (d1 + 5) at
  // once, impossible for d1 <= 6, while the horizontal line at y 1.5 passes both.
  Scene scene;
  for (double z : {5.0, 10.0}) {
    vislib_test::add_quad(scene, {-50, -50, z}, {50, -50, z}, {50, 1.4, z}, {-50, 1.4, z});
    vislib_test::add_quad(scene, {-50, 1.6, z}, {50, 1.6, z}, {50, 50, z}, {-50, 50, z});
  }
  const uint32_t target = uint32_t(scene.triangle_count());
  vislib_test::add_quad(scene, {-2, 1.3, 20}, {2, 1.3, 20}, {2, 1.7, 20}, {-2, 1.7, 20});
  // The oracle: an eye inside the band sees the target.
  const OracleSample hit = brute_force_first_hit(scene, 0, {0.3, 1.5, 0}, {0, 0, 1}, 1e-3);
  ASSERT_FALSE(hit.ambiguous);
  ASSERT_TRUE(hit.tri == target || hit.tri == target + 1);

  Box3 box;
  box.extend({-1, 0, -1});
  box.extend({1, 3, 1});
  ViewCells cells = grid_cells(box, 1, 1, 1, EyeBand{1, 2});
  const RegionOptions o = band_test_options();
  auto sees_target = [&](const CellVisibility& v) { return sees_quad(v, target); };
  const CellVisibility two = cell_visibility(scene, cells, 0, o);
  EXPECT_FALSE(sees_target(two)) << "the bottom and top perimeters see through both slits";
  EXPECT_EQ(two.segments.size(), 8u);
  cells.band_levels = 3;
  const CellVisibility three = cell_visibility(scene, cells, 0, o);
  EXPECT_TRUE(sees_target(three));
  ASSERT_EQ(three.segments.size(), 12u);
  for (size_t k = 4; k < 8; ++k) {  // the middle rectangle, bottom first
    EXPECT_EQ(three.segments[k].from.y, 1.5);
    EXPECT_EQ(three.segments[k].to.y, 1.5);
  }
  // Everything the paper's rule sees is still seen (its segments are among these).
  EXPECT_TRUE(std::includes(three.triangles.begin(), three.triangles.end(), two.triangles.begin(),
                            two.triangles.end()));
  // The region's vertical edges pass through the slits' height at the corners: with them the
  // bottom and top levels alone see the target.
  cells.band_levels = 2;
  cells.vertical_edges = true;
  const CellVisibility edges = cell_visibility(scene, cells, 0, o);
  EXPECT_TRUE(sees_target(edges));
  ASSERT_EQ(edges.segments.size(), 12u);
  for (size_t k = 8; k < 12; ++k) {  // after the rectangles, bottom to top
    EXPECT_EQ(edges.segments[k].from.y, 1);
    EXPECT_EQ(edges.segments[k].to.y, 2);
    EXPECT_EQ(edges.segments[k].from.x, edges.segments[k].to.x);
    EXPECT_EQ(edges.segments[k].from.z, edges.segments[k].to.z);
  }
  cells.vertical_edges = false;
  // Placed cells record a choice other than the paper's.
  CellPlacement p;
  p.box = box;
  p.grid = std::array<uint32_t, 3>{1, 1, 1};
  p.eye = EyeBand{1, 2};
  EXPECT_EQ(nlohmann::json::parse(place_view_cells(scene, p).description).count("band_levels"), 0u);
  p.band_levels = 3;
  const ViewCells placed = place_view_cells(scene, p);
  EXPECT_EQ(placed.band_levels, 3);
  EXPECT_EQ(nlohmann::json::parse(placed.description).at("band_levels"), 3);
  EXPECT_FALSE(placed.vertical_edges);  // a grid's default
  p.vertical_edges = true;
  const ViewCells with_edges = place_view_cells(scene, p);
  EXPECT_TRUE(with_edges.vertical_edges);
  const std::string md =
      nlohmann::json{{"cells", nlohmann::json::parse(with_edges.description)}}.dump();
  EXPECT_TRUE(vertical_edges_of(md));
  EXPECT_FALSE(vertical_edges_of(
      nlohmann::json{{"cells", nlohmann::json::parse(placed.description)}}.dump()));
}

// A building (x 4..6, z 4..14, walls y 0..10, wound to face out) stands in a cell over
// [0, 10]^2 whose eye band is y 1.5..1.8; a roof at y 20 covers everything but a hole above the
// strip just west of the building, and a target at y 50 lies above the hole. An eye next to the
// building's west wall sees the target straight up through the hole; from the perimeter of the
// band's rectangles (x or z 0 or 10), a line through the hole lands at y 50 at least 1.6 times
// its distance to the hole beyond it, far off the target (x 1.96..5.96, z 3..7).
Scene building_under_a_holed_roof(uint32_t* target) {
  Scene scene;
  vislib_test::add_quad(scene, {4, 0, 4}, {4, 0, 14}, {4, 10, 14}, {4, 10, 4});    // west, -x
  vislib_test::add_quad(scene, {6, 0, 14}, {6, 0, 4}, {6, 10, 4}, {6, 10, 14});    // east, +x
  vislib_test::add_quad(scene, {6, 0, 4}, {4, 0, 4}, {4, 10, 4}, {6, 10, 4});      // south, -z
  vislib_test::add_quad(scene, {4, 0, 14}, {6, 0, 14}, {6, 10, 14}, {4, 10, 14});  // north, +z
  const double hx0 = 3.86, hx1 = 4.06, hz0 = 4.5, hz1 = 5.5, y = 20;
  vislib_test::add_quad(scene, {-50, y, -50}, {hx0, y, -50}, {hx0, y, 50}, {-50, y, 50});
  vislib_test::add_quad(scene, {hx1, y, -50}, {50, y, -50}, {50, y, 50}, {hx1, y, 50});
  vislib_test::add_quad(scene, {hx0, y, -50}, {hx1, y, -50}, {hx1, y, hz0}, {hx0, y, hz0});
  vislib_test::add_quad(scene, {hx0, y, hz1}, {hx1, y, hz1}, {hx1, y, 50}, {hx0, y, 50});
  *target = uint32_t(scene.triangle_count());
  vislib_test::add_quad(scene, {1.96, 50, 3}, {5.96, 50, 3}, {5.96, 50, 7}, {1.96, 50, 7});
  return scene;
}

TEST(WallTraces, AreTheWallsAtMidBandOffTheirFrontClippedToTheCellAndJoined) {
  uint32_t target = 0;
  const Scene scene = building_under_a_holed_roof(&target);
  Box3 region;
  region.extend({0, 1.5, 0});
  region.extend({10, 1.8, 10});
  WallTraceOptions o;
  o.clearance = 0.04;
  const std::vector<Segment> t = wall_traces(scene, region, o);
  // West, east and south walls, each quad's two triangles joined into one segment; the north wall
  // lies outside the cell, the roof and the target are not walls.
  ASSERT_EQ(t.size(), 3u);
  auto near = [](Vec3 a, Vec3 b) { return length(a - b) < 1e-12; };
  auto is = [&](const Segment& s, Vec3 a, Vec3 b) {
    return (near(s.from, a) && near(s.to, b)) || (near(s.from, b) && near(s.to, a));
  };
  EXPECT_TRUE(is(t[0], {3.96, 1.65, 4}, {3.96, 1.65, 10})) << t[0].from.x << " " << t[0].to.z;
  EXPECT_TRUE(is(t[1], {6.04, 1.65, 4}, {6.04, 1.65, 10}));
  EXPECT_TRUE(is(t[2], {4, 1.65, 3.96}, {6, 1.65, 3.96}));
  // Wound the other way, the fronts face into the building.
  o.clockwise_front = true;
  const std::vector<Segment> inside = wall_traces(scene, region, o);
  ASSERT_EQ(inside.size(), 3u);
  EXPECT_TRUE(is(inside[0], {4.04, 1.65, 4}, {4.04, 1.65, 10}));
  // A layout's cells get what their regions get.
  o.clockwise_front = false;
  const ViewCells cells = grid_cells(Box3{{0, 0, 0}, {10, 3, 10}}, 1, 1, 1, EyeBand{1.5, 1.8});
  const std::vector<std::vector<Segment>> per_cell = wall_traces(scene, cells.layout, o);
  ASSERT_EQ(per_cell.size(), 1u);
  ASSERT_EQ(per_cell[0].size(), 3u);
  for (size_t k = 0; k < 3; ++k)
    EXPECT_TRUE(near(per_cell[0][k].from, t[k].from) && near(per_cell[0][k].to, t[k].to));
}

TEST(WallTraces, AnEyeNextToAWallInsideTheCellSeesWhatThePerimetersCannot) {
  uint32_t target = 0;
  const Scene scene = building_under_a_holed_roof(&target);
  // The oracle: an eye of the band next to the west wall sees the target.
  const OracleSample hit = brute_force_first_hit(scene, 0, {3.95, 1.6, 5}, {0, 1, 0}, 1e-3);
  ASSERT_FALSE(hit.ambiguous);
  ASSERT_TRUE(hit.tri == target || hit.tri == target + 1);

  CellPlacement p;
  p.box = Box3{{0, 0, 0}, {10, 3, 10}};
  p.grid = std::array<uint32_t, 3>{1, 1, 1};
  p.eye = EyeBand{1.5, 1.8};
  const RegionOptions o = band_test_options();
  auto sees_target = [&](const CellVisibility& v) { return sees_quad(v, target); };
  const ViewCells perimeters = place_view_cells(scene, p);  // a grid: no traces by default
  EXPECT_TRUE(perimeters.wall_traces.empty());
  EXPECT_EQ(nlohmann::json::parse(perimeters.description).count("wall_traces"), 0u);
  const CellVisibility without = cell_visibility(scene, perimeters, 0, o);
  EXPECT_FALSE(sees_target(without)) << "the band's perimeters see through the hole";
  EXPECT_EQ(without.segments.size(), 8u);

  p.wall_traces = true;
  const ViewCells traced = place_view_cells(scene, p);
  ASSERT_EQ(traced.wall_traces.size(), 1u);
  EXPECT_EQ(traced.wall_traces[0].size(), 3u);
  const nlohmann::json recorded = nlohmann::json::parse(traced.description).at("wall_traces");
  EXPECT_DOUBLE_EQ(recorded.at("clearance").get<double>(),
                   kWallTraceClearanceFactor * kDefaultNear);
  EXPECT_EQ(recorded.at("front_faces"), "counter-clockwise");
  const CellVisibility with = cell_visibility(scene, traced, 0, o);
  EXPECT_TRUE(sees_target(with));
  EXPECT_EQ(with.segments.size(), 11u);  // the traces run after the rectangles (a grid: no edges)
  EXPECT_TRUE(std::includes(with.triangles.begin(), with.triangles.end(), without.triangles.begin(),
                            without.triangles.end()));
  // The file's metadata gives the options back (pvs inspect draws the traces from them).
  const std::optional<WallTraceOptions> back =
      wall_traces_of(nlohmann::json{{"cells", nlohmann::json::parse(traced.description)}}.dump());
  ASSERT_TRUE(back.has_value());
  EXPECT_DOUBLE_EQ(back->clearance, kWallTraceClearanceFactor * kDefaultNear);
  EXPECT_FALSE(back->clockwise_front);
  EXPECT_FALSE(wall_traces_of(
      nlohmann::json{{"cells", nlohmann::json::parse(perimeters.description)}}.dump()));
}
