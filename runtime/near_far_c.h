/* near_far_c.h: the consumer side of a PVS in C (docs/runtime.md, "Near-far and CloVR in C"): the
 * near-far partition of a cell's visible set with its continuous morph (near-far paper Eqs. 1-5),
 * dynamic far objects (Eqs. 2-3), and CloVR's progressive near region as a scheduler that an
 * engine drives frame by frame (equal-area rings, ring merging, Alg. 1 injection weights, growth
 * from R_0 = 0). The same mathematics as the C++ functions of runtime/near_far.h, which it calls.
 *
 * Conventions as near_far.h: y up, the cylinders are vertical around the centre O, r is the
 * distance to their axis in the x-z plane, U is the eye. Errors as pvs_runtime_c.h: a status, the
 * message in pvs_rt_last_error(); a bad argument (r1 >= r2, an id or index out of range, the eye
 * outside r1) is PVS_RT_INVALID_ARGUMENT, never an assert. No function keeps a pointer it was given
 * beyond the call, except pvs_rt_clovr_create (the geometry, see there). */
#ifndef PVS_NEAR_FAR_C_H
#define PVS_NEAR_FAR_C_H

#include <stddef.h>
#include <stdint.h>

#include "runtime/pvs_runtime_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The engine's triangles, indexed by PVS triangle id (vislib's id order, pvs_rt_scene_fingerprint).
 * positions: 3 floats per vertex; indices: 3 per triangle, each < vertex_count. triangle_object:
 * object id per triangle (< object_count), needed by CloVR (objects enter the near region whole),
 * may be NULL for the near-far partition. dynamic: one byte per triangle, nonzero if it moves, or
 * NULL for a static scene. */
typedef struct pvs_rt_geometry {
  const float* positions;
  size_t vertex_count;
  const uint32_t* indices;
  size_t triangle_count;
  const uint32_t* triangle_object;
  size_t object_count;
  const uint8_t* dynamic;
} pvs_rt_geometry;

/* w_U between r1 and r2 (x = (r2 - r)/(r2 - r1)): x (Eq. 1), x^2 (Eq. 4), the S-curve (Eq. 5). */
typedef enum pvs_rt_morph_curve {
  PVS_RT_CURVE_LINEAR = 0,
  PVS_RT_CURVE_QUADRATIC = 1,
  PVS_RT_CURVE_SCURVE = 2
} pvs_rt_morph_curve;

/* The default near-far cylinders of a cell (what `pvs view` uses without --near-far): O at the
 * centre of the cell's lookup box, r1 = 1.25 x the half diagonal of the box in x-z (so every eye
 * in the cell is strictly inside r1, as Eq. 1 needs), r2 = 2 r1. */
PVS_RT_API pvs_rt_status pvs_rt_cell_near_far(const pvs_rt* handle, uint32_t cell, double centre[3],
                                              double* r1, double* r2);

/* The partition of a cell's visible triangles (runtime/near_far.h, partition_near_far). Every
 * array is the caller's and must hold `capacity` >= id_count ids (PVS_RT_BUFFER_TOO_SMALL
 * otherwise); the counts are set on success. All lists sorted. */
typedef struct pvs_rt_near_far {
  uint32_t* near_ids;            /* every vertex r <= r1: drawn as is */
  uint32_t* intermediate_ids;    /* the others not all beyond r2: drawn morphed (Eq. 1) */
  uint32_t* far_static_ids;      /* every vertex r >= r2, static: environment map only */
  uint32_t* far_dynamic_ids;     /* every vertex r >= r2, moving: Eq. 2 + Eq. 3 per frame */
  uint32_t* environment_map_ids; /* what the cube map from O renders (static, a vertex beyond r2) */
  uint32_t*
      geometry_ids; /* what is drawn from geometry each frame (near, intermediate, dynamic far) */
  size_t capacity;
  size_t near_count, intermediate_count, far_static_count, far_dynamic_count, environment_map_count,
      geometry_count;
} pvs_rt_near_far;

PVS_RT_API pvs_rt_status pvs_rt_partition_near_far(const pvs_rt_geometry* geometry,
                                                   const uint32_t* ids, size_t id_count,
                                                   const double centre[3], double r1, double r2,
                                                   pvs_rt_near_far* out);

/* w_U of a vertex at axis distance r (1 for r <= r1, 0 for r >= r2). */
PVS_RT_API pvs_rt_status pvs_rt_morph_weight(double r, double r1, double r2,
                                             pvs_rt_morph_curve curve, double* weight);

/* The displaced positions of `count` vertices (3 floats each, in and out may alias): near ones
 * unchanged, intermediate ones by Eq. 1 with the chosen curve, far ones by Eq. 2. The eye must be
 * strictly inside r1. What an engine's vertex shader computes; here for the CPU and for tests. */
PVS_RT_API pvs_rt_status pvs_rt_morph_vertices(const float* in, size_t count, const double eye[3],
                                               const double centre[3], double r1, double r2,
                                               pvs_rt_morph_curve curve, float* out);

/* Eq. 2 for dynamic far vertices: Q = U + P - O (in and out may alias). */
PVS_RT_API pvs_rt_status pvs_rt_displace_far(const float* in, size_t count, const double eye[3],
                                             const double centre[3], float* out);

/* Eq. 3: *passes = 1 iff a fragment at displaced position q, seen from the eye, is not behind the
 * far surface the range cube map from O stores for its direction (near_far.h, RangeCubeMap: 6
 * faces of size x size floats, +X -X +Y -Y +Z -Z). */
