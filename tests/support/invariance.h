// invariance.h: why a from-segment visible set changes when the scene is moved, rotated and
// rescaled (docs/visibility-math.md §6 "Invariance under transformation").
//
// The same segment is computed on scene A and on B = sim(A) (segment mapped by sim, cube
// orientation rotated with the scene, near distance scaled), and every id visible in one set only
// is classified with a double-precision ray oracle in A's coordinates, at the midpoint of every
// final piece (longer than eps_len) of the id in the set where it is visible, or at its witness
// when it is visible through a depth tie only:
//  Grazing: at some evidence ray, the ray passes within `bound` of an edge of the id's triangle or
//    of a triangle in front of it (or tied with it), and no evidence ray shows a defect;
//  DepthTie: at every evidence ray the id is hit away from its edges and lies within
//    kTieBandFactor * eps_z (relative) of the nearest other surface hit away from its edges;
//  Defect: some evidence ray contradicts the set: the id is missed or robustly hidden there while
//    the set shows it, or robustly the first hit there while the other set lacks it.
// "Robustly": hit (or missed) with every edge farther than `bound` from the ray.
//
// The bound (A's units) is kInvarianceUlps * 2^-53 * (max|x_A| + max|x_B| / scale + lambda |d|):
// the rounding of vertices, of the transform and of the pixel direction, each a few ulps of the
// largest coordinate involved. Every evidence ray records the distance it measured in those units
// (ulps_needed), so a caller can see how much of the bound a grazing id used.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/scene.h"
#include "vislib/scene/scene_transform.h"

namespace vislib {

// Multiple of 2^-53 * (coordinate magnitudes) within which a ray grazes an edge (unitless). Errs
// towards "grazing" for rays that close to an edge.
constexpr double kInvarianceUlps = 8;
// A depth tie: depths within this multiple of eps_z (relative) of each other. The kernel's tie test
// samples both ends and the middle of a stretch, the oracle one ray, hence the slack (unitless).
constexpr double kTieBandFactor = 2;
// Evidence rays examined per differing id at most (the longest pieces first).
constexpr size_t kMaxEvidenceRays = 64;

enum class InvarianceClass { Grazing, DepthTie, Defect };
const char* invariance_class_name(InvarianceClass c);

struct InvarianceEvidence {
  uint32_t id = 0;
  bool in_original = false;  // visible in A (and not in B), else in B only
  InvarianceClass cls = InvarianceClass::Defect;
  // The deciding ray: pixel, t, and what it measured.
  int face = 0, x = 0, y = 0;
  double t = 0;
  double piece_length = 0;   // length in t of the id's final piece there (0: a tie's witness)
  double edge_distance = 0;  // nearest relevant edge to the ray, A's units
  double ulps_needed = 0;    // edge_distance / (2^-53 * magnitudes): <= kInvarianceUlps grazes
  double depth_gap = 0;      // |lambda_id - lambda_other| / lambda to the nearest robust surface
  size_t rays = 0;           // evidence rays examined
  std::string why;           // one line
};

struct InvarianceReport {
  size_t visible_a = 0, visible_b = 0;
  std::vector<InvarianceEvidence> diffs;  // in id order
  size_t count(InvarianceClass c) const;
};

// Computes the segment v0 -> v1 on `a` with `options` (orientation, resolution, eps_len, eps_z,
// near) and on `b` = sim(a) (same triangle ids) with the segment mapped by sim, the orientation
// sim.rotation * options.orientation and near * sim.scale, and classifies every differing id.
// Static scenes only. Deterministic.
InvarianceReport classify_invariance(const Scene& a, const Scene& b, const Similarity& sim, Vec3 v0,
                                     Vec3 v1, const SegmentOptions& options);

}  // namespace vislib
