// cell_visibility.cpp: a cell's visibility from the perimeter of the bottom and top rectangles of
// its eye band (paper §4.1 perimeter heuristic, §4.5 orientations).
#include "vislib/bake/cell_visibility.h"

#include <algorithm>
#include <iterator>

#include "vislib/bake/view_cells.h"
#include "vislib/base/random.h"

namespace vislib {

namespace {

// The bottom and top rectangles of a view region (the bottom alone when it is flat in y).
std::vector<Box3> bottom_and_top(const Box3& region) {
  Box3 bottom = region, top = region;
  bottom.max.y = region.min.y;
  top.min.y = region.max.y;
  if (region.max.y > region.min.y) return {bottom, top};
  return {bottom};
}

}  // namespace

std::vector<Segment> cell_boundary_segments(const Box3& view_region) {
  std::vector<Segment> out;
  for (const Box3& rect : bottom_and_top(view_region)) {
    auto s = perimeter_segments(rect);
    out.insert(out.end(), s.begin(), s.end());
  }
  return out;
}

uint64_t cell_seed(uint64_t seed, uint32_t cell) {
  return Rng::derive(seed, cell);
}

std::vector<Box3> cell_rectangles(const pvs::CellLayout& layout, uint32_t cell) {
  return bottom_and_top(to_box3(layout.view_region(cell)));
}

CellVisibility cell_visibility(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress) {
  Box3 region = to_box3(layout.view_region(cell));
  CellVisibility out;
  out.segments = cell_boundary_segments(region);
  const std::vector<Box3> rect = cell_rectangles(layout, cell);
  const int rects = int(rect.size());
  const uint64_t seed = cell_seed(options.seed, cell);
  for (int r = 0; r < rects; ++r) {
    RegionOptions o = options;
    o.seed = Rng::derive(seed, uint64_t(r));
    std::function<void(size_t, size_t)> run_done;
    if (progress)
      run_done = [&](size_t done, size_t total) {
        progress((double(r) + double(done) / double(std::max<size_t>(1, total))) / double(rects));
      };
    RegionResult rr = region_visibility(scene, rect[r], o, run_done);
    std::vector<uint32_t> merged;
    merged.reserve(out.triangles.size() + rr.visible.size());
    std::set_union(out.triangles.begin(), out.triangles.end(), rr.visible.begin(), rr.visible.end(),
                   std::back_inserter(merged));
    out.triangles = std::move(merged);
    merged.clear();
    std::set_union(out.spheres.begin(), out.spheres.end(), rr.visible_spheres.begin(),
                   rr.visible_spheres.end(), std::back_inserter(merged));
    out.spheres = std::move(merged);
    out.seconds += rr.seconds;
  }
  return out;
}

}  // namespace vislib
