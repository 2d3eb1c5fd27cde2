// cell_visibility.cpp: a cell's visibility from the perimeter of the bottom and top rectangles of
// its eye band (paper §4.1 perimeter heuristic, §4.5 orientations).
#include "vislib/bake/cell_visibility.h"

#include <algorithm>
#include <cassert>
#include <iterator>

#include "vislib/bake/scene_subset.h"
#include "vislib/base/cubemap.h"
#include "vislib/base/phase_times.h"
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

namespace {

// The options of group g of a cell's segment groups: its runs seeded Rng::derive(cell_seed, g),
// so that a re-run of one group (cell_witness_rays) makes the bake's own runs.
RegionOptions group_options(const RegionOptions& options, uint64_t cell_seed, size_t g) {
  RegionOptions o = options;
  o.seed = Rng::derive(cell_seed, uint64_t(g));
  return o;
}

// The union of segments_visibility over `groups`, each with group_options.
CellVisibility groups_visibility(const Scene& scene,
                                 const std::vector<std::vector<Segment>>& groups, uint32_t cell,
                                 const RegionOptions& options,
                                 const std::function<void(double)>& progress) {
  CellVisibility out;
  for (const std::vector<Segment>& g : groups)
    out.segments.insert(out.segments.end(), g.begin(), g.end());
  const int count = int(groups.size());
  const uint64_t seed = cell_seed(options.seed, cell);
  for (int r = 0; r < count; ++r) {
    const RegionOptions o = group_options(options, seed, size_t(r));
    std::function<void(size_t, size_t)> run_done;
    if (progress)
      run_done = [&](size_t done, size_t total) {
        progress((double(r) + double(done) / double(std::max<size_t>(1, total))) / double(count));
      };
    RegionResult rr = segments_visibility(scene, groups[r], o, run_done);
    PhaseScope merging(Phase::Merge);
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

std::vector<std::vector<Segment>> rectangle_groups(const pvs::CellLayout& layout, uint32_t cell) {
  std::vector<std::vector<Segment>> groups;
  for (const Box3& rect : cell_rectangles(layout, cell)) groups.push_back(perimeter_segments(rect));
  return groups;
}

}  // namespace

std::vector<std::vector<Segment>> cell_segment_groups(const ViewCells& cells, uint32_t cell) {
  if (!cells.segments.empty()) return {cells.segments.at(cell)};
  return rectangle_groups(cells.layout, cell);
}

CellVisibility cell_visibility(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress) {
  assert(layout.kind != pvs::LayoutKind::BspTree);  // BSP leaf cells: pass their ViewCells
  return groups_visibility(scene, rectangle_groups(layout, cell), cell, options, progress);
}

namespace {

// `scene` cut to the triangles `ids` (sorted) of a cell's bound, with what its runs need: its own
// BVH, and the full scene's lines of collinear edges carried over edge by edge, so that every kept
// edge is computed from the same two points as in the full scene (edge_lines.h).
struct BoundScene {
  std::vector<uint32_t> ids;  // triangle id in `scene` of each triangle of the subset
  Scene scene;
  TriangleBvh bvh;
  EdgeLines lines;
};

void make_bound_scene(const Scene& full, const RegionOptions& options, std::vector<uint32_t> ids,
                      BoundScene& out) {
  out.ids = std::move(ids);
  out.scene = scene_subset(full, out.ids, Granularity::Triangle);
  const size_t state = options.segment.state;
  EdgeLines own;
  const EdgeLines* lines = options.segment.edge_lines;
  if (!lines) {
    own = build_edge_lines(full, state);
    lines = &own;
  }
  out.lines.lines = lines->lines;
  if (!lines->edge_line.empty()) {
    out.lines.edge_line.resize(3 * out.ids.size());
    for (size_t t = 0; t < out.ids.size(); ++t)
      for (size_t e = 0; e < 3; ++e)
        out.lines.edge_line[3 * t + e] = lines->edge_line[3 * size_t(out.ids[t]) + e];
  }
  out.lines.state = state;
  out.lines.triangle_count = out.scene.triangle_count();
  out.lines.scene = &out.scene;
  if (options.segment.bvh && bvh_applies(out.scene)) out.bvh = build_triangle_bvh(out.scene, state);
}

}  // namespace

CellVisibility cell_visibility(const Scene& scene, const ViewCells& cells, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress) {
  if (cells.bound.empty())
    return groups_visibility(scene, cell_segment_groups(cells, cell), cell, options, progress);
  assert(!scene.is_dynamic() && scene.sphere_count() == 0 && options.shared_runs == nullptr);
  BoundScene b;
  make_bound_scene(scene, options, cells.bound.triangles(cell), b);
  RegionOptions o = options;
  o.segment.bvh = b.bvh.nodes.empty() ? nullptr : &b.bvh;
  o.segment.edge_lines = &b.lines;
  CellVisibility v =
      groups_visibility(b.scene, cell_segment_groups(cells, cell), cell, o, progress);
  for (uint32_t& t : v.triangles) t = b.ids[t];  // increasing: the subset keeps the order
  return v;
}

std::vector<CellWitnessRay> cell_witness_rays(const Scene& scene, const ViewCells& cells,
                                              uint32_t cell, const RegionOptions& options,
                                              const std::vector<uint32_t>& wanted) {
  assert(options.shared_runs == nullptr);
  const std::vector<std::vector<Segment>> groups = cell_segment_groups(cells, cell);
  const uint64_t seed = cell_seed(options.seed, cell);
  const int n = options.segment.resolution;
  std::vector<CellWitnessRay> out;
  std::vector<uint8_t> found(wanted.size(), 0);
  size_t left = wanted.size(), first_segment = 0;
  for (size_t r = 0; r < groups.size() && left > 0; ++r) {
    RegionOptions o = group_options(options, seed, r);
    o.segment.want_witnesses = true;
    const RegionResult rr = segments_visibility(scene, groups[r], o);
    for (size_t i = 0; i < rr.visible.size(); ++i) {
      const auto it = std::lower_bound(wanted.begin(), wanted.end(), rr.visible[i]);
      if (it == wanted.end() || *it != rr.visible[i] || found[size_t(it - wanted.begin())])
        continue;
      found[size_t(it - wanted.begin())] = 1;
      --left;
      const RegionWitness& w = rr.witnesses[i];
      const Segment& s = groups[r][w.segment];
      const Mat3& R = rr.runs[w.segment * size_t(o.runs) + size_t(w.run)].orientation;
      const Vec3 d = pixel_direction(face_axes(w.witness.face, R), w.witness.x, w.witness.y, n);
      out.push_back({rr.visible[i], s.from + (s.to - s.from) * w.witness.t, d * (1.0 / length(d)),
                     first_segment + w.segment, w.run, w.witness.t});
    }
    first_segment += groups[r].size();
  }
  std::sort(out.begin(), out.end(),
            [](const CellWitnessRay& a, const CellWitnessRay& b) { return a.tri < b.tri; });
  return out;
}

}  // namespace vislib
