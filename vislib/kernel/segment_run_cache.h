// segment_run_cache.h: from-segment runs shared between the view cells of a bake (issue 13 item
// 5). Neighbouring cells share the edges of their eye-band rectangles, and run 0 of every segment
// is world-aligned (region_visibility.h), so a shared edge's run 0 is the same computation with
// bit-identical inputs: the cache computes it once and hands the result to every cell that uses
// it. The sets are those of baking each cell alone, byte for byte (test
// BakeSharedSegments.SetsEqualBakingEachCellAlone).
//
// Use: expect() every use before the work starts (the bake registers the runs of the cells it will
// compute), then get() from any thread. An entry is freed after its last expected use, so memory
// holds only results still awaited (in a grid baked in cell order, about one row of cells).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>

#include "vislib/kernel/segment_visibility.h"

namespace vislib {

class SegmentRunCache {
 public:
  // Registers one future get() of the world-aligned run on (from, to). Not thread-safe with get().
  void expect(Vec3 from, Vec3 to);

  // The result of the world-aligned run on (from, to): `compute()` runs on the first call (inside
  // a TBB isolated region, so that the computing thread never picks up a task that waits for this
  // very entry), concurrent callers for the same segment wait for it, later callers get the stored
  // result. `*computed` says whether this call ran compute(). A segment that was not expect()ed
  // twice or more is computed and not stored. An exception from compute() reaches every caller.
  std::shared_ptr<const SegmentResult> get(Vec3 from, Vec3 to,
                                           const std::function<SegmentResult()>& compute,
                                           bool* computed = nullptr);

  uint64_t runs_computed() const { return computed_.load(); }
  uint64_t runs_shared() const { return shared_.load(); }  // get() calls served from the cache
  size_t entries_held() const;                             // results awaiting a later use

 private:
  using Key = std::array<uint64_t, 6>;  // the bits of from and to
  static Key key_of(Vec3 from, Vec3 to);
  struct Entry {
    uint32_t remaining = 0;  // expected get() calls still to come
    bool started = false;
    std::shared_future<std::shared_ptr<const SegmentResult>> result;
  };
  mutable std::mutex mutex_;
  std::map<Key, Entry> entries_;
  std::atomic<uint64_t> computed_{0}, shared_{0};
};

}  // namespace vislib
