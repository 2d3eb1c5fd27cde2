// pvs bake: bake a scene's view cells into a PVS file (docs/bake.md); cmd_merge.cpp joins the
// shard files of a sharded bake.
#include <fmt/format.h>
#include <sys/stat.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "cli/bake_progress.h"
#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "vislib/bake/bake.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

struct BakeArgs {
  std::string scene, output, checkpoint, json_out;
  std::string box, grid, eye, shard = "0/1";
  bool walkable = false, resume = false, no_headroom = false, dry_run = false;
  double cell_size = 0, max_slope = 45;
  int resolution = 512, runs = 1, threads = 0, tile = 32;
  uint64_t seed = 1;
  double near = vislib::kDefaultNear, eps_len = vislib::kDefaultEpsLen;
  std::string granularity = "triangle";
  std::string mode = "diagonal";
  std::string coplanar = "both";
  double eps_z = vislib::kDefaultEpsZ;
  int states = 1;
  std::string preset = "default";
};

// Quality presets (like vis's -fast / -level): what --preset sets unless given explicitly.
struct Preset {
  int resolution, runs;
  double cell_size;
};
Preset preset_values(const std::string& name) {
  if (name == "draft") return {128, 1, 8.0};
  if (name == "final") return {2048, 4, 1.0};
  return {512, 1, 2.0};  // default: the options' own defaults
}

vislib::Shard parse_shard(const std::string& text) {
  unsigned i = 0, n = 0;
  char extra;
  if (std::sscanf(text.c_str(), "%u/%u%c", &i, &n, &extra) != 2 || n == 0 || i >= n)
    throw CLI::ValidationError("--shard", "expected i/N with 0 <= i < N, got '" + text + "'");
  return {i, n};
}

vislib::ViewCells make_cells(const BakeArgs& a, const vislib::Scene& scene) {
  std::optional<vislib::EyeBand> eye;
  if (!a.eye.empty()) {
    auto h = parse_doubles(a.eye, "--eye-height", 2);
    if (!(h[0] <= h[1])) throw CLI::ValidationError("--eye-height", "expected h0,h1 with h0 <= h1");
    eye = vislib::EyeBand{h[0], h[1]};
  }
  std::optional<vislib::Box3> box;
  if (!a.box.empty()) {
    auto b = parse_doubles(a.box, "--box", 6);
    box = vislib::Box3{};
    box->extend({b[0], b[1], b[2]});
    box->extend({b[3], b[4], b[5]});
    for (int k = 0; k < 6; ++k)
      if (!std::isfinite(b[k])) throw CLI::ValidationError("--box", "coordinates must be finite");
  }
  if (a.walkable) {
    if (!a.grid.empty()) throw CLI::ValidationError("--grid", "cannot be combined with --walkable");
    vislib::WalkableOptions w;
    w.cell_size = a.cell_size > 0 ? a.cell_size : 2.0;
    if (eye) w.eye = *eye;
    w.max_slope_degrees = a.max_slope;
    w.require_headroom = !a.no_headroom;
    w.clip = box;
    vislib::Box3 r = box ? *box : scene.bounds();
    auto columns = [&](double extent) { return std::max(1.0, std::ceil(extent / w.cell_size)); };
    if (!r.empty() && columns(r.max.x - r.min.x) * columns(r.max.z - r.min.z) > 1e7)
      throw CLI::ValidationError("--cell-size",
                                 "more than 10^7 columns: use a larger cell size or a --box");
    return vislib::walkable_cells(scene, w);
  }
  if (!box)
    throw CLI::ValidationError("--box", "give --box with --grid or --cell-size, or --walkable");
  if (!a.grid.empty() && a.cell_size > 0)
    throw CLI::ValidationError("--grid", "give --grid or --cell-size, not both");
  if (!a.grid.empty()) {
    auto g = parse_doubles(a.grid, "--grid", 3);
    for (double v : g)
      if (!(v >= 1 && v == std::floor(v) && v <= 1e6))
        throw CLI::ValidationError("--grid", "expected three integers >= 1");
    if (g[0] * g[1] * g[2] > 1e7) throw CLI::ValidationError("--grid", "more than 10^7 cells");
    return vislib::grid_cells(*box, uint32_t(g[0]), uint32_t(g[1]), uint32_t(g[2]), eye);
  }
  if (!(a.cell_size > 0))
    throw CLI::ValidationError("--grid", "give --grid nx,ny,nz or --cell-size S with --box");
  double count = 1;
  for (int k = 0; k < 3; ++k)
    count *= std::max(1.0, std::ceil((box->max[k] - box->min[k]) / a.cell_size));
  if (count > 1e7) throw CLI::ValidationError("--cell-size", "more than 10^7 cells");
  return vislib::grid_cells_by_size(*box, a.cell_size, eye);
}

