// pvs bake: bake a scene's view cells into a PVS file (docs/bake.md); cmd_merge.cpp joins the
// shard files of a sharded bake.
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <set>
#include <string>

#include "cli/bake_options.h"
#include "cli/bake_progress.h"
#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "vislib/bake/bake.h"
#include "vislib/bake/bake_report.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/kernel/segment_run_cache.h"
#include "vislib/kernel/segment_visibility.h"

namespace pvs_cli {
namespace {

bool file_exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

const char* kind_name(const vislib::ViewCells& cells) {
  if (cells.layout.kind == pvs::LayoutKind::BspTree) return "bsp-leaves";
  return cells.layout.kind == pvs::LayoutKind::Grid ? "grid" : "walkable";
}

// After the bake: the checkpoint's damage, the summary, the --json report.
void report_bake(const BakeArgs& a, const vislib::BakeRunInfo& info, const vislib::BakeReport& r,
                 const std::string& checkpoint) {
  if (r.checkpoint_dropped_records && show_progress())  // a warning: -q silences it
    std::fprintf(stderr,
                 "pvs bake: checkpoint %s: %zu damaged or torn record(s) dropped (%llu bytes); "
                 "their cells "
                 "were baked again, %u valid records kept\n",
                 checkpoint.c_str(), r.checkpoint_dropped_records,
                 static_cast<unsigned long long>(r.checkpoint_dropped_bytes), r.resumed);
  const vislib::LongSegmentChoice& pilot = r.long_segment_choice;
  if (!pilot.candidates.empty() && show_progress()) {
    std::string est;
    for (const vislib::LongSegmentCandidate& c : pilot.candidates)
      est += fmt::format("{}L = {}: {:.3g}", est.empty() ? "" : ", ", c.parts, c.cost);
    std::fprintf(stderr,
                 "pvs bake: long segments: L = %d chosen by the pilot (%d rows of edges at N = %d, "
                 "%.2f s; estimated work in covered-pair equivalents %s)\n",
                 r.long_segments, pilot.stretches_sampled, pilot.resolution, pilot.seconds,
                 est.c_str());
  }
  const double kernel = vislib::kernel_seconds(r);
  const vislib::BakeTimes& t = r.times;
  const vislib::BakePhases& ph = t.phases;
  // The threads' time in the pipeline, by phase (wall seconds summed over threads).
  const double thread_seconds = std::max(1e-9, r.threads * r.seconds);
  auto share = [&](double wall) { return 100.0 * wall / thread_seconds; };
  if (show_progress())
    std::fprintf(
        stderr,
        "pvs bake: %u cell%s (%u baked, %u resumed) in %.2f s (%.3f s kernel per baked cell), "
        "%llu bytes (%.1f per cell) written to %s; %llu from-segment runs, %llu of them served "
        "by shared edges and long segments; %d thread%s: %.0f%% in runs, %.0f%% waiting on shared "
        "runs, %.0f%% helping other runs, %.0f%% idle, %.2f CPU s\n",
        r.shard_cells, plural_s(r.shard_cells), r.baked, r.resumed, r.seconds,
        r.baked ? kernel / r.baked : 0.0, static_cast<unsigned long long>(r.stats.file_bytes),
        r.shard_cells ? double(r.stats.block_bytes) / r.shard_cells : 0.0, a.output.c_str(),
        static_cast<unsigned long long>(r.segment_runs_computed + r.segment_runs_shared),
        static_cast<unsigned long long>(r.segment_runs_shared), r.threads, plural_s(r.threads),
        share(ph.runs.wall), share(ph.shared_waits.wall), share(ph.helping.wall),
        share(ph.idle.wall), t.process_cpu);
  pvs_cli::info(fmt::format(
      "bake: {} thread{} x {:.2f} s = {:.2f} thread-seconds; process CPU {:.2f} s; wall / CPU "
      "seconds by phase: runs {:.2f} / {:.2f}, waiting on shared runs {:.2f} / {:.2f}, merge "
      "{:.2f} / {:.2f}, rest of cells {:.2f} / {:.2f}, progress {:.2f} / {:.2f}, checkpoint "
      "{:.2f} / {:.2f}, encode {:.2f} / {:.2f}, write {:.2f} / {:.2f}, helping other runs {:.2f} / "
      "{:.2f}, trees over the runs' bounds {:.2f} / {:.2f}, idle {:.2f} / {:.2f}; "
      "before the cells: BVH {:.2f} / {:.2f}, pilot {:.2f} / {:.2f}",
      r.threads, plural_s(r.threads), r.seconds, r.threads * r.seconds, t.process_cpu, ph.runs.wall,
      ph.runs.cpu, ph.shared_waits.wall, ph.shared_waits.cpu, ph.merge.wall, ph.merge.cpu,
      ph.cell.wall, ph.cell.cpu, ph.progress.wall, ph.progress.cpu, ph.checkpoint.wall,
      ph.checkpoint.cpu, ph.encode.wall, ph.encode.cpu, ph.write.wall, ph.write.cpu,
      ph.helping.wall, ph.helping.cpu, ph.bound_trees.wall, ph.bound_trees.cpu, ph.idle.wall,
      ph.idle.cpu, ph.bvh.wall, ph.bvh.cpu, ph.pilot.wall, ph.pilot.cpu));
  if (a.json_out.empty()) return;
  const std::string text = vislib::bake_report_json(info, r);
  if (a.json_out == "-")
    std::fwrite(text.data(), 1, text.size(), stdout);
  else
    vislib::write_file_atomic(a.json_out, text);
}

void run_bake(BakeArgs& a, const CLI::App& cmd) {
  const vislib::Shard shard = parse_shard(a.shard);
  check_cells_options(a, cmd);
  apply_preset(a, cmd);
  vislib::BakeRunInfo info;
  info.scene = a.scene;
  info.output = a.output;
  info.preset = a.preset;
  info.resolution = a.resolution;
  info.runs = a.runs;
  if (a.grid.empty() && a.cells.empty()) info.cell_size = a.cell_size;
  info.shard = shard;
  // Every output is checked before any work.
  check_output_file(a.output, "--output");
  check_output_file(a.checkpoint.empty() ? a.output + ".ckpt" : a.checkpoint, "--checkpoint");
  if (!a.json_out.empty()) check_output_file(a.json_out, "--json", true);
  std::string checkpoint = a.checkpoint.empty() ? a.output + ".ckpt" : a.checkpoint;
  // One bake per output at a time (the checkpoint has its own lock too): taken before looking
  // at the checkpoint, so a second bake is told that the first is running (exit 2).
  std::unique_ptr<vislib::FileLock> lock;
  if (!a.dry_run) {
    lock = std::make_unique<vislib::FileLock>(a.output + ".lock", "the output " + a.output);
    vislib::remove_dead_writers_temps(a.output);  // a killed bake's: none of its writers lives
  }
  if (!a.resume && file_exists(checkpoint)) {
    std::fprintf(stderr,
                 "pvs: error: %s: a checkpoint of an interrupted bake exists: pass --resume to "
                 "continue it, or delete it to start over\n",
                 checkpoint.c_str());
    throw Exit{2};
  }
  auto t0 = std::chrono::steady_clock::now();
  // A Quake map is read and parsed once, for the scene and for its leaves or player starts.
  vislib::QuakeBsp map;
  const bool bsp = vislib::file_extension(a.scene) == ".bsp";
  vislib::Scene scene = load_scene_for_cli(a.scene, a.states, a.import, bsp ? &map : nullptr);
  if (scene.triangle_count() + scene.sphere_count() >= 0xFFFFFFFFull)
    throw vislib::InputError(a.scene, "more than 2^32-1 triangles and spheres");
  if (scene.has_see_through() && (scene.sphere_count() > 0 || scene.is_dynamic()))
    throw vislib::InputError(a.scene, vislib::kSeeThroughStaticOnly);
  vislib::ViewCells cells = vislib::with_memory_stage(
      "placing view cells", [&] { return make_cells(a, scene, bsp ? &map : nullptr); });
  info.setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  uint32_t n = cells.layout.cell_count();
  if (n == 0) {
    std::fprintf(stderr, "pvs: error: no view cells (no walkable floor in the scene%s)\n",
                 a.box.empty() ? "" : " within --box");
    throw Exit{2};
  }
  if (a.dry_run) {
    size_t segments = 0;                              // mean over the cells, rounded down
    std::set<vislib::SegmentRunCache::Key> distinct;  // runs shared between cells count once
    for (uint32_t c = 0; c < n; ++c)
      for (const auto& g : vislib::cell_segment_groups(cells, c)) {
        segments += g.size();
        if (cells.shared_runs)
          for (const vislib::Segment& s : g)
            distinct.insert(vislib::SegmentRunCache::key_of(s.from, s.to, run_key_normal(s)));
      }
    std::printf("%u cell%s (%s), %u in shard %u/%u, %zu boundary segments x %d runs per cell%s", n,
                plural_s(n), kind_name(cells), (n + shard.count - 1 - shard.index) / shard.count,
                shard.index, shard.count, segments / n, a.runs,
                cells.segments.empty() ? "" : " (mean)");
    if (cells.shared_runs)
      std::printf("; %zu distinct segments in all (a portal's serve both of its leaves%s)",
                  distinct.size(),
                  a.portal_edges == "shared" ? ", an edge the portals that meet there" : "");
    std::printf("\n");
    return;
  }
  if (a.resume && !file_exists(checkpoint) && show_progress())
    std::fprintf(stderr, "pvs bake: no checkpoint %s: starting from the beginning\n",
                 checkpoint.c_str());
  if (show_progress())
    std::fprintf(stderr, "pvs bake: %u cell%s (%s), %zu triangles, shard %u/%u\n", n, plural_s(n),
                 kind_name(cells), scene.triangle_count(), shard.index, shard.count);
  const vislib::BakeSettings settings = settings_of(a);
  if (settings.long_segments == 0 && show_progress() &&
      vislib::long_segments_apply(scene, settings))
    std::fprintf(stderr,
                 "pvs bake: --long-segments auto: a pilot runs a few rows of cell edges with "
                 "L = 1, 2, 4 and 8 and counts the kernel's work\n");
  vislib::BakeFiles files{a.output, checkpoint, a.resume, /*lock=*/false};
  const vislib::BakeReport r =
      vislib::bake(scene, cells, settings, shard, files, progress_printer());
  report_bake(a, info, r, checkpoint);
}

void add_bake(CLI::App& app) {
  auto a = std::make_shared<BakeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bake",
      "Bake a PVS file: the triangles (or objects) visible from every view cell, from-segment runs "
      "on the perimeter of the bottom and top rectangles of each cell's eye band. Cells: a grid "
      "over --box, --walkable cells over the floors of the scene, or a Quake map's BSP leaves "
      "(--cells bsp-leaves, segments sweeping each leaf's faces).");
  add_bake_options(cmd, *a);
  cmd->callback([a, cmd] { run_with_threads(a->threads, [&] { run_bake(*a, *cmd); }); });
}

Registration bake_registration("bake", add_bake);

}  // namespace
}  // namespace pvs_cli
