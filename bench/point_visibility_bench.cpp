// point_visibility_bench.cpp: one from-point first-hit cubemap (docs/visibility-math.md §8, Embree
// baseline) at N = 512 (6*512*512 = 1,572,864 rays) on a generated city: a 150 x 150 grid of boxes
// (12 triangles each, heights 2..30 m, 10 m pitch, 6 m footprint) on a ground quad, 270,002
// triangles. The eye is at street level (1.7 m) near the middle; orientation fixed (seed 1).
// Argument: TBB thread count (tbb::global_control), 1 and 2.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/point_visibility.h"

using namespace vislib;

namespace {

Scene box_city(int grid, uint64_t seed) {
  Scene s;
  s.positions.resize(1);
  s.objects.push_back({"city"});
  auto& p = s.positions[0];
  auto quad = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    s.triangles.push_back({a, b, c});
    s.triangles.push_back({a, c, d});
  };
  const double pitch = 10.0, half = 3.0, extent = grid * pitch;
  const uint32_t g = uint32_t(p.size());
  p.insert(p.end(), {{-5, -5, 0}, {extent, -5, 0}, {extent, extent, 0}, {-5, extent, 0}});
  quad(g, g + 1, g + 2, g + 3);
  Rng rng(seed);
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      const double cx = i * pitch, cy = j * pitch, h = rng.uniform(2.0, 30.0);
      const uint32_t b = uint32_t(p.size());
      for (int k = 0; k < 8; ++k)
        p.push_back(
            {cx + ((k & 1) ? half : -half), cy + ((k & 2) ? half : -half), (k & 4) ? h : 0.0});
      quad(b + 0, b + 1, b + 3, b + 2);  // bottom
      quad(b + 4, b + 5, b + 7, b + 6);  // top
      quad(b + 0, b + 1, b + 5, b + 4);  // y-
      quad(b + 2, b + 3, b + 7, b + 6);  // y+
      quad(b + 0, b + 2, b + 6, b + 4);  // x-
      quad(b + 1, b + 3, b + 7, b + 5);  // x+
    }
  s.triangle_object.assign(s.triangles.size(), 0);
  return s;
}

const Vec3 kEye{745.0, 752.0, 1.7};  // in a street (between boxes) near the middle

void BM_PointCubemap512(benchmark::State& state) {
  static const Scene scene = box_city(150, 1);
  static const EmbreeScene es(scene, 0.0, kEye);
  const Mat3 R = random_orientation(1);
  const int n = 512;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(state.range(0)));
  size_t visible = 0;
  for (auto _ : state) {
    auto cube = point_cubemap(es, kEye, R, n, 0.1);
    benchmark::DoNotOptimize(cube.data());
    visible = visible_set(cube).size();
  }
  const double rays = 6.0 * n * n;
  state.counters["rays/s"] =
      benchmark::Counter(rays * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["triangles"] = double(scene.triangle_count());
  state.counters["visible"] = double(visible);
}
BENCHMARK(BM_PointCubemap512)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
