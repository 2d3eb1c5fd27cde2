// bake_speed_bench.cpp: a bake's speed in cells per minute, with and without the
// edges shared between cells (segment_run_cache.h).
//
// A third configuration runs long segments (--long L, default 8; 1 skips it): up to L cell edges
// end to end as one split run. Its file records the setting in the metadata, so its sets are
// compared cell by cell with the plain bake's (cells that differ and ids that differ, printed).
//
// The scene is `pvs generate city --target-triangles T --seed 1` (default T = 1,000,000); the
// cells are walkable 2 m columns (eye band 1.5..1.8 m) of a 200 x 200 m block centred on the
// city. Baking all ~10,000 of them takes hours on a small machine, so the figure is measured on a
// square sample of --sample metres at the block's centre (default 16 m: 64 columns before the
// headroom rule drops those under buildings) and reported per minute. Each configuration bakes the
// same cells to a file in a temporary folder; the files with and without sharing must be
// byte-identical (checked; exit 1 otherwise).
//
//   bake_speed_bench [--triangles T] [--sample S] [--res N] [--runs K] [--long L|auto]
//                    [--cores 1|all|both] [--no-bvh]
// --no-bvh: the runs bin every triangle on every face instead of walking the BVH (BakeSettings::
// bvh); the file hashes printed must equal those of a run without it.
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "bench/peak_memory.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/bake.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/generate.h"

using namespace vislib;
using vislib_bench::peak_mb;
using vislib_bench::reset_peak;

namespace {

// CPU seconds of the whole process (user + system): on one core the fair figure on a loaded
// machine, where wall time also counts other processes' turns.
double process_cpu() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace

int main(int argc, char** argv) {
  size_t triangles = 1000000;
  double sample = 16;
  int res = 512, runs = 1, long_parts = 8;
  std::string cores = "both";
  bool bvh = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--no-bvh") {
      bvh = false;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr,
                   "usage: bake_speed_bench [--triangles T] [--sample S] [--res N] [--runs K] "
                   "[--long L|auto] [--cores 1|all|both] [--no-bvh]\n");
      return 2;
    }
    const std::string v = argv[++i];
    if (a == "--triangles")
      triangles = std::stoul(v);
    else if (a == "--sample")
      sample = std::stod(v);
    else if (a == "--res")
      res = std::stoi(v);
    else if (a == "--runs")
      runs = std::stoi(v);
    else if (a == "--long")
      long_parts = v == "auto" ? 0 : std::stoi(v);
    else if (a == "--cores")
      cores = v;
    else {
      std::fprintf(stderr, "bake_speed_bench: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  CityOptions co;
  co.seed = 1;
  co.target_triangles = triangles;
  co.auto_blocks = true;
  const Scene scene = generate_city(co);
  const Box3 bounds = scene.bounds();
  const Vec3 c = (bounds.min + bounds.max) * 0.5;
  WalkableOptions wo;
  wo.cell_size = 2;
  Box3 clip;
  clip.extend({c.x - sample / 2, bounds.min.y - 1, c.z - sample / 2});
  clip.extend({c.x + sample / 2, bounds.max.y + 1, c.z + sample / 2});
  wo.clip = clip;
  const ViewCells cells = walkable_cells(scene, wo);
  const uint32_t n = cells.layout.cell_count();
  std::printf(
      "bake_speed_bench: city of %zu triangles; %u walkable 2 m cells in the %.0f x %.0f m "
      "sample at the centre of the 200 x 200 m block; N = %d, K = %d\n",
      scene.triangle_count(), n, sample, sample, res, runs);
  std::printf("%-6s %-7s %10s %10s %10s %14s %12s %12s %10s %16s %7s\n", "cores", "shared",
              "wall s", "CPU s", "cells/min", "cells/CPU-min", "runs comp.", "runs shared",
              "peak MB", "file hash", "bvh s");
  const std::string dir =
      (std::filesystem::temp_directory_path() / ("bake_speed_bench_" + std::to_string(::getpid())))
          .string();
  std::filesystem::create_directories(dir);
  int status = 0;
  for (const char* k : {"1", "all"}) {
    if (cores != "both" && cores != k) continue;
    std::unique_ptr<tbb::global_control> limit;
    if (std::string(k) == "1")
      limit =
          std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
    std::string bytes[3];
    for (int share = 0; share < (long_parts != 1 ? 3 : 2); ++share) {
      BakeSettings s;
      s.region.segment.resolution = res;
      s.region.runs = runs;
      s.share_segments = share >= 1;
      s.long_segments = share == 2 ? long_parts : 1;
      s.bvh = bvh;
      const std::string path = dir + "/" + k + "_" + std::to_string(share) + ".pvs";
      reset_peak();
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = process_cpu();
      const BakeReport r = bake(scene, cells, s, {}, {path, "", false});
      const double sec =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double cpu = process_cpu() - c0;
      const std::string label =
          share == 2   ? (long_parts == 0 ? "auto" : "long") + std::to_string(r.long_segments)
          : share == 1 ? "yes"
                       : "no";
      bytes[share] = read_file(path);
      uint64_t h = 1469598103934665603ull;  // FNV-1a of the file: compare runs with --no-bvh
      for (unsigned char ch : bytes[share]) h = (h ^ ch) * 1099511628211ull;
      std::printf("%-6s %-7s %10.2f %10.2f %10.1f %14.1f %12llu %12llu %10.1f %016llx %7.3f\n", k,
                  label.c_str(), sec, cpu, 60.0 * n / sec, 60.0 * n / cpu,
                  (unsigned long long)r.segment_runs_computed,
                  (unsigned long long)r.segment_runs_shared, peak_mb(), (unsigned long long)h,
                  r.bvh_seconds);
      if (!r.long_segment_choice.candidates.empty()) {
        std::printf("       auto: pilot of %d stretches at N = %d, %.2f s wall:",
                    r.long_segment_choice.stretches_sampled, r.long_segment_choice.resolution,
                    r.long_segment_choice.seconds);
        for (const LongSegmentCandidate& lc : r.long_segment_choice.candidates)
          std::printf(" L=%d %.3g s (work %.3g: pairs %.3g, tiles %.3g, nodes %.3g, bounded %.3g)",
                      lc.parts, lc.seconds, lc.cost, double(lc.stats.covered_pairs),
                      double(lc.stats.triangle_tiles), double(lc.stats.bvh_nodes_opened),
                      double(lc.stats.primitives_bounded));
        std::printf("\n");
      }
      std::fflush(stdout);
    }
    if (bytes[0] != bytes[1]) {
      std::printf("bake_speed_bench: MISMATCH: the shared-edge bake differs from the plain one\n");
      status = 1;
    }
    if (!bytes[2].empty()) {
      // Long segments: the sets cell by cell against the plain bake.
      pvs::Reader plain = pvs::Reader::from_memory(bytes[0]),
                  split = pvs::Reader::from_memory(bytes[2]);
      uint32_t cells_differ = 0;
      uint64_t ids_differ = 0, ids = 0;
      for (uint32_t cell = 0; cell < n; ++cell) {
        const std::vector<uint32_t> a = plain.read_cell(cell), b = split.read_cell(cell);
        std::vector<uint32_t> diff;
        std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(),
                                      std::back_inserter(diff));
        cells_differ += diff.empty() ? 0 : 1;
        ids_differ += diff.size();
        ids += a.size();
      }
      std::printf("long segments: %u of %u cells differ from the plain bake, %llu of %llu ids\n",
                  cells_differ, n, (unsigned long long)ids_differ, (unsigned long long)ids);
    }
  }
  std::filesystem::remove_all(dir);
  return status;
}
