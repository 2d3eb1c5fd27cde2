// segment_visibility_bench.cpp: one from-segment run (6 faces, N = 512) against one Embree
// from-point cubemap at the same N, same eye, same orientation, in one process.
//
// Scenes: generated cities of about 100K, 300K and 1M triangles (pvs generate city
// --target-triangles T --seed 1), segment 20 m along the central street at eye height 1.7 m;
// and sauer_pandora from ../shared/scenes when present (a 2 m segment in its largest room).
//
//   segment_visibility_bench                 Google Benchmark timings with counters
//   segment_visibility_bench --ratio         a table: median of 3 runs of each, ratio, counts
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>

#include "vislib/eval/embree_scene.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/import.h"
#include "vislib/eval/point_visibility.h"
#include "vislib/kernel/segment_visibility.h"

using namespace vislib;

namespace {

struct BenchScene {
  std::string name;
  Scene scene;
  Vec3 v0, v1;
};

const int kN = 512;
const double kNear = 0.05;

std::vector<std::unique_ptr<BenchScene>>& scenes() {
  static std::vector<std::unique_ptr<BenchScene>> all = [] {
    std::vector<std::unique_ptr<BenchScene>> v;
    for (uint64_t target : {100000ull, 300000ull, 1000000ull}) {
      CityOptions o;
      o.seed = 1;
      o.target_triangles = target;
      o.auto_blocks = true;  // as `pvs generate city --target-triangles`
      auto b = std::make_unique<BenchScene>();
      b->scene = generate_city(o);
      b->name = "city" + std::to_string(b->scene.triangle_count() / 1000) + "k";
      // The generator centres the city on the origin; with an even block count a street runs
      // along x = 0.
      b->v0 = {0, 1.7, -10};
      b->v1 = {0, 1.7, 10};
      v.push_back(std::move(b));
    }
    std::string pandora = std::string(VISLIB_SOURCE_DIR) + "/../shared/scenes/sauer_pandora/pandora.obj";
    if (std::filesystem::exists(pandora)) {
      auto b = std::make_unique<BenchScene>();
      b->name = "pandora";
      b->scene = load_scene(pandora);
      Box3 bb = b->scene.bounds();
      Vec3 c = (bb.min + bb.max) * 0.5;
      b->v0 = c + Vec3{-1, 0, 0};
      b->v1 = c + Vec3{1, 0, 0};
      v.push_back(std::move(b));
    }
    return v;
  }();
  return all;
}

double peak_rss_mb() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;
}

SegmentResult run_segment(const BenchScene& b) {
  SegmentOptions o;
  o.resolution = kN;
  o.near = kNear;
  return segment_visibility(b.scene, b.v0, b.v1, o);
}

void BM_Segment512(benchmark::State& state, const BenchScene* b) {
  SegmentResult r;
  for (auto _ : state) r = run_segment(*b);
  state.counters["triangles"] = double(b->scene.triangle_count());
  state.counters["visible"] = double(r.visible.size());
  state.counters["pairs"] = double(r.stats.pair_tests);
  state.counters["pieces/pixel"] = r.stats.pieces_per_pixel();
  state.counters["peak_tile_MB"] = r.stats.peak_tile_bytes / 1048576.0;
  state.counters["peak_rss_MB"] = peak_rss_mb();
}

void BM_PointCubemap512(benchmark::State& state, const BenchScene* b) {
  EmbreeScene es(b->scene, 0.0, b->v0);
  size_t visible = 0;
  for (auto _ : state) {
    auto cube = point_cubemap(es, b->v0, Mat3{}, kN, kNear);
    visible = visible_set(cube).size();
  }
  state.counters["visible"] = double(visible);
}

template <class F>
double median_seconds(F f, int reps) {
  std::vector<double> t;
  for (int k = 0; k < reps; ++k) {
    auto s = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - s).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int ratio_table() {
  std::printf("%-10s %10s %12s %12s %8s %10s %10s %12s %10s\n", "scene", "triangles", "segment_s",
              "point_s", "ratio", "seg_vis", "point_vis", "pairs", "pcs/px");
  for (auto& b : scenes()) {
    SegmentResult r;
    double seg = median_seconds([&] { r = run_segment(*b); }, 3);
    EmbreeScene es(b->scene, 0.0, b->v0);
    size_t pv = 0;
    double pt = median_seconds([&] { pv = visible_set(point_cubemap(es, b->v0, Mat3{}, kN, kNear)).size(); }, 3);
    std::printf("%-10s %10zu %12.3f %12.4f %8.1f %10zu %10zu %12llu %10.2f\n", b->name.c_str(),
                b->scene.triangle_count(), seg, pt, seg / pt, r.visible.size(), pv,
                (unsigned long long)r.stats.pair_tests, r.stats.pieces_per_pixel());
    std::fflush(stdout);
  }
  std::printf("peak RSS %.0f MB\n", peak_rss_mb());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--ratio") == 0) return ratio_table();
  for (auto& b : scenes()) {
    benchmark::RegisterBenchmark(("Segment512/" + b->name).c_str(), BM_Segment512, b.get())
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("PointCubemap512/" + b->name).c_str(), BM_PointCubemap512, b.get())
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
