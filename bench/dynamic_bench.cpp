// dynamic_bench.cpp: the dynamic kernel's two comparisons, each
// measured in one process:
//  1. spheres handled directly against the same spheres tessellated into icospheres (moving
//     triangles), same segment, same N (the paper reports an order of magnitude);
//  2. dynamic against static cost on the same swaying grass: all K states (moving blades) against
//     the scene frozen at state 0 (the linear path).
//
//   dynamic_bench            Google Benchmark timings
//   dynamic_bench --table    one table with both ratios (median of 3 runs each)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>

#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/generate.h"

using namespace vislib;

namespace {

const int kN = 128;

// Icosphere of `subdiv` subdivisions around the origin, radius 1.
void icosphere(int subdiv, std::vector<Vec3>& verts, std::vector<std::array<uint32_t, 3>>& tris) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  verts = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  tris = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
          {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
          {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& v : verts) v = v * (1.0 / length(v));
  for (int s = 0; s < subdiv; ++s) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      Vec3 m = (verts[a] + verts[b]) * 0.5;
      verts.push_back(m * (1.0 / length(m)));
      return mid[key] = uint32_t(verts.size() - 1);
    };
    std::vector<std::array<uint32_t, 3>> next;
    for (auto& f : tris) {
      uint32_t a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    tris = next;
  }
}

// The spheres of `s` as moving icospheres (every state).
Scene tessellate(const Scene& s, int subdiv) {
  std::vector<Vec3> uv;
  std::vector<std::array<uint32_t, 3>> ut;
  icosphere(subdiv, uv, ut);
  Scene out;
  out.positions.resize(s.sphere_centers.size());
  for (size_t i = 0; i < s.sphere_count(); ++i) {
    uint32_t base = uint32_t(out.positions[0].size());
    for (size_t k = 0; k < s.sphere_centers.size(); ++k)
      for (const Vec3& v : uv)
        out.positions[k].push_back(s.sphere_centers[k][i] + v * s.sphere_radius[i]);
    for (auto f : ut) out.triangles.push_back({base + f[0], base + f[1], base + f[2]});
    out.triangle_object.insert(out.triangle_object.end(), ut.size(), uint32_t(i));
    out.objects.push_back({"sphere" + std::to_string(i)});
  }
  return out;
}

struct Scenes {
  Scene spheres, tessellated, grass, grass_static;
};

const Scenes& scenes() {
  static const Scenes s = [] {
    Scenes x;
    SphereOptions so;
    so.count = 300;
    so.states = 3;
    so.seed = 1;
    x.spheres = generate_spheres(so);
    x.tessellated = tessellate(x.spheres, 1);  // 80 triangles per sphere
    GrassOptions g;
    g.size = 20;
    g.target_triangles = 50000;
    g.states = 10;
    g.seed = 1;
    x.grass = generate_grass(g);
    x.grass_static = x.grass;
    x.grass_static.positions.resize(1);
    return x;
  }();
  return s;
}

SegmentResult run(const Scene& s, Vec3 a, Vec3 b) {
  SegmentOptions o;
  o.resolution = kN;
  return segment_visibility(s, a, b, o);
}

const Vec3 kSphereA{-5, 2, 0}, kSphereB{5, 2, 0};
const Vec3 kGrassA{-4, 1.0, 0}, kGrassB{4, 1.2, 1};

void BM_Spheres(benchmark::State& st) {
  for (auto _ : st)
    benchmark::DoNotOptimize(run(scenes().spheres, kSphereA, kSphereB).visible_spheres.size());
}
void BM_TessellatedSpheres(benchmark::State& st) {
  for (auto _ : st)
    benchmark::DoNotOptimize(run(scenes().tessellated, kSphereA, kSphereB).visible.size());
}
void BM_GrassDynamic(benchmark::State& st) {
  for (auto _ : st) benchmark::DoNotOptimize(run(scenes().grass, kGrassA, kGrassB).visible.size());
}
void BM_GrassStatic(benchmark::State& st) {
  for (auto _ : st)
    benchmark::DoNotOptimize(run(scenes().grass_static, kGrassA, kGrassB).visible.size());
}
BENCHMARK(BM_Spheres)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TessellatedSpheres)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_GrassDynamic)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_GrassStatic)->Unit(benchmark::kMillisecond)->UseRealTime();

double median3(const std::function<void()>& f) {
  double t[3];
  for (double& x : t) {
    auto s = std::chrono::steady_clock::now();
    f();
    x = std::chrono::duration<double>(std::chrono::steady_clock::now() - s).count();
  }
  std::sort(t, t + 3);
  return t[1];
}

int table() {
  const Scenes& s = scenes();
  size_t vs = 0, vt = 0, vd = 0, vst = 0;
  double ts = median3([&] { vs = run(s.spheres, kSphereA, kSphereB).visible_spheres.size(); });
  double tt = median3([&] {
    auto r = run(s.tessellated, kSphereA, kSphereB);
    std::vector<uint32_t> obj;
    for (uint32_t t : r.visible) obj.push_back(s.tessellated.triangle_object[t]);
    std::sort(obj.begin(), obj.end());
    vt = size_t(std::unique(obj.begin(), obj.end()) - obj.begin());
  });
  std::setvbuf(stdout, nullptr, _IONBF, 0);
  std::printf(
      "spheres: %zu spheres x %zu states, N=%d: direct %.3f s (%zu visible), tessellated "
      "(%zu triangles) %.3f s (%zu spheres visible): speedup %.1fx\n",
      s.spheres.sphere_count(), s.spheres.state_count(), kN, ts, vs, s.tessellated.triangle_count(),
      tt, vt, tt / ts);
  double td = median3([&] { vd = run(s.grass, kGrassA, kGrassB).visible.size(); });
  double tst = median3([&] { vst = run(s.grass_static, kGrassA, kGrassB).visible.size(); });
  std::printf(
      "grass: %zu triangles, N=%d: dynamic (%zu states) %.3f s (%zu visible), static (state 0) "
      "%.3f s "
      "(%zu visible): dynamic/static %.1fx\n",
      s.grass.triangle_count(), kN, s.grass.state_count(), td, vd, tst, vst, td / tst);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--table") == 0) return table();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
