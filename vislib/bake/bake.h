// bake.h: baking a scene's view cells into a PVS file (docs/bake.md), in parallel over cells,
// with a crash-safe checkpoint to resume from and deterministic shards for cluster job arrays.
//
// Determinism: a cell's set depends only on the scene, its view region, the settings and its id
// (view_cells.h: cell_visibility), and the file is written from the sets in cell order
// (pvs::write_pvs), so the output is byte-identical for any thread count, for a bake resumed any
// number of times, and for shards merged with pvs::merge_pvs.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/bake/long_segments.h"
#include "vislib/bake/view_cells.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

struct BakeSettings {
  RegionOptions region;  // resolution, near, eps_len, tile size (segment); runs K; seed
  Granularity granularity = Granularity::Triangle;
  // Compute each world-aligned run (run 0) of an edge shared by several cells once
  // (segment_run_cache.h). Never changes the sets; false recomputes it for every cell.
  bool share_segments = true;
  // Long segments (with share_segments, static scenes without spheres): run 0 of
  // up to this many cell edges lying end to end on one line runs as one segment whose per-pixel
  // lists are split per edge (segment_run_cache.h); at most kMaxSplitParts. 1 = off. Recorded in
  // the file's metadata when on: a set can differ from the per-edge runs where an event falls
  // within rounding of a junction (none seen in the tests and benchmarks, docs/performance.md).
  // Off by default: they pay where a run's fixed cost dominates (many small cells over a large
  // scene: 3.5x on the 1M-triangle city's 2 m cells) and cost where the length does (24 m cells
  // over the 20K-triangle default scene: 2x slower); docs/bake.md. 0 = auto: a pilot of a few
  // chains measures which L (1, 2, 4 or 8) costs least (long_segments.h) and the bake runs it.
  int long_segments = 1;
  // Static scenes without spheres: build one BVH of the triangles (triangle_bvh.h) that every run
  // of the bake walks per tile, instead of each run computing footprint bounds for every
  // triangle on every face. The file is byte-identical either way.
  bool bvh = true;
};

// Whether long segments can run on `scene` with `settings`, whatever long_segments says (shared
// edges, a static scene without spheres, no witnesses).
bool long_segments_apply(const Scene& scene, const BakeSettings& settings);
// Whether `settings` run long segments on `scene`: long_segments > 1 and they apply.
bool uses_long_segments(const Scene& scene, const BakeSettings& settings);

// Shard `index` of `count` bakes the cells c with c % count == index (round robin, so each shard
// gets a share of every part of the scene and similar work). 0 <= index < count.
struct Shard {
  uint32_t index = 0, count = 1;
};
inline bool in_shard(uint32_t cell, Shard shard) {
  return cell % shard.count == shard.index;
}

// What the file will hold besides the sets: scene_fingerprint(scene), the universe (triangle or
// object count), granularity, the cells' layout, and metadata: a JSON object with the cells'
// description and every setting the sets depend on (not the thread count, not the shard).
// Precondition: the scene has fewer than 2^32 triangles.
pvs::FileInfo bake_file_info(const Scene& scene, const ViewCells& cells,
                             const BakeSettings& settings);

// Identifies a bake for its checkpoint: a digest of the file info and the shard.
uint64_t bake_key(const pvs::FileInfo& info, Shard shard);

// The visible set of one cell at the settings' granularity (sorted ids). `seconds` receives the
// kernel time if given. Thread-safe.
// `progress` as for cell_visibility (fraction of the cell's runs done).
std::vector<uint32_t> bake_cell(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                                const BakeSettings& settings, double* seconds = nullptr,
                                const std::function<void(double)>& progress = {});
// The same for cells that may carry their own segments (ViewCells::segments) and sweeps: what
// bake() stores. BSP leaf cells (bsp_cells.h) must use this one; the layout overload asserts a
// box layout. `segments_run` receives the number of segments run (each `runs` times), the chords
// an adaptive sweep inserted among them.
std::vector<uint32_t> bake_cell(const Scene& scene, const ViewCells& cells, uint32_t cell,
                                const BakeSettings& settings, double* seconds = nullptr,
                                const std::function<void(double)>& progress = {},
                                uint64_t* segments_run = nullptr);

struct BakeProgress {
  uint32_t done = 0;     // cells of the shard finished, resumed ones included
  uint32_t total = 0;    // cells of the shard
  uint32_t resumed = 0;  // of which taken from the checkpoint
  double elapsed = 0;    // seconds since this run started baking
  // Work inside the cells being baked: the sum over them of the fraction of their from-segment
  // runs done, so done + running (<= total) counts the cells' work finished (a long cell shows).
  double running = 0;
  // The same in expected work (bake_eta.h: expected_cell_work of the cells this run bakes):
  // finished cells' work plus each running cell's fraction of its own, and the total to bake;
  // eta_seconds(elapsed, work_done, work_total - work_done) weights the cells left by their work.
  double work_done = 0;
  double work_total = 0;
};
// Called once before the first cell (done = resumed), after every from-segment run inside a cell
// and after every finished cell, serialised (never two calls at once) but from any worker thread.
using BakeProgressFn = std::function<void(const BakeProgress&)>;

struct BakeFiles {
  std::string output;      // the PVS file (a partial file when sharded); written atomically
  std::string checkpoint;  // checkpoint file, "" for none; deleted once `output` is in place
  bool resume = false;     // continue from `checkpoint` if it exists
  // Hold an exclusive lock on `output`.lock (FileLock, file_util.h) for the whole bake, so that a
  // second bake of the same output is refused. false if the caller holds that lock already.
  bool lock = true;
};

// Wall and CPU seconds of one phase, summed over threads.
struct PhaseSeconds {
  double wall = 0, cpu = 0;
};

