// pvs_check.h: the sampled ground truth of a bake, for any cells (`pvs check`, docs/check.md), and
// the sampler it shares with `pvs vis-compare` (vis_compare.h).
//
// Sampling: random eyes in a cell's view region, a first-hit cubemap of N x N pixels per face
// from each eye, in one or more orientations (Embree, float; see-through triangles passed through
// as the kernel's rule says, docs/visibility.md "See-through triangles"), and every triangle hit
// must be in the cell's set. A hit x missing from a set S is re-cast in double
// (ray_crossings, ray_reference.h) under the seeing rule of vis_compare.h: it is a **miss** of S
// when the double-precision ray sees x (crossed beyond z_near, farther than kReferenceBarycentric
// inside its edges, no opaque triangle in front of it by more than eps_z * lambda_x) and crosses
// no triangle of S (edges widened by kReferenceBarycentric) within eps_z * lambda_x of x: a hit
// on either of two coincident faces, or on a shared edge, counts for a set holding either. A hit
// whose re-cast does not see x is **ambiguous** (the float and double answers disagree, or the
// ray grazes an edge), never a miss. Hits that are in the set are not re-cast: a hit in the set
// can be no miss, whatever the double answer.
//
// Eyes: drawn uniformly in the view region (a box in scene coordinates, or a BSP leaf's convex
// view region, bsp_leaf_view_region, in Quake coordinates: uniform in its bounding box up to
// kEyeRejectionTries times until inside, else a random convex combination of its corners). An
// eye the caller's free-space test rejects (an eye inside a solid) is drawn again, up to
// kEyeRedraws times per eye; the rejected draws are counted, and an eye that finds no free point
// is given up and counted. The eyes of a BSP leaf's region need no such test (PvsCheckOptions).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/random.h"
#include "vislib/base/tolerances.h"
#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/quake_bsp_volumes.h"
#include "vislib/scene/scene.h"