bool file_exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

void add_bake(CLI::App& app) {
  auto a = std::make_shared<BakeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bake",
      "Bake a PVS file: the triangles (or objects) visible from every view cell, from-segment runs "
      "on the perimeter of the bottom and top rectangles of each cell's eye band. Cells: a grid "
      "over --box, or --walkable cells over the floors of the scene.");
  cmd->add_option("SCENE", a->scene, "Scene file (.glb .gltf .obj .ply .off .stl)")->required();
  cmd->add_option("-o,--output", a->output, "Output PVS file (a shard file with --shard)")
      ->required();
  cmd->add_option("--box", a->box,
                  "Grid box x0,y0,z0,x1,y1,z1 (with --walkable: only place cells in it)");
  cmd->add_option("--grid", a->grid, "Grid cells nx,ny,nz over --box");
  cmd->add_flag("--walkable", a->walkable, "Place cells automatically over upward-facing floors");
  cmd->add_option("--cell-size", a->cell_size,
                  "Cell side: walkable columns (default 2) or grid cells over --box")
      ->check(positive());
  cmd->add_option("--eye-height", a->eye,
                  "Eye band h0,h1 above the floor / the cell bottom (walkable default 1.5,1.8)");
  cmd->add_option("--max-slope", a->max_slope, "Walkable: steepest floor, degrees from horizontal")
      ->check(in_range(0.0, 90.0))
      ->capture_default_str();
  cmd->add_flag("--no-headroom", a->no_headroom,
                "Walkable: keep floors covered by other geometry (under buildings)");
  cmd->add_option("--res", a->resolution, "Cube face resolution N of the from-segment runs")
      ->check(in_range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--runs", a->runs, "Cube orientations K per boundary segment")
      ->check(in_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed of the orientations (derived per cell)")
      ->capture_default_str();
  cmd->add_option("--near", a->near, "Near plane (view depth, scene units)")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--eps-len", a->eps_len, "Final pieces must be longer than this (in t) to count")
      ->check(in_range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--tile", a->tile, "Kernel tile side in pixels")
      ->check(in_range(1, 4096))
      ->capture_default_str();
  cmd->add_option("--states", a->states,
                  "Key states to sample glTF animations into (dynamic scenes)")
      ->check(in_range(1, 100000));
  cmd->add_option("--mode", a->mode,
                  "Dynamic scenes: 'diagonal' or 'decoupled' (as for pvs segment)")
      ->check(CLI::IsMember({"diagonal", "decoupled"}))
      ->capture_default_str();
  cmd->add_option("--coplanar", a->coplanar,
                  "Depth ties: 'both' (within --eps-z) or 'first' (as for pvs segment)")
      ->check(CLI::IsMember({"both", "first"}))
      ->capture_default_str();
  cmd->add_option("--eps-z", a->eps_z,
                  "Depth tie tolerance, relative to the front depth (as for pvs segment)")
      ->check(in_range(0.0, 0.1))
      ->capture_default_str();
  cmd->add_option("--granularity", a->granularity,
                  "Store triangle ids (spheres after them) or object ids")
      ->check(CLI::IsMember({"triangle", "object"}))
      ->capture_default_str();
  cmd->add_option("-j,--threads", a->threads,
                  "Worker threads (0 = all cores); never changes the output")
      ->check(non_negative());
  cmd->add_option("--shard", a->shard,
                  "Bake only cells c with c % N == i, into a shard file for pvs merge")
      ->capture_default_str();
  cmd->add_flag("--resume", a->resume, "Continue an interrupted bake from its checkpoint");
  cmd->add_option("--checkpoint", a->checkpoint, "Checkpoint file (default OUTPUT.ckpt)");
  cmd->add_flag("--dry-run", a->dry_run, "Place the cells, print their count and stop");
  cmd->add_option("--json", a->json_out,
                  "Write a bake report (timings per cell, sizes) as JSON ('-' = stdout)");
  cmd->add_option("--preset", a->preset,
                  "Quality preset: draft (--res 128, --runs 1, --cell-size 8), default (512, 1, 2) "
                  "or final (2048, 4, 1); options given explicitly win")
      ->check(CLI::IsMember({"draft", "default", "final"}))
      ->capture_default_str();
  cmd->callback([a, cmd] {
    vislib::Shard shard = parse_shard(a->shard);
    // The preset fills the options not given (issue 17 item 2); the report states the result.
    const Preset preset = preset_values(a->preset);
    if (cmd->count("--res") == 0) a->resolution = preset.resolution;
    if (cmd->count("--runs") == 0) a->runs = preset.runs;
    const bool cell_size_given = cmd->count("--cell-size") > 0;
    // Cell size: walkable cells, or a grid over --box by size when a preset is named (without
    // one, --box still needs --grid or --cell-size).
    if (!cell_size_given && a->grid.empty() && (a->walkable || cmd->count("--preset")))
      a->cell_size = preset.cell_size;
    json preset_j = {{"name", a->preset},
                     {"res", a->resolution},
                     {"runs", a->runs},
                     {"cell_size", a->grid.empty() ? json(a->cell_size) : json(nullptr)}};
    if (show_progress() && cmd->count("--preset"))
      std::fprintf(
          stderr, "pvs bake: preset %s: --res %d%s, --runs %d%s, --cell-size %s\n",
          a->preset.c_str(), a->resolution, cmd->count("--res") ? " (given)" : "", a->runs,
          cmd->count("--runs") ? " (given)" : "",
          !a->grid.empty()
              ? "none (--grid)"
              : (fmt::format("{:g}", a->cell_size) + (cell_size_given ? " (given)" : "")).c_str());
    // Every output is checked before any work (issue 17 item 1).
    check_output_file(a->output, "--output");
    check_output_file(a->checkpoint.empty() ? a->output + ".ckpt" : a->checkpoint, "--checkpoint");
    if (!a->json_out.empty()) check_output_file(a->json_out, "--json", true);
    std::unique_ptr<tbb::global_control> limit;
    if (a->threads > 0)
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    a->threads);
    std::string checkpoint = a->checkpoint.empty() ? a->output + ".ckpt" : a->checkpoint;
    // One bake per output at a time (the checkpoint has its own lock too): taken before looking
    // at the checkpoint, so a second bake is told that the first is running (exit 2).
    std::unique_ptr<vislib::FileLock> lock;
    if (!a->dry_run)
      lock = std::make_unique<vislib::FileLock>(a->output + ".lock", "the output " + a->output);
    if (!a->resume && file_exists(checkpoint)) {
      std::fprintf(stderr,
                   "pvs: error: %s: a checkpoint of an interrupted bake exists: pass --resume to "
                   "continue it, or delete it to start over\n",
                   checkpoint.c_str());
      throw Exit{2};
    }
    auto t0 = std::chrono::steady_clock::now();
    vislib::Scene scene = load_scene_for_cli(a->scene, a->states);
    if (scene.triangle_count() + scene.sphere_count() >= 0xFFFFFFFFull)
      throw vislib::InputError(a->scene, "more than 2^32-1 triangles and spheres");
    vislib::ViewCells cells =
        vislib::with_memory_stage("placing view cells", [&] { return make_cells(*a, scene); });
    double setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    uint32_t n = cells.layout.cell_count();
    if (n == 0) {
      std::fprintf(stderr, "pvs: error: no view cells (no walkable floor in the scene%s)\n",
                   a->box.empty() ? "" : " within --box");
      throw Exit{2};
    }
    if (a->dry_run) {
      std::printf(
          "%u cells (%s), %u in shard %u/%u, %zu boundary segments x %d runs per cell\n", n,
          cells.layout.kind == pvs::LayoutKind::Grid ? "grid" : "walkable",
          (n + shard.count - 1 - shard.index) / shard.count, shard.index, shard.count,
          vislib::cell_boundary_segments(vislib::to_box3(cells.layout.view_region(0))).size(),
          a->runs);
      return;
    }
    if (a->resume && !file_exists(checkpoint) && show_progress())
      std::fprintf(stderr, "pvs bake: no checkpoint %s: starting from the beginning\n",
                   checkpoint.c_str());
    if (show_progress())
      std::fprintf(stderr, "pvs bake: %u cells (%s), %zu triangles, shard %u/%u\n", n,
                   cells.layout.kind == pvs::LayoutKind::Grid ? "grid" : "walkable",
                   scene.triangle_count(), shard.index, shard.count);

    vislib::BakeSettings s;
    s.region.segment.resolution = a->resolution;
    s.region.segment.near = a->near;
    s.region.segment.eps_len = a->eps_len;
    s.region.segment.tile_size = a->tile;
    s.region.runs = a->runs;
    s.region.seed = a->seed;
    s.granularity =
        a->granularity == "object" ? vislib::Granularity::Object : vislib::Granularity::Triangle;
    s.region.segment.mode =
        a->mode == "decoupled" ? vislib::DynamicMode::Decoupled : vislib::DynamicMode::Diagonal;
    s.region.segment.coplanar =
        a->coplanar == "first" ? vislib::CoplanarRule::First : vislib::CoplanarRule::Both;
    s.region.segment.eps_z = a->eps_z;
    vislib::BakeFiles files{a->output, checkpoint, a->resume, /*lock=*/false};
    vislib::BakeReport r = vislib::bake(scene, cells, s, shard, files, progress_printer());

    if (r.checkpoint_dropped_records && show_progress())  // a warning: -q silences it
      std::fprintf(stderr,
                   "pvs bake: checkpoint %s: %zu damaged or torn record(s) dropped (%llu bytes); "
                   "their cells "
                   "were baked again, %u valid records kept\n",
                   checkpoint.c_str(), r.checkpoint_dropped_records,
                   static_cast<unsigned long long>(r.checkpoint_dropped_bytes), r.resumed);
    double kernel = 0;
    for (double x : r.cell_seconds) kernel += x;
    if (show_progress())
      std::fprintf(
          stderr,
          "pvs bake: %u cells (%u baked, %u resumed) in %.2f s (%.3f s kernel per baked cell), "
          "%llu bytes (%.1f per cell) written to %s\n",
          r.shard_cells, r.baked, r.resumed, r.seconds, r.baked ? kernel / r.baked : 0.0,
          static_cast<unsigned long long>(r.stats.file_bytes),
          r.shard_cells ? double(r.stats.block_bytes) / r.shard_cells : 0.0, a->output.c_str());
    if (!a->json_out.empty()) {
      json j = {
          {"scene", a->scene},
          {"output", a->output},
          {"preset", preset_j},
          {"cells", r.cells},
          {"shard", {shard.index, shard.count}},
          {"shard_cells", r.shard_cells},
          {"baked", r.baked},
          {"resumed", r.resumed},
          {"timings",
           {{"setup_seconds", setup_s}, {"bake_seconds", r.seconds}, {"kernel_seconds", kernel}}},
          {"cell_seconds", r.cell_seconds},
          {"bytes",
           {{"file", r.stats.file_bytes},
            {"header", r.stats.header_bytes},
            {"layout", r.stats.layout_bytes},
            {"index", r.stats.index_bytes},
            {"blocks", r.stats.block_bytes}}}};
      std::string text = j.dump(1) + "\n";
      if (a->json_out == "-")
        std::fwrite(text.data(), 1, text.size(), stdout);
      else
        vislib::write_file_atomic(a->json_out, text);
    }
  });
}

Registration bake_registration("bake", add_bake);

}  // namespace
}  // namespace pvs_cli
