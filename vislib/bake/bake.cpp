// bake.cpp: parallel bake over view cells with checkpoint and shards (bake.h, docs/bake.md).
#include "vislib/bake/bake.h"

#include <tbb/parallel_invoke.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cassert>
#include <chrono>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "vislib/bake/bake_eta.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/checkpoint.h"
#include "vislib/bake/id_universe.h"
#include "vislib/bake/long_segments.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/base/phase_times.h"
#include "vislib/kernel/segment_run_cache.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/scene_fingerprint.h"

namespace vislib {

pvs::FileInfo bake_file_info(const Scene& scene, const ViewCells& cells,
                             const BakeSettings& settings) {
  assert(scene.triangle_count() < 0xFFFFFFFFull && scene.objects.size() < 0xFFFFFFFFull);
  pvs::FileInfo info;
  info.scene_fingerprint = scene_fingerprint(scene);
  info.granularity = settings.granularity == Granularity::Object ? pvs::Granularity::Object
                                                                 : pvs::Granularity::Triangle;
  info.universe = id_universe(scene, settings.granularity);  // the one id rule (bake/id_universe.h)
  info.layout = cells.layout;
  const SegmentOptions& s = settings.region.segment;
  nlohmann::json m = {
      {"generator", "vislib pvs bake"},
      {"cells", nlohmann::json::parse(cells.description)},
      {"granularity", settings.granularity == Granularity::Object ? "object" : "triangle"},
      {"resolution", s.resolution},
      {"near", s.near},
      {"eps_len", s.eps_len},
      {"runs", settings.region.runs},
      {"seed", settings.region.seed},
      {"state", s.state},
      {"states", scene.state_count()},
      {"mode", s.mode == DynamicMode::Decoupled ? "decoupled" : "diagonal"},
      {"coplanar", s.coplanar == CoplanarRule::First ? "first" : "both"},
      {"eps_z", s.eps_z},
      {"fans", s.fans},
      {"boundary", cells.segments.empty()
                       ? "perimeter of the eye band's bottom and top rectangles"
                       : "segments sweeping the boundary faces of each cell's view region"}};
  if (uses_long_segments(scene, settings)) m["long_segments"] = settings.long_segments;
  info.metadata = m.dump();
  return info;
}

bool long_segments_apply(const Scene& scene, const BakeSettings& settings) {
  return settings.share_segments && !scene.is_dynamic() && scene.sphere_count() == 0 &&
         !settings.region.segment.want_witnesses;
}

bool uses_long_segments(const Scene& scene, const BakeSettings& settings) {
  return settings.long_segments > 1 && long_segments_apply(scene, settings);
}

uint64_t bake_key(const pvs::FileInfo& info, Shard shard) {
  // The bytes of a file with every cell absent hold exactly the info (header, layout, metadata).
  pvs::FileInfo empty = info;
  empty.partial = true;
  std::string bytes = pvs::write_pvs(empty, std::vector<pvs::CellSet>(info.layout.cell_count()));
  uint64_t h = pvs::fnv1a64(bytes.data(), bytes.size());
  uint32_t s[2] = {shard.index, shard.count};
  return pvs::fnv1a64(s, sizeof s, h);
}

std::vector<uint32_t> bake_cell(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                                const BakeSettings& settings, double* seconds,
                                const std::function<void(double)>& progress) {
  CellVisibility v = cell_visibility(scene, layout, cell, settings.region, progress);
  if (seconds) *seconds = v.seconds;
  PhaseScope merging(Phase::Merge);
  return ids_of(scene, settings.granularity, v.triangles, v.spheres);
}

std::vector<uint32_t> bake_cell(const Scene& scene, const ViewCells& cells, uint32_t cell,
                                const BakeSettings& settings, double* seconds,
                                const std::function<void(double)>& progress,
                                uint64_t* segments_run) {
  CellVisibility v = cell_visibility(scene, cells, cell, settings.region, progress);
  if (seconds) *seconds = v.seconds;
  if (segments_run) *segments_run = v.segments.size();
  PhaseScope merging(Phase::Merge);
  return ids_of(scene, settings.granularity, v.triangles, v.spheres);
}

namespace {

// Run 0's segment of every segment of every cell, in cell order.
std::vector<SegmentEnds> all_edges(const ViewCells& cells) {
  std::vector<SegmentEnds> all;
  for (uint32_t c = 0; c < cells.layout.cell_count(); ++c)
    for (const std::vector<Segment>& g : cell_segment_groups(cells, c))
      for (const Segment& s : g)
        if (s.side_normal == Vec3{0, 0, 0}) all.emplace_back(s.from, s.to);  // a portal's: no chain
  return all;
}

// Every cell's segments, its groups in order (expected_cell_work); for an adaptive sweep, the
// chords its first two rounds run whatever the scene (the even chords at half the coarse
// spacing), the least it costs.
std::vector<std::vector<Segment>> all_cell_segments(const ViewCells& cells) {
  std::vector<std::vector<Segment>> out(cells.layout.cell_count());
  for (uint32_t c = 0; c < cells.layout.cell_count(); ++c) {
    for (const std::vector<Segment>& g : cell_segment_groups(cells, c))
      out[c].insert(out[c].end(), g.begin(), g.end());
    if (!cells.sweeps.empty())
      for (const FaceSweep& f : cells.sweeps[c]) {
        const std::vector<Segment> first =
            even_chords(f, 0.5 * cells.sweep_spacing.coarse, kSweepMinChord);
        out[c].insert(out[c].end(), first.begin(), first.end());
      }
  }
  return out;
}

// Wall clock of the calling thread.
double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Adds `seconds` to `*sum` (std::atomic<double> has no fetch_add before C++20).
void add_to(std::atomic<double>* sum, double seconds) {
  double old = sum->load(std::memory_order_relaxed);
  while (!sum->compare_exchange_weak(old, old + seconds, std::memory_order_relaxed)) {
  }
}

// Cells baked inside another cell on the same thread (a thread waiting in its cell ran another's
// pipeline task): the outermost's wall time counts once, and a cell's own CPU seconds leave out
// those of the cells run inside it (their sum, per thread, while a cell runs).
thread_local int g_cell_depth = 0;
thread_local double g_nested_cpu = 0;

// One BVH for every static run of this bake (the runs walk it per tile): `requested`'s own, else
// one built into `tree` when the bake asks for it and the scene allows it, else none.
const TriangleBvh* bake_bvh(const Scene& scene, const BakeSettings& requested, TriangleBvh& tree,
                            BakeReport& report) {
  const TriangleBvh* bvh = requested.region.segment.bvh;
  if (requested.bvh && !bvh && bvh_applies(scene)) {
    const auto t0 = std::chrono::steady_clock::now();
    tree = build_triangle_bvh(
        scene, requested.region.segment.fans ? BvhPrimitives::Groups : BvhPrimitives::Triangles,
        requested.region.segment.state);
    bvh = &tree;
    report.bvh_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return bvh;
}

// `requested` with --long-segments auto (0) resolved.
BakeSettings resolved_settings(const Scene& scene, const ViewCells& cells,
                               const BakeSettings& requested, const TriangleBvh* bvh,
                               const EdgeLines* lines, BakeReport& report) {
  // --long-segments auto: L from a pilot over every cell of the layout (not only this shard's),
  // so that every shard and every resumed run chooses the same L (long_segments.h).
  BakeSettings settings = requested;
  if (!cells.segments.empty()) {  // no chains of a cell's own segments
    // A cell's own segments are shared with another's only when they are a portal's.
    settings.share_segments = settings.share_segments && cells.shared_runs;
    settings.long_segments = 1;
  }
  if (settings.long_segments == 0) {
    settings.long_segments = 1;
    if (long_segments_apply(scene, settings)) {
      SegmentOptions run0 = settings.region.segment;
      run0.bvh = bvh;
      run0.edge_lines = lines;
      report.long_segment_choice = choose_long_segments(scene, all_edges(cells), run0);
      settings.long_segments = report.long_segment_choice.parts;
    }
  }
  report.long_segments = uses_long_segments(scene, settings) ? settings.long_segments : 1;
  return settings;
}

// Opens the checkpoint of `files` (none when not asked for); `recovered` receives its cells.
std::unique_ptr<Checkpoint> open_checkpoint(
    const BakeFiles& files, const pvs::FileInfo& info, Shard shard,
    std::vector<std::optional<std::vector<uint32_t>>>& recovered, BakeReport& report) {
  const uint32_t n = info.layout.cell_count();
  std::unique_ptr<Checkpoint> checkpoint;
  if (!files.checkpoint.empty()) {
    checkpoint = std::make_unique<Checkpoint>(files.checkpoint, bake_key(info, shard), n,
                                              files.resume, &recovered, info.universe);
    report.checkpoint_dropped_records = checkpoint->dropped_records();
    report.checkpoint_dropped_bytes = checkpoint->discarded_bytes();
    for (uint32_t c = 0; c < n; ++c)
      if (recovered[c] && !in_shard(c, shard))
        throw InputError(files.checkpoint,
                         "holds cell " + std::to_string(c) + ", which is not in this shard");
  }
  return checkpoint;
}

// Announces to `shared_runs` the runs of the cells this bake computes (settings.share_segments).
void plan_shared_runs(const Scene& scene, const BakeSettings& settings, const ViewCells& cells,
                      const pvs::FileInfo& info, Shard shard,
                      const std::vector<std::optional<std::vector<uint32_t>>>& recovered,
                      SegmentRunCache& shared_runs, BakeReport& report) {
  const uint32_t n = info.layout.cell_count();
  if (uses_long_segments(scene, settings)) {
    // The plan covers every cell of the layout, so that it does not depend on the shard or on
    // the cells recovered from a checkpoint.
    shared_runs.plan_chains(all_edges(cells), settings.long_segments);
  }
  for (uint32_t c = 0; c < n; ++c) {
    if (!in_shard(c, shard) || recovered[c]) continue;
    for (const std::vector<Segment>& g : cell_segment_groups(cells, c))
      for (const Segment& s : g) shared_runs.expect(s.from, s.to, run_key_normal(s));
    // A portal's adaptive chords, the same for both of its leaves: one user per leaf computed.
    if (!cells.sweeps.empty())
      for (const FaceSweep& f : cells.sweeps[c])
        if (!(f.side_normal == Vec3{0, 0, 0})) shared_runs.expect_family(sweep_family_key(f));
  }
  // The pilot's runs of the chosen L are runs of this bake: not computed again.
  for (LongSegmentChoice::Run& run : report.long_segment_choice.runs)
    shared_runs.provide(run.from, run.to, run.splits, std::move(run.result));
  report.long_segment_choice.runs.clear();
}

// The pipeline's phases into report.times.phases, and the rest of the threads' time (idle).
// Precondition: report.seconds, report.threads and report.times.process_cpu are set.
void record_phases(const PhaseTimes& t, BakeReport& report) {
  BakePhases& p = report.times.phases;
  auto get = [&t](Phase phase) { return PhaseSeconds{t.wall(phase), t.cpu(phase)}; };
  p.cell = get(Phase::Cell);
  p.runs = get(Phase::Run);
  p.shared_waits = get(Phase::SharedWait);
  p.merge = get(Phase::Merge);
  p.progress = get(Phase::Progress);
  p.checkpoint = get(Phase::Checkpoint);
  p.encode = get(Phase::Encode);
  p.write = get(Phase::Write);
  p.helping = get(Phase::Helping);
  p.bound_trees = get(Phase::BoundTrees);
  p.idle.wall = std::max(0.0, double(report.threads) * report.seconds - t.wall_total());
  p.idle.cpu = std::max(0.0, report.times.process_cpu - t.cpu_total());
}

// Streaming: cells are baked in parallel and written in cell order as soon as every earlier
// cell is written (a TBB pipeline whose last stage is serial and in order), so the memory held
// is the cells in flight (a bounded number of tokens) plus what pvs::StreamWriter keeps for
// delta references, whatever the cell count. The bytes are those of pvs::write_pvs.
// Writes files.output, baking the cells of `shard` not in `recovered` with `run_settings`
// (`runs` orientations each); adds the runs of the baked cells to `runs_done`.
void stream_cells(const Scene& scene, const ViewCells& cells, const pvs::FileInfo& info,
                  Shard shard, const BakeSettings& run_settings, int runs,
                  std::vector<std::optional<std::vector<uint32_t>>>& recovered,
                  Checkpoint* checkpoint, const BakeFiles& files, const BakeProgressFn& progress,
                  std::atomic<uint64_t>& runs_done, BakeReport& report) {
  const uint32_t n = info.layout.cell_count();
  PhaseTimes phases;
  AtomicFile out(files.output);
  pvs::StreamWriter writer(info, [&out, &phases](uint64_t offset, std::string_view bytes) {
    PhaseScope writing(Phase::Write, &phases);
    out.write_at(offset, bytes);
  });
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::mutex progress_mutex;
  uint32_t done = report.resumed;
  std::vector<double> partial(n, 0.0);  // fraction of each running cell's runs done
  double running = 0;                   // their sum
  // Expected work of the cells to bake (bake_eta.h), finished and in the running cells.
  std::vector<uint8_t> to_bake(n, 0);
  for (uint32_t c = 0; c < n; ++c) to_bake[c] = in_shard(c, shard) && !recovered[c];
  const std::vector<double> work =
      expected_cell_work(all_cell_segments(cells), to_bake, runs, run_settings.share_segments);
  double work_total = 0, work_finished = 0, work_running = 0;
  for (double w : work) work_total += w;
  auto state = [&] {
    BakeProgress p;
    p.done = done;
    p.total = report.shard_cells;
    p.resumed = report.resumed;
    p.elapsed = elapsed();
    p.running = std::max(0.0, running);
    p.work_done = work_finished + std::max(0.0, work_running);
    p.work_total = work_total;
    return p;
  };
  if (progress) progress(state());
  std::atomic<double> t_cells{0}, t_cells_cpu{0};
  const double cpu_start = process_cpu_seconds();
  const size_t tokens = 4 * size_t(std::max(1, report.threads));
  uint32_t next = 0;
  // Threads with no cell of their own that the scheduler lends to a run are timed too (helping).
  PhaseFallback lent_threads(&phases);
  try {
    tbb::parallel_pipeline(
        tokens,
        tbb::make_filter<void, uint32_t>(tbb::filter_mode::serial_in_order,
                                         [&](tbb::flow_control& fc) -> uint32_t {
                                           if (next >= n) {
                                             fc.stop();
                                             return 0;
                                           }
                                           return next++;
                                         }) &
            tbb::make_filter<uint32_t, std::shared_ptr<pvs::CellSet>>(
                tbb::filter_mode::parallel,
                [&](uint32_t c) {
                  PhaseScope in_cell_phase(Phase::Cell, &phases);
                  auto set = std::make_shared<pvs::CellSet>();
                  if (!in_shard(c, shard)) return set;  // absent from this shard's file
                  if (recovered[c]) {
                    *set = std::move(recovered[c]);
                    recovered[c].reset();
                    return set;
                  }
                  double seconds = 0;
                  uint64_t segments_run = 0;
                  std::function<void(double)> in_cell;  // progress inside the cell
                  if (progress)
                    in_cell = [&, c](double fraction) {
                      PhaseScope reporting(Phase::Progress, &phases);
                      std::lock_guard<std::mutex> guard(progress_mutex);
                      running += fraction - partial[c];
                      work_running += (fraction - partial[c]) * work[c];
                      partial[c] = fraction;
                      progress(state());
                    };
                  const bool outer = g_cell_depth++ == 0;
                  const double nested_before = g_nested_cpu;
                  g_nested_cpu = 0;
                  const double w0 = wall_now(), c0 = thread_cpu_seconds();
                  std::vector<uint32_t> ids;
                  try {
                    ids = with_memory_stage(
                        "baking cell " + std::to_string(c) + " of " + std::to_string(n), [&] {
                          return bake_cell(scene, cells, c, run_settings, &seconds, in_cell,
                                           &segments_run);
                        });
                  } catch (...) {
                    --g_cell_depth;
                    g_nested_cpu = nested_before;
                    throw;
                  }
                  --g_cell_depth;
                  const double cpu = thread_cpu_seconds() - c0;
                  report.cell_cpu_seconds[c] = cpu - g_nested_cpu;
                  g_nested_cpu = nested_before + cpu;
                  if (outer) {
                    add_to(&t_cells, wall_now() - w0);
                    add_to(&t_cells_cpu, cpu);
                  }
                  runs_done += segments_run * uint64_t(runs);
                  {
                    PhaseScope appending(Phase::Checkpoint, &phases);
                    if (checkpoint) checkpoint->append(c, ids);
                  }
                  *set = std::move(ids);
                  report.cell_seconds[c] = seconds;
                  PhaseScope reporting(Phase::Progress, &phases);
                  std::lock_guard<std::mutex> guard(progress_mutex);
                  ++done;
                  ++report.baked;
                  running -= partial[c];
                  work_running -= partial[c] * work[c];
                  work_finished += work[c];
                  partial[c] = 0;
                  if (progress) progress(state());
                  return set;
                }) &
            tbb::make_filter<std::shared_ptr<pvs::CellSet>, void>(
                tbb::filter_mode::serial_in_order, [&](const std::shared_ptr<pvs::CellSet>& set) {
                  PhaseScope encoding(Phase::Encode, &phases);
                  with_memory_stage("writing " + files.output, [&] { writer.add(*set); });
                }));
  } catch (...) {
    // A bake that recorded nothing leaves no checkpoint behind.
    if (checkpoint && done == 0) checkpoint->remove();
    throw;
  }
  report.times.cells = t_cells;
  report.times.cells_cpu = t_cells_cpu;
  {
    PhaseScope encoding(Phase::Encode, &phases);
    report.stats = writer.finish();
  }
  {
    PhaseScope writing(Phase::Write, &phases);
    out.commit();
  }
  report.seconds = elapsed();
  report.times.process_cpu = process_cpu_seconds() - cpu_start;
  record_phases(phases, report);
}

}  // namespace

BakeReport bake(const Scene& scene, const ViewCells& cells, const BakeSettings& requested,
                Shard shard, const BakeFiles& files, const BakeProgressFn& progress) {
  assert(shard.count >= 1 && shard.index < shard.count);
  std::unique_ptr<FileLock> lock;
  if (files.lock) {
    lock = std::make_unique<FileLock>(files.output + ".lock", "the output " + files.output);
    remove_dead_writers_temps(files.output);  // a killed bake's, now that none can be alive
  }
  BakeReport report;
  report.threads = tbb::this_task_arena::max_concurrency();
  TriangleBvh tree;
  double w0 = wall_now(), c0 = process_cpu_seconds();
  // The tree, and the runs of collinear edges once for every static run (the kernel would build
  // them per run): independent, so built side by side.
  const TriangleBvh* bvh = nullptr;
  EdgeLines own_lines;
  const EdgeLines* lines = requested.region.segment.edge_lines;
  const bool own = !lines && bvh_applies(scene);
  if (own) lines = &own_lines;
  tbb::parallel_invoke([&] { bvh = bake_bvh(scene, requested, tree, report); },
                       [&] {
                         if (own)
                           own_lines = build_edge_lines(scene, requested.region.segment.state);
                       });
  report.times.phases.bvh = {wall_now() - w0, process_cpu_seconds() - c0};
  w0 = wall_now();
  c0 = process_cpu_seconds();
  const BakeSettings settings = resolved_settings(scene, cells, requested, bvh, lines, report);
  report.times.phases.pilot = {wall_now() - w0, process_cpu_seconds() - c0};
  pvs::FileInfo info = bake_file_info(scene, cells, settings);
  info.partial = shard.count > 1;
  const uint32_t n = info.layout.cell_count();
  report.cells = n;
  report.cell_seconds.assign(n, 0.0);
  report.cell_cpu_seconds.assign(n, 0.0);

  // Cells recovered from the checkpoint (resume); each is released once written.
  std::vector<std::optional<std::vector<uint32_t>>> recovered;
  std::unique_ptr<Checkpoint> checkpoint = open_checkpoint(files, info, shard, recovered, report);
  if (recovered.empty()) recovered.resize(n);
  for (uint32_t c = 0; c < n; ++c) {
    if (!in_shard(c, shard)) continue;
    ++report.shard_cells;
    if (recovered[c]) ++report.resumed;
  }

  // Shared edges: announce run 0 of every perimeter segment of the cells this run computes, so
  // that an edge common to two cells is computed once and freed after its last use.
  SegmentRunCache shared_runs;
  BakeSettings run_settings = settings;
  if (settings.share_segments) {
    run_settings.region.shared_runs = &shared_runs;
    plan_shared_runs(scene, settings, cells, info, shard, recovered, shared_runs, report);
  }
  run_settings.region.segment.bvh = bvh;
  run_settings.region.segment.edge_lines = lines;
  std::atomic<uint64_t> runs_done{0};

  stream_cells(scene, cells, info, shard, run_settings, settings.region.runs, recovered,
               checkpoint.get(), files, progress, runs_done, report);
  report.times.shared_wait = shared_runs.wait_seconds();
  report.segment_runs_shared = shared_runs.runs_shared();
  report.segment_runs_computed = runs_done.load() - report.segment_runs_shared;
  if (checkpoint) checkpoint->remove();
  return report;
}

}  // namespace vislib
