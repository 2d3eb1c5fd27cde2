// cell_visibility.cpp: a cell's visibility from the perimeter of the bottom and top rectangles of
// its eye band (paper §4.1 perimeter heuristic, §4.5 orientations).
#include "vislib/bake/cell_visibility.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>

#include "vislib/bake/bsp_bound.h"
#include "vislib/bake/face_sweep.h"
#include "vislib/base/cubemap.h"
#include "vislib/base/phase_times.h"
#include "vislib/base/random.h"
#include "vislib/kernel/segment_run_cache.h"

namespace vislib {

namespace {

// The rectangles of a view region at `levels` heights evenly spaced from its bottom to its top
// (the bottom alone when it is flat in y).
std::vector<Box3> band_rectangles(const Box3& region, int levels) {
  assert(levels >= 2);
  if (!(region.max.y > region.min.y)) {
    Box3 bottom = region;
    bottom.max.y = region.min.y;
    return {bottom};
  }
  std::vector<Box3> out;
  for (int k = 0; k < levels; ++k) {
    Box3 r = region;
    r.min.y = r.max.y = k == 0            ? region.min.y
                        : k == levels - 1 ? region.max.y
                                          : region.min.y + (region.max.y - region.min.y) *
                                                               double(k) / double(levels - 1);
    out.push_back(r);
  }
  return out;
}

}  // namespace

SegmentRunCache::Key sweep_family_key(const FaceSweep& sweep) {
  assert(sweep.face.size() >= 2);
  // A strip's window tells it from the face's other strips, `across` the face's crossed sweep
  // from its first (crossed_sweep).
  const auto end = [](double t) { return std::isfinite(t) ? t : 0.0; };
  return SegmentRunCache::key_of(sweep.face[0] + sweep.along * end(sweep.t_lo),
                                 sweep.face[1] + sweep.along * end(sweep.t_hi) + sweep.across,
                                 sweep.side_normal);
}

std::vector<Segment> cell_boundary_segments(const Box3& view_region, int levels) {
  std::vector<Segment> out;
  for (const Box3& rect : band_rectangles(view_region, levels)) {
    auto s = perimeter_segments(rect);
    out.insert(out.end(), s.begin(), s.end());
  }
  return out;
}

std::vector<Segment> vertical_edge_segments(const Box3& view_region) {
  if (!(view_region.max.y > view_region.min.y)) return {};
  std::vector<Segment> out;
  for (double z : {view_region.min.z, view_region.max.z})
    for (double x : {view_region.min.x, view_region.max.x})
      out.push_back(Segment{{x, view_region.min.y, z}, {x, view_region.max.y, z}});
  return out;
}

uint64_t cell_seed(uint64_t seed, uint32_t cell) {
  return Rng::derive(seed, cell);
}

std::vector<Box3> cell_rectangles(const pvs::CellLayout& layout, uint32_t cell, int levels) {
  return band_rectangles(to_box3(layout.view_region(cell)), levels);
}

namespace {

// The options of group g of a cell's segment groups: its runs seeded Rng::derive(cell_seed, g),
// so that a re-run of one group (cell_witness_rays) makes the bake's own runs.
RegionOptions group_options(const RegionOptions& options, uint64_t cell_seed, size_t g) {
  RegionOptions o = options;
  o.seed = Rng::derive(cell_seed, uint64_t(g));
  return o;
}

// `options` for cell `cell` of `cells`: its near distance clipped to the cell's near_limit, unless
// the runs are shared between cells (ViewCells::shared_runs: not eyes of this cell).
RegionOptions cell_options(const ViewCells& cells, uint32_t cell, const RegionOptions& options) {
  RegionOptions o = options;
  if (!cells.near_limit.empty() && !cells.shared_runs)
    o.segment.near = std::min(o.segment.near, cells.near_limit.at(cell));
  return o;
}

// Runs cell `cell`'s groups in order, each a segments_visibility call with its own seed
// (group_options), and hands each to `consume(segments, result, options)`, which returns whether
// more groups are wanted (a cell without sweeps then stops; a sweep's rounds need every round
// before them, so an adaptive cell runs on): the cell's fixed
// groups (cell_segment_groups), then, for a cell with adaptive face sweeps (ViewCells::sweeps),
// the sweep's rounds (face_sweep.h), round r seeded as group (fixed groups + r), whose neighbours
// at a face's ends see what the fixed groups saw. Ids of spheres count after the triangles in
// the sweep's comparisons. `progress(fraction)` as in cell_visibility: the runs done over the
// runs to do; for an adaptive cell the rounds' runs are an estimate (expected_adaptive_probes,
// then the sweep's own before each round), and the fraction never decreases.
void run_cell_groups(const Scene& scene, const ViewCells* cells,
                     const std::vector<std::vector<Segment>>& groups, uint32_t cell,
                     const RegionOptions& options, const std::function<void(double)>& progress,
                     const std::function<bool(const std::vector<Segment>&, const RegionResult&,
                                              const RegionOptions&)>& consume) {
  const bool adaptive = cells && !cells->sweeps.empty() && !cells->sweeps.at(cell).empty();
  const uint64_t seed = cell_seed(options.seed, cell);
  const size_t fixed = groups.size();
  // Progress: runs done over runs to do, the rounds' an estimate (set below).
  double runs_before = 0, runs_total = 0, shown = 0;
  for (const std::vector<Segment>& g : groups)
    runs_total += double(g.size() * size_t(options.runs));
  const double fixed_runs = runs_total;
  auto report = [&](double runs_in_group) {
    const double fraction = (runs_before + runs_in_group) / std::max(1.0, runs_total);
    shown = std::max(shown, std::min(1.0, fraction));
    progress(shown);
  };
  bool wanted = true;
  // Trees over the bounds of the cell's runs (ViewCells::bound_leaves), each built once.
  const bool bounded = cells && !cells->bound_leaves.empty();
  constexpr uint32_t kWholeScene = UINT32_MAX;
  std::map<uint32_t, TriangleBvh> trees;
  // Their primitives: the bake's tree's, or without one the scene's fans when the runs take them
  // (built on the first bound).
  std::optional<TriangleGroups> own_fans;
  const TriangleGroups* fans = options.segment.bvh ? &options.segment.bvh->groups : nullptr;
  auto tree_of = [&](uint32_t b) -> const TriangleBvh* {
    if (b == kWholeScene) return nullptr;
    auto it = trees.find(b);
    if (it == trees.end()) {
      PhaseScope building(Phase::BoundTrees);
      if (!fans) {
        own_fans = options.segment.fans ? build_triangle_groups(scene, options.segment.state)
                                        : TriangleGroups{};
        fans = &*own_fans;
      }
      const std::vector<uint32_t> subset =
          bound_triangles(cells->leaf_triangles, cells->bound_leaves.at(b));
      it = trees.emplace(b, build_triangle_bvh(scene, options.segment.state, subset, *fans)).first;
    }
    return &it->second;
  };
  // The trees of segments `segs`, whose bounds are bound_of(i); none when the cells have no bounds.
  auto trees_of = [&](const std::vector<Segment>& segs,
                      const std::function<uint32_t(size_t)>& bound_of) {
    std::vector<const TriangleBvh*> out;
    if (bounded)
      for (size_t i = 0; i < segs.size(); ++i) out.push_back(tree_of(bound_of(i)));
    return out;
  };
  auto run_group = [&](const std::vector<Segment>& segs, size_t g, std::vector<uint32_t> users,
                       std::vector<const TriangleBvh*> bvhs,
                       std::vector<std::vector<uint8_t>> masks = {}) {
    RegionOptions o = group_options(options, seed, g);
    o.segment_users = std::move(users);
    o.segment_bvhs = std::move(bvhs);
    o.segment_tile_masks = std::move(masks);
    o.segment_tile_mask_size = cells ? cells->sweep_spacing.tile_size : 0;
    std::function<void(size_t, size_t)> run_done;
    if (progress) run_done = [&](size_t done, size_t) { report(double(done)); };
    RegionResult rr = segments_visibility(scene, segs, o, run_done);
    runs_before += double(segs.size() * size_t(o.runs));
    wanted = consume(segs, rr, o) && wanted;
    return rr;
  };
  const uint32_t tris = uint32_t(scene.triangle_count());
  auto ids_of_run = [&](const RunRecord& r, std::vector<uint32_t>& out) {
    std::vector<uint32_t> run = r.visible, merged;  // triangles, then spheres: sorted
    for (uint32_t sp : r.visible_spheres) run.push_back(tris + sp);
    std::set_union(out.begin(), out.end(), run.begin(), run.end(), std::back_inserter(merged));
    out = std::move(merged);
  };
  // A portal's sweep (sided: both of its leaves sweep it) is judged by what run 0 sees on both
  // sides (side 0's triangle ids, then side 1's offset by the id count), from a base of what its
  // polygon's edges see so, so that both leaves insert the same chords and the second takes the
  // first's runs from the cache (sweep_family_key, SegmentRunCache::expect_family).
  static const std::vector<FaceSweep> kNoSweeps;
  const std::vector<FaceSweep>& sweeps = adaptive ? cells->sweeps[cell] : kNoSweeps;
  if (adaptive)
    runs_total +=
        expected_adaptive_probes(sweeps, cells->sweep_spacing, kRefinePrior) * double(options.runs);
  std::vector<std::vector<uint32_t>> bases(sweeps.size());
  std::vector<uint32_t> users(sweeps.size(), 0);
  bool any_sided = false;
  for (size_t f = 0; f < sweeps.size(); ++f) {
    const bool sided = !(sweeps[f].side_normal == Vec3{0, 0, 0});
    any_sided = any_sided || sided;
    if (sided && options.shared_runs)
      users[f] = options.shared_runs->family_users(sweep_family_key(sweeps[f]));
  }
  const uint32_t ids = tris + uint32_t(scene.sphere_count());
  auto both_sides = [&](const RunRecord& r, int side, std::vector<uint32_t>& out) {
    const std::vector<uint32_t>& s0 = side == 0 ? r.visible : r.visible_other_side;
    const std::vector<uint32_t>& s1 = side == 0 ? r.visible_other_side : r.visible;
    std::vector<uint32_t> run = s0, merged;
    for (uint32_t t : s1) run.push_back(ids + t);
    std::set_union(out.begin(), out.end(), run.begin(), run.end(), std::back_inserter(merged));
    out = std::move(merged);
  };
  // The runs that judge: `rr`, or with witnesses (whose sided runs keep their own side only) run 0
  // of `segs` again without them (on the same tiles).
  std::vector<RunRecord> rerun;
  auto judging =
      [&](const std::vector<Segment>& segs, const RegionResult& rr,
          const std::vector<const TriangleBvh*>& bvhs,
          const std::vector<std::vector<uint8_t>>& masks = {}) -> const std::vector<RunRecord>& {
    if (!(any_sided && options.segment.want_witnesses)) return rr.runs;
    RegionOptions o = options;
    o.segment.want_witnesses = false;
    o.runs = 1;
    o.shared_runs = nullptr;
    o.segment_bvhs = bvhs;
    o.segment_tile_masks = masks;
    o.segment_tile_mask_size = cells ? cells->sweep_spacing.tile_size : 0;
    rerun = segments_visibility(scene, segs, o).runs;
    return rerun;
  };
  // A cell whose runs lie on portals has one group, its own segments (cell_segment_groups); a
  // sided segment is an edge of each sweep of its portal (ViewCells::segment_portal), and its
  // bound is its portal's, but for a run that stands for several portals' edges.
  const bool on_portals = cells && !cells->segment_portal.empty();
  assert(!on_portals || (fixed == 1 && groups[0].size() == cells->segment_portal.at(cell).size()));
  auto segment_bound = [&](size_t i) {
    return groups[0][i].run_planes[0] == Vec3{0, 0, 0} ? cells->segment_portal[cell][i]
                                                       : kWholeScene;
  };
  std::vector<uint32_t> base;
  for (size_t g = 0; g < fixed && (wanted || adaptive); ++g) {
    const std::vector<const TriangleBvh*> bvhs = trees_of(groups[g], segment_bound);
    const RegionResult rr = run_group(groups[g], g, {}, bvhs);
    if (!adaptive) continue;
    for (const RunRecord& r : rr.runs) ids_of_run(r, base);
    if (!any_sided) continue;
    for (const RunRecord& r : judging(groups[g], rr, bvhs)) {
      const Segment& s = groups[g].at(r.segment);
      if (r.run != 0 || s.side_normal == Vec3{0, 0, 0} || !on_portals) continue;
      for (size_t f = 0; f < sweeps.size(); ++f)
        if (cells->segment_portal[cell][r.segment] == cells->sweep_portal.at(cell).at(f))
          both_sides(r, s.side, bases[f]);
    }
  }
  if (!adaptive) return;
  for (size_t f = 0; f < sweeps.size(); ++f)
    if (sweeps[f].side_normal == Vec3{0, 0, 0}) bases[f] = base;
  // A chord below a probe that saw new ids looks only toward them (AdaptiveSpacing::tiles):
  // the tiles of its run 0 where they can appear (chord_tiles_toward, tiles of
  // AdaptiveSpacing::tile_size pixels), a sided run's ids of either side being triangles; the whole
  // cube when one is a sphere.
  const bool masked = cells && cells->sweep_spacing.tiles != ChordTiles::All &&
                      scene.sphere_count() == 0 && !scene.is_dynamic();
  auto tiles_toward = [&](const std::vector<Segment>& segs,
                          const std::vector<std::vector<uint32_t>>& fresh) {
    std::vector<std::vector<uint8_t>> masks;
    if (!masked) return masks;
    masks.resize(segs.size());
    bool any = false;
    std::vector<uint32_t> tri;
    for (size_t i = 0; i < segs.size(); ++i) {
      tri.clear();
      for (uint32_t id : fresh[i]) tri.push_back(id >= ids ? id - ids : id);
      if (std::any_of(tri.begin(), tri.end(), [&](uint32_t t) { return t >= tris; })) continue;
      std::optional<std::vector<uint8_t>> m =
          chord_tiles_toward(scene, options.segment.state, segs[i], tri, options.segment.resolution,
                             cells->sweep_spacing.tile_size, kChordTileMargin,
                             cells->sweep_spacing.tiles == ChordTiles::NewEveryFace);
      if (!m) continue;
      masks[i] = std::move(*m);
      any = true;
    }
    if (!any) masks.clear();
    return masks;
  };
  size_t round = 0;
  adaptive_sweep(
      sweeps, cells->sweep_spacing, bases, kSweepMinChord,
      [&](const std::vector<Segment>& segs, const std::vector<size_t>& sweep_of,
          const std::vector<std::vector<uint32_t>>& fresh) {
        std::vector<uint32_t> segment_users(segs.size());
        for (size_t i = 0; i < segs.size(); ++i) segment_users[i] = users[sweep_of[i]];
        const std::vector<const TriangleBvh*> bvhs =
            trees_of(segs, [&](size_t i) { return cells->sweep_portal.at(cell)[sweep_of[i]]; });
        const std::vector<std::vector<uint8_t>> masks = tiles_toward(segs, fresh);
        const RegionResult rr =
            run_group(segs, fixed + round++, std::move(segment_users), bvhs, masks);
        std::vector<std::vector<uint32_t>> seen(segs.size());
        for (const RunRecord& r : judging(segs, rr, bvhs, masks)) {
          const Segment& s = segs.at(r.segment);
          if (s.side_normal == Vec3{0, 0, 0})
            ids_of_run(r, seen[r.segment]);
          else if (r.run == 0)
            both_sides(r, s.side, seen[r.segment]);
        }
        return seen;
      },
      [&](size_t, double expected) { runs_total = fixed_runs + expected * double(options.runs); });
}

// The middle of the points q - s d (s >= 0) inside `region`, if any.
std::optional<Vec3> back_into(const ConvexPolytope& region, Vec3 q, Vec3 d) {
  double lo = 0, hi = INFINITY;
  for (const HalfSpace& h : region.halfspaces) {
    // dot(n, q - s d) <= offset  <=>  -s dot(n, d) <= offset - dot(n, q)
    const double a = -dot(h.normal, d), b = h.offset - dot(h.normal, q);
    if (a > 0)
      hi = std::min(hi, b / a);
    else if (a < 0)
      lo = std::max(lo, b / a);
    else if (b < 0)
      return std::nullopt;
  }
  if (!(lo < hi) || !std::isfinite(hi)) return std::nullopt;
  return q - d * (0.5 * (lo + hi));
}

// The union of the cell's groups (run_cell_groups).
CellVisibility groups_visibility(const Scene& scene, const ViewCells* cells,
                                 const std::vector<std::vector<Segment>>& groups, uint32_t cell,
                                 const RegionOptions& options,
                                 const std::function<void(double)>& progress) {
  CellVisibility out;
  run_cell_groups(
      scene, cells, groups, cell, options, progress,
      [&](const std::vector<Segment>& segs, const RegionResult& rr, const RegionOptions&) {
        out.segments.insert(out.segments.end(), segs.begin(), segs.end());
        PhaseScope merging(Phase::Merge);
        std::vector<uint32_t> merged;
        merged.reserve(out.triangles.size() + rr.visible.size());
        std::set_union(out.triangles.begin(), out.triangles.end(), rr.visible.begin(),
                       rr.visible.end(), std::back_inserter(merged));
        out.triangles = std::move(merged);
        merged.clear();
        std::set_union(out.spheres.begin(), out.spheres.end(), rr.visible_spheres.begin(),
                       rr.visible_spheres.end(), std::back_inserter(merged));
        out.spheres = std::move(merged);
        out.seconds += rr.seconds;
        return true;
      });
  return out;
}

std::vector<std::vector<Segment>> rectangle_groups(const pvs::CellLayout& layout, uint32_t cell,
                                                   int levels = kPaperBandLevels) {
  std::vector<std::vector<Segment>> groups;
  for (const Box3& rect : cell_rectangles(layout, cell, levels))
    groups.push_back(perimeter_segments(rect));
  return groups;
}

}  // namespace

std::vector<std::vector<Segment>> cell_segment_groups(const ViewCells& cells, uint32_t cell) {
  if (!cells.segments.empty()) return {cells.segments.at(cell)};
  std::vector<std::vector<Segment>> groups =
      rectangle_groups(cells.layout, cell, cells.band_levels);
  if (cells.vertical_edges) {
    std::vector<Segment> v = vertical_edge_segments(to_box3(cells.layout.view_region(cell)));
    if (!v.empty()) groups.push_back(std::move(v));
  }
  if (!cells.wall_traces.empty() && !cells.wall_traces.at(cell).empty())
    groups.push_back(cells.wall_traces[cell]);
  return groups;
}

std::vector<Segment> recorded_cell_segments(const pvs::FileInfo& info, uint32_t cell,
                                            const Scene* scene) {
  assert(info.layout.kind != pvs::LayoutKind::BspTree);
  const Box3 region = to_box3(info.layout.view_region(cell));
  std::vector<Segment> out = cell_boundary_segments(region, band_levels_of(info.metadata));
  if (vertical_edges_of(info.metadata)) {
    const std::vector<Segment> v = vertical_edge_segments(region);
    out.insert(out.end(), v.begin(), v.end());
  }
  const std::optional<WallTraceOptions> traces = wall_traces_of(info.metadata);
  if (traces && scene) {
    const std::vector<Segment> t = wall_traces(*scene, region, *traces);
    out.insert(out.end(), t.begin(), t.end());
  }
  return out;
}

CellVisibility cell_visibility(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress) {
  assert(layout.kind != pvs::LayoutKind::BspTree);  // BSP leaf cells: pass their ViewCells
  return groups_visibility(scene, nullptr, rectangle_groups(layout, cell), cell, options, progress);
}

CellVisibility cell_visibility(const Scene& scene, const ViewCells& cells, uint32_t cell,
                               const RegionOptions& options,
                               const std::function<void(double)>& progress) {
  CellVisibility v = groups_visibility(scene, &cells, cell_segment_groups(cells, cell), cell,
                                       cell_options(cells, cell, options), progress);
  if (!cells.own.empty() && !cells.own.at(cell).empty()) {
    std::vector<uint32_t> own, merged;
    for (const ViewCells::OwnTriangle& t : cells.own[cell]) own.push_back(t.tri);
    std::set_union(v.triangles.begin(), v.triangles.end(), own.begin(), own.end(),
                   std::back_inserter(merged));
    v.triangles = std::move(merged);
  }
  return v;
}

std::vector<CellWitnessRay> cell_witness_rays(const Scene& scene, const ViewCells& cells,
                                              uint32_t cell, const RegionOptions& options,
                                              const std::vector<uint32_t>& wanted) {
  assert(options.shared_runs == nullptr);
  RegionOptions with_witnesses = cell_options(cells, cell, options);
  with_witnesses.segment.want_witnesses = true;
  const int n = options.segment.resolution;
  std::vector<CellWitnessRay> out;
  std::vector<uint8_t> found(wanted.size(), 0);
  size_t left = wanted.size(), first_segment = 0;
  if (!cells.own.empty())  // the cell's own triangles: their ray from the view region
    for (const ViewCells::OwnTriangle& t : cells.own.at(cell)) {
      const auto it = std::lower_bound(wanted.begin(), wanted.end(), t.tri);
      if (it == wanted.end() || *it != t.tri) continue;
      found[size_t(it - wanted.begin())] = 1;
      --left;
      CellWitnessRay w;
      w.tri = t.tri;
      w.eye = t.eye;
      w.dir = t.dir;
      w.segment = kOwnTriangleSegment;
      out.push_back(w);
    }
  if (left == 0) {
    std::sort(out.begin(), out.end(),
              [](const CellWitnessRay& a, const CellWitnessRay& b) { return a.tri < b.tri; });
    return out;
  }
  run_cell_groups(
      scene, &cells, cell_segment_groups(cells, cell), cell, with_witnesses, {},
      [&](const std::vector<Segment>& segs, const RegionResult& rr, const RegionOptions& o) {
        for (size_t i = 0; i < rr.visible.size() && left > 0; ++i) {
          const auto it = std::lower_bound(wanted.begin(), wanted.end(), rr.visible[i]);
          if (it == wanted.end() || *it != rr.visible[i] || found[size_t(it - wanted.begin())])
            continue;
          found[size_t(it - wanted.begin())] = 1;
          --left;
          const RegionWitness& w = rr.witnesses[i];
          const Segment& s = segs[w.segment];
          const Mat3& R = rr.runs[w.segment * size_t(o.runs) + size_t(w.run)].orientation;
          const Vec3 d = pixel_direction(face_axes(w.witness.face, R), w.witness.x, w.witness.y, n);
          Vec3 eye = s.from + (s.to - s.from) * w.witness.t;
          if (!cells.regions.empty() && !cells.regions.at(cell).empty()) {
            // A shared run's eye lies on the region's boundary: back along the ray into the region.
            const std::optional<Vec3> inside = back_into(cells.regions[cell], eye, d);
            if (!inside) {  // the ray does not pass through the region: no witness of the cell
              found[size_t(it - wanted.begin())] = 0;
              ++left;
              continue;
            }
            eye = *inside;
          }
          out.push_back({rr.visible[i], eye, d * (1.0 / length(d)), first_segment + w.segment,
                         w.run, w.witness.t});
        }
        first_segment += segs.size();
        return left > 0;
      });
  std::sort(out.begin(), out.end(),
            [](const CellWitnessRay& a, const CellWitnessRay& b) { return a.tri < b.tri; });
  return out;
}

}  // namespace vislib
