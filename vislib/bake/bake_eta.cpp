// bake_eta.cpp: the expected work of the cells of a bake and the ETA it gives (bake_eta.h).
#include "vislib/bake/bake_eta.h"

#include <cassert>
#include <cmath>
#include <set>

#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/view_cells.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/kernel/segment_run_cache.h"

namespace vislib {

std::vector<double> expected_cell_work(const pvs::CellLayout& layout,
                                       const std::vector<uint8_t>& bake, int runs,
                                       bool share_segments) {
  const uint32_t n = layout.cell_count();
  assert(bake.size() == n);
  std::vector<std::vector<Segment>> segments(n);
  for (uint32_t c = 0; c < n; ++c) {
    if (!bake[c]) continue;
    for (const Box3& rect : cell_rectangles(layout, c))
      for (const Segment& s : perimeter_segments(rect)) segments[c].push_back(s);
  }
  return expected_cell_work(segments, bake, runs, share_segments);
}

std::vector<double> expected_cell_work(const std::vector<std::vector<Segment>>& segments,
                                       const std::vector<uint8_t>& bake, int runs,
                                       bool share_segments) {
  const size_t n = segments.size();
  assert(bake.size() == n && runs >= 1);
  double total = 0;
  size_t count = 0;
  for (size_t c = 0; c < n; ++c) {
    if (!bake[c]) continue;
    for (const Segment& s : segments[c]) {
      total += length(s.to - s.from);
      ++count;
    }
  }
  std::vector<double> work(n, 0.0);
  if (count == 0) return work;
  const double mean = total / double(count);
  const double fixed = kRunFixedEdges * mean;
  const double unit = mean + fixed;
  std::set<SegmentRunCache::Key> computed;  // run 0 of these segments is counted already
  for (size_t c = 0; c < n; ++c) {
    if (!bake[c]) continue;
    for (const Segment& s : segments[c]) {
      const double run = (length(s.to - s.from) + fixed) / unit;
      const bool first =
          !share_segments ||
          computed.insert(SegmentRunCache::key_of(s.from, s.to, run_key_normal(s))).second;
      work[c] += run * double(runs - 1 + (first ? 1 : 0));
    }
  }
  return work;
}

double eta_seconds(double elapsed, double done, double left) {
  if (left <= 0) return 0.0;
  if (!(done > 0)) return NAN;
  return elapsed * left / done;
}

}  // namespace vislib
