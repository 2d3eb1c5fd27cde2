// region_visibility.h: from-region visibility as a union of from-segment runs (paper §4.1, §4.5).
//
// A view region is an axis-aligned box. Its perimeter segments are the paper's heuristic: the four
// sides of a view rectangle (a box flat along one axis), the twelve edges of a full box, the
// segment itself for a box flat along two axes, and a zero-length segment for a point. Each
// segment is run with K cube orientations: run 0 is aligned with the world axes, runs 1..K-1 use
// random rotations drawn from the seed (paper §4.5). The visible set is the union.
#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "vislib/kernel/segment_visibility.h"

namespace vislib {

enum class Granularity { Triangle, Object };

// A segment of eyes. With `side_normal` not zero, only the directions on side `side` of the plane
// through the eye with that normal count (SegmentOptions::side_normal: side 0 is dot(d, n) >= 0,
// side 1 is dot(d, n) <= 0): a portal's chord, whose run serves the leaves on both sides
// (docs/quake.md "Portals"). Its runs are computed with both sides split, so that the shared run
// cache hands one run to both; with witnesses, with the one side.
struct Segment {
  Vec3 from, to;
  Vec3 side_normal{0, 0, 0};
  int side = 0;
  // A run shared by the segments that stand for the edges of several portals meeting along one
  // line, each with its own side_normal: the planes that run splits its directions by
  // (SegmentOptions::more_side_normals), the same for every segment of it, side_normal among them
  // at run_plane; all zero: side_normal alone. Its sides of its plane are those of a run split by
  // that plane alone.
  std::array<Vec3, kMaxSidePlanes> run_planes{};
  int run_plane = 0;
};

// The segments of one shared run (Segment::run_planes) stand for edges whose ends lie within this
// distance of its ends (scene units): the edges of portals that meet along one line, each inset
// from the others' planes by a bake's clearance (about 0.02 at the default near distance).
constexpr double kSharedRunEdgeDistance = 0.1;

// The normal a segment's run is known by in a SegmentRunCache: run_planes[0] when set, else
// side_normal.
inline Vec3 run_key_normal(const Segment& s) {
  return s.run_planes[0] == Vec3{0, 0, 0} ? s.side_normal : s.run_planes[0];
}

// Perimeter segments of `box` (min <= max on every axis), in a fixed documented order: edges
// sorted by (axis of the edge, then the fixed coordinates' low/high pattern).
std::vector<Segment> perimeter_segments(const Box3& box);

// Orientation of run `run` on segment `segment`: identity for run 0, else a rotation drawn from
// (seed, segment, run). Same arguments, same rotation on every platform.
Mat3 run_orientation(uint64_t seed, size_t segment, int run);

class SegmentRunCache;

struct RegionOptions {
  // resolution, near, eps_len, tile size, want_witnesses... (orientation and want_pieces are
  // ignored)
  SegmentOptions segment;
  int runs = 1;  // K orientations per segment, >= 1
  uint64_t seed = 1;
  // When set, run 0 (world-aligned) of every segment goes through this cache, shared with other
  // regions using the same options (segment_run_cache.h; the bake shares cells' common edges).
  // A run served from the cache counts 0 kernel seconds. Not part of the result's identity.
  SegmentRunCache* shared_runs = nullptr;
  // Empty, or one per segment: with shared_runs, run 0 of a segment not announced to it is kept
  // for this many users in all when > 1 (SegmentRunCache::get's `users`: the two leaves of a
  // portal, whose adaptive chords are the same for both).
  std::vector<uint32_t> segment_users;
  // Empty, or one per segment: the tree segment s's runs use instead of segment.bvh, when not
  // null (a tree over a bound of what the segment can see: triangle_bvh.h). A run shared through
  // shared_runs is computed with the tree of the region that computes it, so regions that share a
  // segment must give it the same tree (or none).
  std::vector<const TriangleBvh*> segment_bvhs;
  // Empty, or one per segment: the tiles run 0 (world-aligned) of segment s computes
  // (SegmentOptions::tile_mask; empty: the whole cube); the other runs compute the whole cube. A
  // masked run goes through shared_runs only as a run of a family (segment_users > 1), whose
  // users must give it the same mask.
  std::vector<std::vector<uint8_t>> segment_tile_masks;
  // The tile side (pixels) of segment_tile_masks and of the runs they mask (their
  // SegmentOptions::tile_size, which changes no result: pixels are independent); 0: the side of
  // `segment`. A mask is a sampling choice, so its tiles need not be the kernel's best grain.
  int segment_tile_mask_size = 0;
};

struct RunRecord {
  size_t segment = 0;
  int run = 0;
  Mat3 orientation;
  std::vector<uint32_t> visible;          // triangle ids of this run
  std::vector<uint32_t> visible_spheres;  // sphere indices of this run
  // A run split by a plane (Segment::side_normal) without witnesses: the triangle ids of the
  // other side's directions (`visible` holds the segment's own side); empty otherwise.
  std::vector<uint32_t> visible_other_side;
  SegmentStats stats;
  size_t union_size_after = 0;  // triangles in the union after this run
  double seconds_after = 0;     // cumulative kernel seconds after this run
};

// A witness of the union: the perimeter segment and run that saw the primitive, and where. The
// eye is at segments[segment].from + witness.t (to - from), the cube orientation is the run's
// (run_orientation(seed, segment, run)), so the id can be checked from outside by one ray cast.
struct RegionWitness {
  size_t segment = 0;
  int run = 0;
  Witness witness;
};

struct RegionResult {
  std::vector<Segment> segments;
  std::vector<RunRecord> runs;            // segment-major, run-minor
  std::vector<uint32_t> visible;          // union of triangle ids, sorted
  std::vector<uint32_t> visible_spheres;  // union of sphere indices, sorted
  // If options.segment.want_witnesses: one per id of the union, triangles (in `visible` order)
  // then spheres (in `visible_spheres` order), each from the first run (segment-major, run-minor)
  // that saw it.
  std::vector<RegionWitness> witnesses;
  double seconds = 0;
};

// Runs every perimeter segment `runs` times: segments_visibility(perimeter_segments(box)).
// `progress(done, total)` is called after each run if given (from the calling thread).
RegionResult region_visibility(const Scene& scene, const Box3& box, const RegionOptions& options,
                               const std::function<void(size_t, size_t)>& progress = {});

// The same on any list of segments (a region whose boundary is not a box's: bsp_cells.h sweeps a
// polytope's faces): segment s is run `runs` times with run_orientation(options.seed, s, k), in
// list order; result.segments = `segments`. Deterministic as region_visibility.
RegionResult segments_visibility(const Scene& scene, std::vector<Segment> segments,
                                 const RegionOptions& options,
                                 const std::function<void(size_t, size_t)>& progress = {});

// Object ids (sorted) of the objects owning at least one of `triangles` or `spheres`.
std::vector<uint32_t> objects_of(const Scene& scene, const std::vector<uint32_t>& triangles,
                                 const std::vector<uint32_t>& spheres = {});

}  // namespace vislib