PVS_RT_API pvs_rt_status pvs_rt_range_test(const double q[3], const double eye[3],
                                           const float* range, int size, int* passes);

/* ---- CloVR: the progressive near region as a frame-by-frame scheduler ------------------------ */

typedef struct pvs_rt_clovr pvs_rt_clovr;

typedef struct pvs_rt_clovr_params {
  double final_radius; /* > 0: the near region's final radius (e.g. the near-far r2) */
  double ring_area; /* > 0: area of the equal-area rings (CloVR: 314 m^2); <= 0: final area / 8 */
  double min_contribution;  /* merging: a merged ring brings at least this many visible triangles;
                               < 0: their total / the equal-area ring count; 0: no merging */
  uint32_t frames_per_ring; /* >= 1: frames over which each ring is injected */
  double near_fraction;     /* R_n / R of Alg. 1, in (0, 1) (CloVR: 0.7) */
} pvs_rt_clovr_params;

/* Fills params with CloVR's values for a final radius: ring_area = pi final^2 / 8,
 * min_contribution = -1, frames_per_ring = 4, near_fraction = 0.7. */
PVS_RT_API void pvs_rt_clovr_default_params(double final_radius, pvs_rt_clovr_params* params);

/* A scheduler over the engine's geometry (triangle_object required). The geometry's arrays are
 * NOT copied: they must stay valid and unchanged while the scheduler lives. */
PVS_RT_API pvs_rt_status pvs_rt_clovr_create(const pvs_rt_geometry* geometry,
                                             const pvs_rt_clovr_params* params, pvs_rt_clovr** out);
PVS_RT_API void pvs_rt_clovr_destroy(pvs_rt_clovr* scheduler);

/* Starts a growth around centre O for the visible set ids[0..count) (typically on entering a
 * cell; the ids are copied). An object's radius is the smallest axis distance of any vertex of
 * any of its triangles (an object enters the near region with its first vertex, as
 * partition_progressive); its contribution is its number of visible triangles. Builds the
 * equal-area rings up to final_radius and merges them (merge_rings). The next frame is frame 0
 * with R = 0 (R_0 = 0: the whole set comes from the environment map). */
PVS_RT_API pvs_rt_status pvs_rt_clovr_start(pvs_rt_clovr* scheduler, const uint32_t* ids,
                                            size_t count, const double centre[3]);

typedef struct pvs_rt_clovr_frame {
  uint32_t frame;      /* frames since start, 0 first */
  uint32_t ring;       /* merged ring being injected (0-based); ring_count once done */
  uint32_t ring_count; /* merged rings */
  double ring_radius;  /* outer radius of the ring being injected (0 on frame 0) */
  double radius;       /* R of this frame: from the previous ring's radius to ring_radius over
                          frames_per_ring frames (R_0 = 0) */
  double near_radius;  /* R_n = near_fraction * R */
  int near_changed;  /* 1 if the near set differs from the previous frame's (rebuild draw lists) */
  int done;          /* 1 once R reached final_radius (this and later frames are final) */
  size_t near_count; /* visible triangles drawn from geometry (objects with radius < ring_radius) */
  size_t environment_count; /* visible triangles left to the environment map */
} pvs_rt_clovr_frame;

/* Advances to the next frame and describes it. After the last ring the frame stays final (done). */
PVS_RT_API pvs_rt_status pvs_rt_clovr_next_frame(pvs_rt_clovr* scheduler, pvs_rt_clovr_frame* out);

/* The current frame's near triangles and environment-map triangles (sorted; capacity as
 * pvs_rt_visible_ids: *count receives the number, PVS_RT_BUFFER_TOO_SMALL if it exceeds it). */
PVS_RT_API pvs_rt_status pvs_rt_clovr_near_ids(const pvs_rt_clovr* scheduler, uint32_t* out,
                                               size_t capacity, size_t* count);
PVS_RT_API pvs_rt_status pvs_rt_clovr_environment_ids(const pvs_rt_clovr* scheduler, uint32_t* out,
                                                      size_t capacity, size_t* count);

/* The equal-area ring radii, their contributions, and the merged radii of the current growth. */
PVS_RT_API pvs_rt_status pvs_rt_clovr_rings(const pvs_rt_clovr* scheduler, double* equal,
                                            double* contribution, size_t capacity,
                                            size_t* equal_count, double* merged,
                                            size_t merged_capacity, size_t* merged_count);

/* Alg. 1 for the current frame: each vertex at axis distance r >= R_n moves to where the ray from
 * the eye in direction normalize(w d_U + (1 - w) d_O), w = (R - r)/(R - R_n) clamped to [0, 1],
 * leaves the cylinder of radius r (in and out may alias). The eye must be strictly inside R_n
 * (PVS_RT_INVALID_ARGUMENT otherwise, e.g. on frame 0 where R = 0: draw no near geometry then). */
PVS_RT_API pvs_rt_status pvs_rt_clovr_inject_vertices(const pvs_rt_clovr* scheduler,
                                                      const float* in, size_t count,
                                                      const double eye[3], float* out);

/* Alg. 1's weight of the user view for axis distance r, near radius R and R_n (0 <= R_n < R). */
PVS_RT_API pvs_rt_status pvs_rt_injection_weight(double r, double big_r, double r_n,
                                                 double* weight);

#ifdef __cplusplus
}
#endif

#endif /* PVS_NEAR_FAR_C_H */
