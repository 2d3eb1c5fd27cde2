// vis_compare.h: our visible sets of a Quake map's BSP leaves held against the map's own (its
// compiler's `vis` stage, quake_bsp.h), for `pvs vis-compare` (docs/quake.md "Comparing with the
// map's vis").
//
// For each cell (one BSP leaf A of model 0): ours = the cell's set, theirs = the triangles the
// engine draws from A (bsp_leaf_drawn_triangles). Degenerate triangles (zero area in double: never
// visible) are left out of both sides, and triangles of faces in no leaf's marksurfaces (the engine
// never draws them) are counted apart as "never drawn". The rest of ours \ theirs are the extras:
// each is searched for a witness, an eye in A's view region (bsp_leaf_view_region) and a ray whose
// double-precision re-cast (ray_reference.h) sees the triangle: "confirmed" (their vis misses a
// visible triangle). An extra whose every seeing ray also crosses a triangle of theirs at the same
// depth (within eps_z: the coincident twin of a sky or liquid boundary, which they draw) is
// "coincident": no error of either side. The rest are "unconfirmed" (no witness found: ours
// possibly wrong).
//
// Kernel witnesses: the ray search samples eyes and aim points, and can miss a triangle seen only
// through a narrow gap. When options.kernel_witnesses is set, the extras a cell leaves unconfirmed
// are handed to it, which re-runs the cell's from-segment runs as the bake made them and returns
// the kernel's own witness rays (an eye on a segment, the witness pixel's direction). Each is
// re-cast under the seeing rule below: seen, with no triangle of theirs at its depth, it is
// confirmed (source "kernel"); seen with one, coincident. Not seen, but crossed within
// kReferenceBarycentric of its edges with nothing opaque in front of it by more than eps_z, it is
// a **tie**: the pixel ray runs through the triangle's edge (typically a corner where it meets
// the surface in front at the same depth), where the re-cast cannot decide and the kernel's tie
// rules do (docs/visibility-math.md §2.5 on-edge ties, §7 depth ties: both surfaces visible);
// neither an error of ours nor a miss of theirs. Otherwise a **false witness**: the kernel called
// the triangle visible where the double-precision reference sees it hidden or missed, an error of
// ours. An extra the re-run does not see at all stays unconfirmed.
//
// The seeing rule (both the witness and the sampling): along a ray, triangle T is seen when the
// ray crosses T at lambda > z_near, farther than kReferenceBarycentric inside its edges, and no
// opaque triangle is crossed (its edges widened by kReferenceBarycentric) in front of T by more
// than eps_z * lambda_T (the kernel's CoplanarRule::Both, tolerances.h). So both faces of a
// coincident coplanar pair (a sky or liquid boundary carries one face turned to each side) are
// seen, and see-through triangles (liquids imported see-through) never hide anything.
//
// Sampled ground truth (the sampler of pvs_check.h, sample_eye, shared with `pvs check`):
// `samples` random eyes in each region, a first-hit cubemap of N x N faces from each (Embree;
// see-through triangles passed through as the kernel's rule says), and every triangle hit must be
// in ours and in theirs. A hit x missing from a set S is re-cast: it is a
// miss of S when the double-precision ray sees x and crosses no triangle of S (edges widened by
// kReferenceBarycentric) within eps_z * lambda_x of x: a hit on either of two coincident faces, or
// on a shared edge, counts for a set holding either. A hit whose re-cast does not see x is
// counted as ambiguous, never as a miss.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vislib/base/tolerances.h"
#include "vislib/base/vec.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/scene.h"

