// point_visibility.h: from-point visibility with Embree (docs/visibility-math.md §8, "Embree"
// bullet) and the sampled region baselines built on it (docs/visibility-math.md §8, item 3: a union
// of from-point sets is a subset of the from-segment set and tends to it as the number of
// viewpoints grows).
//
// All functions take an already built EmbreeScene (build it once, reuse it for every viewpoint).
// Eyes are world coordinates in double; the scene subtracts its own origin.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "vislib/base/cubemap.h"
#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"

namespace vislib {

// The first-hit cubemap seen from `eye` with orientation R: 6*n*n triangle ids, index
// (face*n + y)*n + x, exactly the convention of cubemap.h (pixel_direction of face_axes(face, R)),
// kNoHit where no triangle is hit at lambda > z_near. Rows go through EmbreeScene::first_hits,
// so a pixel equals scene.first_hit(eye, pixel_direction(...), z_near).tri except on rays through
// a shared edge (see first_hits).
// `n` must be >= 1, `z_near` >= 0, R a rotation. TBB-parallel over rows; each pixel is written by
// exactly one task, so the result is identical whatever the thread count.
std::vector<uint32_t> point_cubemap(const EmbreeScene& scene, Vec3 eye, const Mat3& R, int n,
                                    double z_near);

// Sorted unique triangle ids of a cubemap (kNoHit removed).
std::vector<uint32_t> visible_set(const std::vector<uint32_t>& cubemap);

// visible_set(point_cubemap(...)); with see-through triangles (EmbreeScene::has_see_through), the
// see-through rule instead: each pixel's first opaque hit and every see-through triangle in front
// of it (EmbreeScene::hits_through). point_cubemap itself keeps the first surface of any class.
std::vector<uint32_t> point_visible_set(const EmbreeScene& scene, Vec3 eye, const Mat3& R, int n,
                                        double z_near);

// Options of the sampled baselines.
struct PointSampling {
  int runs = 1;                     // K viewpoints; must be >= 1
  int n = 256;                      // cubemap resolution per face
  double z_near = 0.1;              // near distance (view depth, scene units)
  Mat3 R;                           // orientation used when random_orientation is false
  bool random_orientation = false;  // viewpoint i uses random_orientation(Rng::derive(seed, i))
  uint64_t seed = 1;
};

// The union of the sampled from-point sets and its growth. Entry i of the vectors describes the
// state after runs 0..i: union size and seconds elapsed since the start (wall clock; the only
// non-reproducible field).
struct SampledVisibility {
  std::vector<uint32_t> ids;            // sorted unique union
  std::vector<uint32_t> first_run;      // first_run[j]: the run that first found ids[j]
  std::vector<Vec3> viewpoints;         // viewpoint of run i (world)
  std::vector<size_t> union_size;       // |union| after run i
  std::vector<double> elapsed_seconds;  // after run i
};

// Called after each run with (runs done, runs in all), from the calling thread; may be empty.
using SamplingProgress = std::function<void(size_t done, size_t total)>;

// K viewpoints evenly along v0->v1: t_i = i/(K-1) (both ends included; K = 1 gives t = 0.5).
SampledVisibility sample_segment(const EmbreeScene& scene, Vec3 v0, Vec3 v1,
                                 const PointSampling& opt, const SamplingProgress& progress = {});

// K viewpoints uniformly at random in `box` (must not be empty), drawn in order from
// Rng(opt.seed) (x, y, z per viewpoint). Same seed, same viewpoints and union.
SampledVisibility sample_box(const EmbreeScene& scene, const Box3& box, const PointSampling& opt,
                             const SamplingProgress& progress = {});

}  // namespace vislib
