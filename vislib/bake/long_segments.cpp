// long_segments.cpp: see long_segments.h.
#include "vislib/bake/long_segments.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vislib {

namespace {

constexpr int kCandidates[] = {1, 2, 4, 8};
constexpr size_t kStretchesSampled = 3;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

double estimated_work(const SegmentStats& s) {
  // Weights relative to one covered pair, fitted to the pilot's own measured times with a free
  // scale per scene (so only the ratios between the counts matter): the 20K-triangle default city
  // with 24 m cells, the 300K- and 1M-triangle cities with 2 m cells, sauer_pandora with 16-unit
  // cells; 19 pilot runs, one core, rms error 4.5% (docs/performance.md, "Choosing L"). A
  // (triangle, tile) pair costs the setup and the row spans of a triangle; a BVH node opened, the
  // footprint rectangles of its children. Per-pixel and per-piece terms did not improve the fit.
  // Without a BVH (--bvh off) every run bounds every triangle on every face: 0.4 per (triangle,
  // face), fitted to 15 pilot runs on four bakes with --bvh off at the weights above
  // (rms 3.7%; 8.0% with this term left out, which kept L = 4 where L = 8 was faster).
  return double(s.covered_pairs) + 4.0 * double(s.triangle_tiles) +
         6.0 * double(s.bvh_nodes_opened) + 0.4 * double(s.primitives_bounded);
}

int pick_long_segments(const std::vector<LongSegmentCandidate>& candidates) {
  int parts = 1;
  double least = INFINITY;
  for (const LongSegmentCandidate& c : candidates) {
    if (c.cost < 0.95 * least) parts = c.parts;
    least = std::min(least, c.cost);
  }
  return parts;
}

LongSegmentChoice choose_long_segments(const Scene& scene, const std::vector<SegmentEnds>& segments,
                                       const SegmentOptions& run0) {
  const auto start = std::chrono::steady_clock::now();
  LongSegmentChoice choice;
  std::vector<std::vector<SegmentEnds>> stretches = segments_end_to_end(segments);
  if (stretches.empty()) return choice;
  // Evenly spread samples in the stretches' fixed order, each cut to its first 8 edges (the
  // bake's chains start at a stretch's low end, so every candidate's chains here are the bake's).
  std::vector<std::vector<SegmentEnds>> sample;
  const size_t k = std::min(kStretchesSampled, stretches.size());
  for (size_t i = 0; i < k; ++i) {
    std::vector<SegmentEnds>& s = stretches[(2 * i + 1) * stretches.size() / (2 * k)];
    s.resize(std::min(s.size(), kMaxSplitParts));
    sample.push_back(s);
  }
  SegmentOptions o = run0;
  o.orientation = Mat3{};
  o.want_pieces = false;
  o.want_witnesses = false;
  // At the bake's own resolution: the counts do not scale alike with N (pairs grow as N^2, BVH
  // nodes opened barely do), so a pilot at N/2 overrates the per-run cost that long segments
  // save (measured: it chose L = 2 where L = 4 and 8 are 15-35% slower; docs/performance.md).
  choice.resolution = o.resolution;
  choice.stretches_sampled = int(sample.size());
  size_t longest = 0;
  for (const std::vector<SegmentEnds>& stretch : sample)
    longest = std::max(longest, stretch.size());
  std::vector<std::vector<LongSegmentChoice::Run>> runs_of;  // per candidate
  double least = INFINITY;
  for (int parts : kCandidates) {
    // Past the longest sampled stretch a longer L runs the same chains: not run again.
    if (parts > int(kMaxSplitParts) || (parts > 1 && size_t(parts / 2) >= longest)) break;
    LongSegmentCandidate c;
    c.parts = parts;
    runs_of.emplace_back();
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<LongSegmentChoice::Run>& runs = runs_of.back();
    for (const std::vector<SegmentEnds>& stretch : sample) {
      for (size_t i = 0, j; i < stretch.size(); i = j) {
        j = std::min(stretch.size(), i + size_t(parts));
        runs.push_back({stretch[i].first, stretch[j - 1].second, chain_splits(stretch, i, j), {}});
      }
    }
    // The candidate's runs side by side (each is parallel inside too): one run's tiles cannot
    // keep many threads busy, and the runs are independent. The counts are summed in run order.
    tbb::parallel_for(size_t(0), runs.size(), [&](size_t r) {
      SegmentOptions ro = o;
      ro.splits = runs[r].splits;
      runs[r].result = segment_visibility(scene, runs[r].from, runs[r].to, ro);
    });
    for (const LongSegmentChoice::Run& run : runs) c.stats.add(run.result.stats);
    c.runs = int(runs.size());
    c.seconds = seconds_since(t0);
    c.cost = estimated_work(c.stats);
    choice.candidates.push_back(c);
    // The work falls with L while the per-run costs dominate and rises once the length's do
    // (measured on every scene of the fit): the first L that costs no less than a shorter one
    // ends the pilot, and longer ones are not run.
    if (choice.candidates.size() >= 2 && !(c.cost < least)) break;
    least = std::min(least, c.cost);
  }
  choice.parts = pick_long_segments(choice.candidates);
  for (size_t i = 0; i < choice.candidates.size(); ++i)
    if (choice.candidates[i].parts == choice.parts) choice.runs = std::move(runs_of[i]);
  choice.seconds = seconds_since(start);
  return choice;
}

}  // namespace vislib