namespace vislib {

// A witness of an extra: the eye, the direction of the ray from it, the triangle seen.
struct VisWitness {
  uint32_t tri = 0;
  Vec3 eye, dir;             // scene coordinates
  bool from_kernel = false;  // a kernel witness (file comment), not one of the ray search
};

struct VisCompareOptions {
  int witness_eyes = 16;    // eyes tried per extra (the region's corners first, then random); >= 1
  int witness_targets = 8;  // points of the extra aimed at from each eye (centroid first); >= 1
  int samples = 4;          // sampled eyes per leaf (0: no sampling)
  int resolution = 64;      // sampled cubemaps: N x N pixels per face; >= 1
  double z_near = kDefaultNear;  // near distance of every ray (scene units); > 0
  double eps_z = kDefaultEpsZ;   // depth tie tolerance, relative (the bake's)
  uint64_t seed = 1;             // eyes of the witness search and of the sampling
  // Kernel witnesses (file comment): called with a cell and its extras left unconfirmed by the ray
  // search (sorted), from a worker thread (several cells at once), returns witness rays (scene
  // coordinates, unit directions, from_kernel set) for those the cell's runs see. Empty: no
  // re-run.
  std::function<std::vector<VisWitness>(uint32_t cell, const std::vector<uint32_t>& extras)>
      kernel_witnesses;
};

struct VisCompareLeaf {
  uint32_t cell = 0, leaf = 0;
  int32_t contents = 0;
  size_t ours = 0, theirs = 0, common = 0;  // non-degenerate triangles, never-drawn ones left out
  size_t never_drawn = 0;                   // ours on faces in no marksurfaces
  std::vector<VisWitness> confirmed;        // extras with a witness, increasing id
  std::vector<uint32_t> unconfirmed;        // extras without one, increasing
  std::vector<uint32_t> coincident;  // extras seen only where theirs has a face at the same depth
                                     // (a coincident twin they draw), increasing
  std::vector<uint32_t> lacks;       // theirs \ ours, increasing
  // Kernel witnesses that the re-cast does not see (our errors), increasing id.
  std::vector<VisWitness> false_witnesses;
  // Kernel witnesses seen only at a tie (file comment), increasing id.
  std::vector<VisWitness> tie_witnesses;
  bool kernel_rerun = false;  // the cell's runs were re-run for kernel witnesses
  double inset = 0;           // of the view region (Quake units)
  // Sampling.
  uint64_t rays = 0, no_hit = 0, ambiguous = 0;
  uint64_t our_misses = 0, their_misses = 0;  // rays (pixels)
  uint64_t their_never_drawn = 0;  // rays whose seen hit is a never-drawn face (not their misses)
  std::vector<uint32_t> our_missed, their_missed;  // the triangles missed, increasing
  // ours / theirs (1 when both are empty, infinity when only theirs is).
  double tightness() const;
};

struct VisCompareResult {
  std::vector<VisCompareLeaf> leaves;  // in cell order
  size_t degenerate_triangles = 0;     // of the scene, left out everywhere
  size_t never_drawn_faces = 0;        // imported faces in no leaf's marksurfaces
  size_t never_drawn_triangles = 0;    // their non-degenerate triangles
};

// Compares ours[c] (the set of cell c: sorted triangle ids of `scene`) for every cell c, whose
// leaf is cell_leaf[c], with the map's own sets. `scene` must be `bsp` imported with the options
// that gave `faces` (bsp_face_triangles); every cell_leaf must be a leaf of model 0 reached from
// its head node. `progress(done, total)` is called from the calling thread after each cell if
// given. TBB-parallel over cells; the result does not depend on the thread count (each cell's
// random streams are Rng::derive(seed, cell)).
VisCompareResult vis_compare(const QuakeBsp& bsp, const Scene& scene,
                             const std::vector<BspFaceTriangles>& faces,
                             const std::vector<uint32_t>& cell_leaf,
                             const std::vector<std::vector<uint32_t>>& ours,
                             const VisCompareOptions& options,
                             const std::function<void(size_t, size_t)>& progress = {});

// Median of the leaves' tightness (finite values only; 0 when none), and their mean.
double median_tightness(const VisCompareResult& r);
double mean_tightness(const VisCompareResult& r);

// The result as JSON text: totals and one row per leaf (docs/quake.md lists the fields).
std::string vis_compare_json(const VisCompareResult& r);

}  // namespace vislib