// Where each thread's time went, phase by phase (phase_times.h: a thread's time goes to the
// innermost phase it is in, so no second counts twice). In the pipeline over cells, the phases'
// wall seconds and `idle` add up to threads x BakeReport::seconds, their CPU seconds and `idle`
// to BakeTimes::process_cpu. Read from the clocks a few times per from-segment run.
struct BakePhases {
  // Before the pipeline, on the calling thread while the arena's other threads join its parallel
  // loops: wall seconds, and the process's CPU seconds (every thread) over the same time.
  PhaseSeconds bvh;    // building the BVH (BakeSettings::bvh)
  PhaseSeconds pilot;  // the pilot of --long-segments auto (long_segments.h)
  // In the pipeline:
  PhaseSeconds runs;          // from-segment runs a thread computes, with the tiles it runs in them
  PhaseSeconds shared_waits;  // in a shared or long-segment run another thread computes: joining
                              // its tiles (CPU) or waiting idle for them to end (wall only)
  PhaseSeconds merge;         // the union of a cell's runs and the ids of its set
  PhaseSeconds cell;          // the rest of a cell's computation (set-up, copies)
  PhaseSeconds progress;      // waiting for the progress lock and reporting
  PhaseSeconds checkpoint;    // appending finished cells to the checkpoint
  PhaseSeconds encode;        // encoding blocks in cell order, and the index at the end
  PhaseSeconds write;         // writing the bytes, the final fsync and rename
  PhaseSeconds helping;       // tiles of a run another thread computes, taken by a thread with
                              // no cell of its own (the scheduler lends it to that run)
  PhaseSeconds bound_trees;   // building a cell's trees over its runs' bounds (--bound)
  // The rest: wall, threads x BakeReport::seconds less every phase (threads with no cell, block
  // or tile to work on); CPU, process_cpu less every phase (the scheduler's spinning while it
  // looks for work).
  PhaseSeconds idle;
};

// Where a bake's threads spent the pipeline over cells (the BVH and the pilot come before it:
// BakeReport::bvh_seconds, long_segment_choice.seconds). Seconds summed over the calls, from
// timers inside the bake; the threads had threads * BakeReport::seconds of wall time in all.
struct BakeTimes {
  double process_cpu = 0;  // CPU seconds (user + system) of the whole process in the pipeline
  // Inside the cells' computation (bake_cell), summed over cells: wall seconds, and CPU seconds of
  // the threads that ran them over the same calls. A thread waiting inside its cell may run tiles
  // or a whole cell of another; a cell run inside another on the same thread is counted once.
  double cells = 0, cells_cpu = 0;
  double shared_wait = 0;  // of `cells`: in shared runs another cell was computing (wall)
  BakePhases phases;       // the same time, phase by phase (progress, checkpoint, writing: there)
};

struct BakeReport {
  uint32_t cells = 0;                // in the layout
  uint32_t shard_cells = 0;          // in this shard
  uint32_t resumed = 0;              // taken from the checkpoint
  uint32_t baked = 0;                // computed in this run
  std::vector<double> cell_seconds;  // kernel seconds per cell id computed in this run, else 0
  // CPU seconds per cell id computed in this run (else 0) of the thread that ran it, cells it ran
  // inside this one left out: the cell's whole cost on one thread (-j 1); with more threads, the
  // tiles other threads took are missing and tiles of other cells it took are in.
  std::vector<double> cell_cpu_seconds;
  double seconds = 0;  // wall time of this run's baking
  // Threads the bake ran on: tbb::this_task_arena::max_concurrency() of the caller's arena (a
  // tbb::task_arena of N slots runs it on N threads, whatever the core count).
  int threads = 0;
  BakeTimes times;        // where the threads' time went
  pvs::WriteStats stats;  // sizes of the written file
  // From-segment runs: computed by the kernel in this run (a long segment counts once), and
  // served from the shared-edge cache or a long segment's part instead (share_segments,
  // long_segments); computed + shared = runs of the baked cells. A long segment's kernel seconds
  // count for the cell that computed it.
  uint64_t segment_runs_computed = 0;
  uint64_t segment_runs_shared = 0;
  double bvh_seconds = 0;  // building the BVH the runs share (BakeSettings::bvh), wall time
  int long_segments = 1;   // the L the bake ran (1: none), chosen by the pilot for "auto"
  LongSegmentChoice long_segment_choice;  // the pilot of "auto" (no candidates: no pilot ran)
  // Damaged records skipped (and a torn tail) when the checkpoint was reopened, and their bytes.
  size_t checkpoint_dropped_records = 0;
  uint64_t checkpoint_dropped_bytes = 0;
};

// Bakes the cells of `shard` in parallel (a TBB pipeline over cells; the kernel is parallel inside
// too), records each finished cell in the checkpoint before counting it done, and streams the
// blocks to a temporary file in cell order as cells finish (index and header patched at the end;
// pvs::StreamWriter), renamed over `files.output` once complete; then deletes the checkpoint.
// Runs on the calling thread's TBB arena: its max_concurrency() is the thread count.
// Cells with their own segments (ViewCells::segments, BSP leaves) run without shared edges and
// long segments (their segments are not shared between cells), whatever `settings` say.
// Memory: the cells in flight (4 per thread at most) and the delta references of StreamWriter,
// plus O(cells) bytes of index and timings; not the sets of all cells (on resume, the recovered
// cells are held until written). Throws InputError for a checkpoint of another bake or a bake
// already running on the output or checkpoint (locks), std::runtime_error on I/O failure (the
// checkpoint is kept).
BakeReport bake(const Scene& scene, const ViewCells& cells, const BakeSettings& settings,
                Shard shard, const BakeFiles& files, const BakeProgressFn& progress = {});

}  // namespace vislib
