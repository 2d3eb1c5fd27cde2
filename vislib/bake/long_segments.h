// long_segments.h: the automatic choice of a bake's long-segment length (`pvs bake
// --long-segments auto`, BakeSettings::long_segments = 0).
//
// Long segments pay where a run's cost grows more slowly than its length (many small cells over
// a large scene) and cost where it grows faster (large cells: more pieces per pixel, less
// culling); docs/performance.md measures both. Which holds depends on the scene and the cells, so
// the choice is measured on the bake itself: a pilot runs a few stretches of cell edges that lie
// end to end (the stretches the bake would chain) at the bake's resolution, once per
// candidate length L in {1, 2, 4, 8} (stopping at the first L that costs no less than a shorter
// one), cut into chains of L from the low end exactly as the bake plans them, and keeps the
// longest L whose estimated cost is 5% below every shorter one's. The chosen L's runs are runs
// the bake needs, and are handed to it. A candidate's runs run side by side (tbb::parallel_for).
//
// The estimate is a weighted count of the kernel's work (SegmentStats), never a clock reading: the
// same scene and settings give the same L on any machine, thread count, shard or resumed bake, so
// the file stays byte-identical (bake.h). The weights are the kernel's measured costs per unit
// (long_segments.cpp says where they come from).
#pragma once

#include <vector>

#include "vislib/kernel/segment_run_cache.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

struct LongSegmentCandidate {
  int parts = 1;       // L: edges per run
  int runs = 0;        // kernel runs of the pilot for this L
  SegmentStats stats;  // their counts, summed
  double cost = 0;     // estimated_work of those runs
  double seconds = 0;  // measured wall time of those runs, run side by side (reported only)
};

struct LongSegmentChoice {
  int parts = 1;              // the L chosen (1: no long segments)
  int stretches_sampled = 0;  // stretches of edges end to end the pilot ran (0: none to chain)
  int resolution = 0;         // the pilot's N
  // 1, 2, 4, 8: up to the longest stretch sampled, and up to the first that costs no less than a
  // shorter one (the pilot stops there).
  std::vector<LongSegmentCandidate> candidates;
  double seconds = 0;  // wall time of the whole pilot
  // The chosen L's runs, which are runs the bake needs (world-aligned, the bake's chains):
  // handed to its SegmentRunCache (provide) so that they are not computed twice.
  struct Run {
    Vec3 from, to;
    std::vector<double> splits;
    SegmentResult result;
  };
  std::vector<Run> runs;
};

// The estimated work of kernel runs with these counts, in covered-pair equivalents: covered
// pairs + 4 (triangle, tile) pairs + 6 BVH nodes opened + 0.4 (triangle, face) pairs of the
// per-face pass that runs without a BVH (long_segments.cpp).
double estimated_work(const SegmentStats& stats);

// The longest candidate L whose cost is below 0.95 times that of every shorter candidate
// (candidates in increasing L; 1 when none is). 0.95: the weights' fit has an rms error of 4.5%;
// with 0.9 the pilot kept L = 1 on sauer_pandora where L = 4 was 1.14x faster.
int pick_long_segments(const std::vector<LongSegmentCandidate>& candidates);

// Chooses L for chaining `segments` (every run-0 segment the bake could compute) with `run0` (the
// options of the world-aligned run: resolution, near, tie rule, BVH...; its orientation, splits
// and want_* fields are ignored). A longer L is chosen only when its estimate is below 0.95 times
// that of every shorter candidate (a pilot of a few stretches is a sample, and long segments can
// change a set where an event falls within rounding of a junction): pick_long_segments.
// Deterministic.
LongSegmentChoice choose_long_segments(const Scene& scene, const std::vector<SegmentEnds>& segments,
                                       const SegmentOptions& run0);

}  // namespace vislib
