// region_visibility.cpp: paper §4.1 (perimeter of the view rectangle) and §4.5 (random cube
// orientations per run).
#include "vislib/kernel/region_visibility.h"

#include <algorithm>
#include <cassert>
#include <functional>
#include <iterator>

#include "vislib/base/phase_times.h"
#include "vislib/base/random.h"
#include "vislib/kernel/segment_run_cache.h"

namespace vislib {

std::vector<Segment> perimeter_segments(const Box3& box) {
  std::vector<int> flat, open;
  for (int a = 0; a < 3; ++a) (box.max[a] > box.min[a] ? open : flat).push_back(a);
  std::vector<Segment> out;
  if (open.empty()) return {{box.min, box.min}};
  // Every edge of the box along an open axis, at each low/high pattern of the other open axes
  // (flat axes have a single value).
  for (int axis : open) {
    std::vector<int> others;
    for (int a : open)
      if (a != axis) others.push_back(a);
    int patterns = 1 << others.size();
    for (int p = 0; p < patterns; ++p) {
      Vec3 a = box.min;
      for (size_t k = 0; k < others.size(); ++k)
        if (p & (1 << k)) a[others[k]] = box.max[others[k]];
      Vec3 b = a;
      b[axis] = box.max[axis];
      out.push_back({a, b});
    }
  }
  return out;
}

Mat3 run_orientation(uint64_t seed, size_t segment, int run) {
  if (run == 0) return Mat3{};
  return random_orientation(Rng::derive(Rng::derive(seed, segment), uint64_t(run)));
}

RegionResult region_visibility(const Scene& scene, const Box3& box, const RegionOptions& options,
                               const std::function<void(size_t, size_t)>& progress) {
  return segments_visibility(scene, perimeter_segments(box), options, progress);
}

RegionResult segments_visibility(const Scene& scene, std::vector<Segment> segments,
                                 const RegionOptions& options,
                                 const std::function<void(size_t, size_t)>& progress) {
  RegionResult result;
  result.segments = std::move(segments);
  const size_t total = result.segments.size() * size_t(options.runs);
  const bool witnesses = options.segment.want_witnesses;
  // Without witnesses the union is merged from the runs' sorted lists, in memory of the visible
  // sets (a bake holds one per cell in flight); with them, flags per id keep each id's first
  // witness.
  std::vector<uint8_t> in_union(witnesses ? scene.triangle_count() : 0),
      sphere_in_union(witnesses ? scene.sphere_count() : 0);
  std::vector<uint32_t> tri_union, sphere_union, merged;
  size_t union_size = 0;
  std::vector<RegionWitness> tri_witness(witnesses ? scene.triangle_count() : 0),
      sphere_witness(witnesses ? scene.sphere_count() : 0);
  for (size_t s = 0; s < result.segments.size(); ++s) {
    for (int k = 0; k < options.runs; ++k) {
      SegmentOptions so = options.segment;
      so.orientation = run_orientation(options.seed, s, k);
      so.want_pieces = false;
      if (!options.segment_bvhs.empty() && options.segment_bvhs.at(s))
        so.bvh = options.segment_bvhs[s];
      if (k == 0 && !options.segment_tile_masks.empty()) {
        so.tile_mask = options.segment_tile_masks.at(s);
        if (!so.tile_mask.empty() && options.segment_tile_mask_size > 0)
          so.tile_size = options.segment_tile_mask_size;
      }
      const uint32_t users = options.segment_users.empty() ? 0 : options.segment_users.at(s);
      const Segment& seg = result.segments[s];
      const bool sided = !(seg.side_normal == Vec3{0, 0, 0});
      // A shared run's planes (Segment::run_planes) without witnesses, else its own plane.
      const bool planes = sided && !witnesses && !(seg.run_planes[0] == Vec3{0, 0, 0});
      so.side_normal = planes ? seg.run_planes[0] : seg.side_normal;
      if (planes)
        std::copy(seg.run_planes.begin() + 1, seg.run_planes.end(), so.more_side_normals.begin());
      so.side_only = witnesses && sided ? seg.side : -1;
      const size_t plane = planes ? size_t(seg.run_plane) : 0;
      SegmentResult sr;
      bool computed = true;
      // Phases for a caller that times them (phase_times.h): a run computed here, or one another
      // thread computes (whose tiles this thread joins while it waits).
      // A planned long segment keeps no witnesses per part, nor a run split by a plane one per
      // side: such regions compute their own.
      if (options.shared_runs && k == 0 && (so.tile_mask.empty() || users > 1) &&
          !(witnesses && (sided || options.shared_runs->chains_planned() > 0))) {
        PhaseScope waiting(Phase::SharedWait);
        auto shared = options.shared_runs->get(
            seg.from, seg.to,
            [&](Vec3 a, Vec3 b, const std::vector<double>& splits) {
              PhaseScope running(Phase::Run);
              SegmentOptions o = so;
              o.splits = splits;
              return segment_visibility(scene, a, b, o);
            },
            &computed, run_key_normal(seg), users);
        sr = *shared;  // a copy: the cache's result is shared with other regions
        if (!computed) sr.stats.seconds = 0;
      } else {
        PhaseScope running(Phase::Run);
        sr = segment_visibility(scene, seg.from, seg.to, so);
      }
      std::vector<uint32_t> other_side;
      if (sided && !witnesses) {
        other_side = std::move(sr.visible_sides.at(2 * plane + size_t(1 - seg.side)));
        sr.visible = std::move(sr.visible_sides.at(2 * plane + size_t(seg.side)));
      }
      PhaseScope merging(Phase::Merge);
      if (witnesses) {
        // sr.witnesses: one per visible triangle (id order), then one per visible sphere.
        for (size_t i = 0; i < sr.visible.size(); ++i) {
          uint32_t id = sr.visible[i];
          if (in_union[id]) continue;
          in_union[id] = 1;
          ++union_size;
          tri_witness[id] = {s, k, sr.witnesses[i]};
        }
        for (size_t i = 0; i < sr.visible_spheres.size(); ++i) {
          uint32_t sp = sr.visible_spheres[i];
          if (sphere_in_union[sp]) continue;
          sphere_in_union[sp] = 1;
          sphere_witness[sp] = {s, k, sr.witnesses[sr.visible.size() + i]};
        }
      } else {
        assert(std::adjacent_find(sr.visible.begin(), sr.visible.end(),
                                  std::greater_equal<uint32_t>()) == sr.visible.end());
        merged.clear();
        std::set_union(tri_union.begin(), tri_union.end(), sr.visible.begin(), sr.visible.end(),
                       std::back_inserter(merged));
        tri_union.swap(merged);
        union_size = tri_union.size();
        merged.clear();
        std::set_union(sphere_union.begin(), sphere_union.end(), sr.visible_spheres.begin(),
                       sr.visible_spheres.end(), std::back_inserter(merged));
        sphere_union.swap(merged);
      }
      result.seconds += sr.stats.seconds;
      RunRecord rec;
      rec.segment = s;
      rec.run = k;
      rec.orientation = so.orientation;
      rec.visible = std::move(sr.visible);
      rec.visible_spheres = std::move(sr.visible_spheres);
      rec.visible_other_side = std::move(other_side);
      rec.stats = sr.stats;
      rec.union_size_after = union_size;
      rec.seconds_after = result.seconds;
      result.runs.push_back(std::move(rec));
      if (progress) progress(result.runs.size(), total);
    }
  }
  PhaseScope merging(Phase::Merge);
  if (!witnesses) {
    result.visible = std::move(tri_union);
    result.visible_spheres = std::move(sphere_union);
    return result;
  }
  for (uint32_t id = 0; id < in_union.size(); ++id)
    if (in_union[id]) {
      result.visible.push_back(id);
      result.witnesses.push_back(tri_witness[id]);
    }
  for (uint32_t s = 0; s < sphere_in_union.size(); ++s)
    if (sphere_in_union[s]) {
      result.visible_spheres.push_back(s);
      result.witnesses.push_back(sphere_witness[s]);
    }
  return result;
}

std::vector<uint32_t> objects_of(const Scene& scene, const std::vector<uint32_t>& triangles,
                                 const std::vector<uint32_t>& spheres) {
  std::vector<uint32_t> out;
  out.reserve(triangles.size() + spheres.size());
  for (uint32_t t : triangles) out.push_back(scene.triangle_object[t]);
  for (uint32_t s : spheres) out.push_back(scene.sphere_object[s]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace vislib
