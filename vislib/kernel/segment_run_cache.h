// segment_run_cache.h: from-segment runs shared between the view cells of a bake.
// Neighbouring cells share the edges of their eye-band rectangles, and run 0 of every segment
// is world-aligned (region_visibility.h), so a shared edge's run 0 is the same computation with
// bit-identical inputs: the cache computes it once and hands the result to every cell that uses
// it. The sets are those of baking each cell alone, byte for byte (test
// BakeSharedSegments.SetsEqualBakingEachCellAlone).
//
// Long segments (optional, plan_chains): where up to `max_parts` expected segments lie end to end
// on one line (cells in a row), one run covers the whole chain and its exact per-pixel lists are
// split by t at the junctions (SegmentOptions::splits), each part standing for one segment. The
// part's set is the one a run over that part alone gives, but the part's end points are points of
// the chain's parametrisation (v0 + s (v1 - v0)), so sets can differ from the per-edge runs where
// a visibility event falls within rounding of a junction; docs/performance.md measures how often.
//
// Use: plan_chains() (optional), then expect() every use before the work starts (the bake
// registers the runs of the cells it will compute), then get() from any thread. An entry is freed
// after its last expected use, so memory holds only results still awaited (in a grid baked in
// cell order, about one row of cells; with chains, up to max_parts rows of the edges across rows).
#pragma once

#include <tbb/collaborative_call_once.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "vislib/kernel/segment_visibility.h"

namespace vislib {

// A segment as (from, to).
using SegmentEnds = std::pair<Vec3, Vec3>;

// The maximal stretches of two or more of `segments` that meet end to end bit for bit along one
// axis (from and to differ in that coordinate only, from < to), each from its low end; duplicates
// count once. In a fixed order (by line, then along it), whatever the order of `segments`.
std::vector<std::vector<SegmentEnds>> segments_end_to_end(const std::vector<SegmentEnds>& segments);

// The split points of the chain stretch[i, j) (j - i >= 1): the parameters of its inner
// junctions on stretch[i].first -> stretch[j - 1].second, ascending, as plan_chains gives them
// (a run handed to provide() must carry these very bits).
std::vector<double> chain_splits(const std::vector<SegmentEnds>& stretch, size_t i, size_t j);

class SegmentRunCache {
 public:
  // What identifies a run: the bits of from, to and the side normal (runs match them exactly).
  using Key = std::array<uint64_t, 9>;
  static Key key_of(Vec3 from, Vec3 to, Vec3 side_normal = {0, 0, 0});

  // Computes the world-aligned run on (from, to), split at `splits` when not empty.
  using RunFn = std::function<SegmentResult(Vec3 from, Vec3 to, const std::vector<double>& splits)>;

  // Plans long segments over `segments`: maximal chains of segments along one axis (from and to
  // differ in that coordinate only, from < to) that meet end to end bit for bit, cut into runs of
  // at most `max_parts` (<= kMaxSplitParts) segments from the chain's low end. Pass every segment
  // the bake could ask for, not only those it will compute, so that the plan (hence the sets)
  // does not depend on the shard or on a resumed checkpoint. Call before expect().
  void plan_chains(const std::vector<SegmentEnds>& segments, int max_parts);

  // Registers one future get() of the world-aligned run on (from, to), with its directions split
  // by the plane of normal `side_normal` when that is not zero (run_key_normal of the segment:
  // its side normal, or a run split by several planes by its first; the run holds every side,
  // each user takes its own). Not thread-safe with get().
  void expect(Vec3 from, Vec3 to, Vec3 side_normal = {0, 0, 0});

  // Registers one future user of a family of runs not known in advance (a portal's adaptive
  // chords, face_sweep.h: both of its leaves choose the same chords from the same runs), by the
  // family's key (key_of of any two points and the normal that identify it). Not thread-safe
  // with get().
  void expect_family(const Key& family);
  // How many users of `family` were registered (0: none).
  uint32_t family_users(const Key& family) const;

  // The result of the world-aligned run on (from, to): `compute` runs on the first call
  // (tbb::collaborative_call_once: isolated, so that the computing thread never picks up a task
  // that waits for this very entry; concurrent callers for the same run join its parallel work
  // instead of waiting idle), later callers get the stored result. A segment of a planned chain
  // gets its part of the chain's run. `*computed` says whether this call ran compute(). A use that
  // was not announced is computed and not stored, unless `users` > 1: then it is announced by this
  // call as used `users` times in all (a run of a family, family_users), and kept for the others.
  // An exception from compute() reaches every caller. `side_normal` as for expect().
  std::shared_ptr<const SegmentResult> get(Vec3 from, Vec3 to, const RunFn& compute,
                                           bool* computed = nullptr, Vec3 side_normal = {0, 0, 0},
                                           uint32_t users = 0);

  // Hands the cache a run computed elsewhere (the pilot of --long-segments auto): `whole`, the
  // result of compute(from, to, splits), for the planned chain from `from` to `to` with these
  // splits, or for one announced segment (splits empty). Its first get() takes it as its own
  // computation (`*computed` true). Nothing is kept when no chain matches bit for bit, when it
  // has started, or when no use of it is expected. Call after expect(), before any get().
  void provide(Vec3 from, Vec3 to, const std::vector<double>& splits, SegmentResult whole);

  uint64_t runs_computed() const { return computed_.load(); }
  uint64_t runs_shared() const { return shared_.load(); }  // get() calls served from the cache
  // Wall seconds, summed over calls, that get() calls served from the cache spent in them: ~0 for
  // a run stored already; for one another caller was computing, the time until it was done
  // (working on its tiles meanwhile, or waiting idle when none was left).
  double wait_seconds() const { return 1e-9 * double(wait_ns_.load()); }
  size_t entries_held() const;  // results awaiting a later use
  size_t chains_planned() const { return planned_; }

 private:
  using Parts = std::vector<std::shared_ptr<const SegmentResult>>;
  // One kernel run: a planned chain of segments (split at the junctions), or a single segment
  // (no splits, one part) announced by expect().
  struct Chain {
    Vec3 from, to;
    std::vector<double> splits;       // the junctions' parameters on from -> to
    std::vector<uint32_t> remaining;  // per part: expected get() calls still to come
    bool started = false;             // a get() or provide() has begun computing or setting it
    bool provided = false;            // result given by provide(), not yet claimed by a get()
    // Set once (tbb::collaborative_call_once: callers that arrive while the first computes join
    // its tiles instead of waiting idle), with the parts or the error of compute(). A part is
    // released after its last expected use (the mutex guards the vector).
    std::unique_ptr<tbb::collaborative_once_flag> once =
        std::make_unique<tbb::collaborative_once_flag>();
    std::shared_ptr<Parts> parts;
    std::exception_ptr error;
  };
  struct ChainRef {
    uint32_t chain, part;
  };
  std::shared_ptr<Parts> run_chain(const Chain& c, const RunFn& compute, bool isolated = true);
  static std::shared_ptr<Parts> split_parts(SegmentResult whole, bool split);

  mutable std::mutex mutex_;
  std::deque<Chain> chains_;          // a deque: get() appends while others hold references
  std::map<Key, ChainRef> chain_of_;  // every segment announced or planned
  size_t planned_ = 0;                // chains of two or more segments
  std::map<Key, uint32_t> family_users_;
  std::atomic<uint64_t> computed_{0}, shared_{0}, wait_ns_{0};
};

}  // namespace vislib
