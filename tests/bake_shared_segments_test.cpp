// Shared edges in a bake (issue 13 item 5): run 0 of an edge common to two cells is computed once
// (segment_run_cache.h), and the file is byte-identical to a bake that computes every cell alone.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <atomic>
#include <thread>

#include "tests/test_support.h"
#include "vislib/bake/bake.h"
#include "vislib/base/file_util.h"
#include "vislib/kernel/segment_run_cache.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using vislib_test::temp_dir;

namespace {

Scene small_city() {
  CityOptions o;
  o.blocks_x = o.blocks_z = 2;
  return generate_city(o);
}

}  // namespace

TEST(BakeSharedSegments, SetsEqualBakingEachCellAloneWithFewerRuns) {
  const Scene scene = small_city();
  Box3 box;
  box.extend({-30, 0, -30});
  box.extend({30, 3, 30});
  const ViewCells cells = grid_cells(box, 3, 1, 3, EyeBand{1.5, 1.8});
  BakeSettings s;
  s.region.segment.resolution = 16;
  s.region.runs = 2;  // run 1 is a per-cell random orientation: never shared
  s.region.seed = 5;
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
  Box3 box;
  box.extend({-30, 0, -30});
  box.extend({30, 3, 30});
  const ViewCells cells = grid_cells(box, 4, 1, 1, EyeBand{1.5, 1.8});
  BakeSettings s;
  s.region.segment.resolution = 16;
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
  auto compute = [&] {
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
  auto failing = []() -> SegmentResult { throw std::runtime_error("kernel failed"); };
  EXPECT_THROW(cache.get(a, b, failing), std::runtime_error);
  EXPECT_THROW(cache.get(a, b, failing), std::runtime_error);
  EXPECT_EQ(cache.entries_held(), 0u);
}