namespace vislib {

class RayCrossingIndex;  // ray_reference.h

// A uniform eye of a leaf region is drawn in its bounding box up to this many times until it
// falls inside (then a random convex combination of its corners).
constexpr int kEyeRejectionTries = 64;
// Draws of one eye rejected by the free-space test before the eye is given up.
constexpr int kEyeRedraws = 64;

// The view region eyes of a cell are drawn from: none (no eye can be drawn), `box` (scene
// coordinates), or the convex region `leaf` of a BSP leaf in Quake coordinates
// (bsp_leaf_view_region), whose eyes are mapped to the scene by quake_to_scene; `leaf_corners`
// are its distinct vertices (polytope_corners), never empty for a leaf region.
struct EyeRegion {
  enum Kind { none, box_region, leaf_region } kind = none;
  Box3 box;
  ConvexPolytope leaf;
  std::vector<Vec3> leaf_corners;
  // The largest near distance at which the region's eyes see no surface cut by the near plane
  // (a leaf thinner than twice the clearance, bsp_leaf_view_region); rays from its eyes use the
  // smaller of this and the bake's near.
  double near_limit = std::numeric_limits<double>::infinity();
};
EyeRegion box_eye_region(const Box3& box);  // box.min <= box.max on every axis
// The distinct vertices of `p`'s faces, in face order.
std::vector<Vec3> polytope_corners(const ConvexPolytope& p);
// Calls one_cell(c) for every c < n, in parallel within chunks of 64 cells, and
// progress(done, n) (if given) from the calling thread after each chunk.
void for_cells_in_chunks(size_t n, const std::function<void(size_t)>& one_cell,
                         const std::function<void(size_t, size_t)>& progress);

// The eye regions of the leaves `leaves` of model 0 of `bsp` for a bake of near distance `near`:
// bsp_leaf_view_region(piece, near) of each leaf's piece (bsp_leaf_pieces), with its near_limit,
// and each region's inset (Quake units; 0 for an empty region) in `insets` if given. Leaf 0 and a
// leaf without a piece (or whose region has no corner) get region `none`.
std::vector<EyeRegion> bsp_leaf_eye_regions(const QuakeBsp& bsp,
                                            const std::vector<uint32_t>& leaves, double near,
                                            std::vector<double>* insets = nullptr);
// A random eye of `r` in scene coordinates (file comment). `r` must not be `none`. Box regions
// draw x, y, z uniformly in that order (a box of zero thickness on an axis gives that coordinate).
Vec3 random_eye(const EyeRegion& r, Rng& rng);

// What the sampler needs besides the sets: the scene (state 0), its Embree scene, and the
// cubemaps' settings.
struct SampleSettings {
  int resolution = 64;           // N x N pixels per face; >= 1
  double z_near = kDefaultNear;  // near distance of every ray (scene units); > 0
  double eps_z = kDefaultEpsZ;   // depth tie tolerance, relative
  std::vector<Mat3> orientations = {identity_orientation()};  // one cubemap per orientation
  // Optional: per triangle, the id of the plane of its face (kNoTrianglePlane: none). When set, a
  // hit x missing from a set is no miss of it, without a re-cast, when the next surface behind x
  // along the ray (Embree) lies on x's plane and is in the set (a coincident face of a map).
  const std::vector<uint32_t>* tri_plane = nullptr;
  // Optional: the scene's RayCrossingIndex at time 0, which makes each re-cast O(log triangles)
  // with the same answer; null: every re-cast visits every triangle (ray_crossings).
  const RayCrossingIndex* crossings = nullptr;
};
constexpr uint32_t kNoTrianglePlane = 0xFFFFFFFFu;

// One set a sampled eye is held against: in_set[t] != 0 for its triangles; misses on triangles
// with excused[t] != 0 (if given) are counted apart (`excused`), not as misses.
struct SampledSet {
  const std::vector<uint8_t>* in_set = nullptr;
  const std::vector<uint8_t>* excused = nullptr;
  uint64_t misses = 0, excused_misses = 0;  // rays (pixels)
  std::vector<uint32_t> missed;             // the triangle of each miss ray, in sampling order
};

struct SampleTally {
  uint64_t rays = 0, no_hit = 0, ambiguous = 0;  // ambiguous: hits whose re-cast does not see them
};

// Casts the cubemaps of `settings` from `eye` (scene coordinates) and holds every hit against
// each of `sets` (file comment), adding to their counts and to `tally`. Thread-safe for distinct
// `sets` and `tally`; deterministic.
void sample_eye(const Scene& scene, const EmbreeScene& embree, const SampleSettings& settings,
                Vec3 eye, std::vector<SampledSet>& sets, SampleTally& tally);

// ---- pvs check -----------------------------------------------------------------------------

struct PvsCheckOptions {
  int samples = 4;        // eyes per cell; >= 1
  SampleSettings sample;  // tri_plane unused
  uint64_t seed = 1;      // eyes: cell c draws from Rng::derive(seed, c)
  // The free-space test: true when an eye lies inside a solid (drawn again). Empty: none.
  // Applied to the eyes of box regions only: a BSP leaf's region lies in an empty leaf, free
  // space by the map's own tree (and a map's faces are wound the other way round, so that a
  // test by back faces, such as point_enclosed, calls every point of a map enclosed). Called
  // from worker threads.
  std::function<bool(Vec3)> in_solid;
};

struct PvsCheckCell {
  uint32_t cell = 0;
  size_t set_size = 0;
  int eyes = 0;               // eyes sampled
  uint64_t eyes_redrawn = 0;  // draws rejected by the free-space test
  int eyes_given_up = 0;      // eyes with kEyeRedraws rejected draws (not sampled)
  SampleTally tally;
  uint64_t miss_rays = 0;
  // The missed triangles, increasing, each with its miss rays.
  std::vector<std::pair<uint32_t, uint64_t>> missed;
};

struct PvsCheckResult {
  std::vector<PvsCheckCell> cells;  // in cell order
};

// Samples every cell c (regions[c], its set sets[c]: sorted triangle ids of `scene`) as the file
// comment says. regions.size() must equal sets.size(); a region `none` is not sampled (eyes 0).
// `progress(done, total)` is called from the calling thread between chunks of cells if given.
// TBB-parallel over cells; the result does not depend on the thread count.
PvsCheckResult pvs_check(const Scene& scene, const std::vector<EyeRegion>& regions,
                         const std::vector<std::vector<uint32_t>>& sets,
                         const PvsCheckOptions& options,
                         const std::function<void(size_t, size_t)>& progress = {});

// Totals over the cells.
struct PvsCheckTotals {
  uint64_t eyes = 0, eyes_redrawn = 0, eyes_given_up = 0, rays = 0, no_hit = 0, ambiguous = 0,
           miss_rays = 0;
  size_t cells_with_misses = 0, missed_pairs = 0;  // pairs (cell, missed triangle)
  size_t missed_triangles = 0;                     // distinct triangles missed by some cell
};
PvsCheckTotals pvs_check_totals(const PvsCheckResult& r);

// The result as JSON text: the members of `header_json` (a JSON object's text: the caller's
// settings) first, then "totals", "per_cell" and "per_triangle" (docs/check.md lists the fields).
std::string pvs_check_json(const PvsCheckResult& r, const std::string& header_json);

}  // namespace vislib
