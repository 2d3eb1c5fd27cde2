// near_far_render.h: a CPU reference renderer of the near-far frame and
// the metrics that compare it with the full-scene frame.
//
// Papers (../shared/papers/): near-far-partitioning.txt §3 (the near, intermediate and far regions
// around two vertical cylinders of radii r1 < r2 about a centre O; Eq. 1 morph) and
// clovr-progressive-near-region.txt §3 (progressive near region, Alg. 1 injection, OVC/OFC).
// The pure functions (regions, Eq. 1, Alg. 1, ring radii) come from runtime/near_far.h.
//
// The near-far frame, per output pixel (a ray tracer, not a rasteriser):
//  1. Geometry: the visible triangles with every vertex within r1 of O's axis (near) are used as
//     they are; the triangles with some vertex inside r2 and some beyond r1 (intermediate) get each
//     vertex displaced by pvs_runtime::morph_vertex (Eq. 1; vertices beyond r2 take Eq. 2's
//     U + P - O, its w_U = 0 end), or, with morph off, stay where they are (the comparison
//     `pvs view` reports). These triangles are put into one Embree scene and the eye ray is cast
//     against it exactly as render_frame does (same camera, shading and depth).
//  2. Environment map: the visible triangles with a vertex at or beyond r2 (far, plus the
//     intermediate ones crossing r2: the paper's SF bin) are rendered once from O into a cube map
//     (vislib/base/cubemap.h convention, identity orientation, `env_size` pixels a side): per pixel
//     the first such triangle along the pixel-centre ray from O, its colour (render_frame's shading
//     with the ray from O as the headlight) and its range from O.
//  3. Compose: where the eye ray hits geometry, the pixel is that hit; where it misses, the
//     environment map is looked up (nearest pixel, pvs_runtime::cube_pixel):
//      - EnvironmentLookup::EyeDirection (the paper, and the default): along the eye ray's own
//        direction ("each output frame is initialized from the cube map"). A far point P then
//        appears from U in the direction O sees it, as Eq. 2 displaces dynamic far vertices, and
//        a vertex on r2 morphed by Eq. 1 lands exactly where the map shows it. The pixel's depth
//        is the map's range (the range of the displaced point U + range * dir).
//      - EnvironmentLookup::CylinderR2: the eye ray is intersected with the cylinder of radius r2
//        about O's axis (U is inside it) and the map is looked up in the direction from O of that
//        point. A far point on the cylinder then lands at its true pixel; the depth is
//        |O + range * dir - U|. This does not match the Eq. 1 morph at r2 (which follows the
//        paper's lookup), so it is offered for comparison only.
//     Geometry is drawn over the map.
//  4. Dynamic far triangles (settings.dynamic marks the moving triangles; a moving triangle with
//     every vertex at or beyond r2): never put into the environment map; drawn per frame from the
//     eye with every vertex displaced by Eq. 2 (pvs_runtime::displace_far, Q = U + P - O, with or
//     without the morph), and each such fragment (the eye ray's first hit among them, at
//     q = U + depth * dir) kept only if it passes Eq. 3 (pvs_runtime::passes_range_test against
//     the map's range from O) and is nearer than the geometry of step 1. A moving triangle that
//     crosses r2 stays intermediate (morphed, not tested by Eq. 3), as in
//     pvs_runtime::partition_near_far, which makes the partition.
//  The output Frame's tri holds scene triangle ids (from geometry or from the map), kNoHit where
//  both miss; rgb and depth as above.
//
// Everything is deterministic and independent of the thread count (render_frame's guarantees;
// the environment map and the composition write one slot per pixel).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene.h"

namespace vislib {

enum class EnvironmentLookup : uint8_t { EyeDirection = 0, CylinderR2 = 1 };

struct NearFarSettings {
  Vec3 centre;              // O, on the cylinders' (vertical) axis; the environment map's viewpoint
  double r1 = 10, r2 = 20;  // scene units; 0 <= r1 < r2
  bool morph = true;        // false: intermediate triangles drawn where they are (no Eq. 1)
  int env_size = 512;       // environment map face side, pixels, >= 1
  EnvironmentLookup lookup = EnvironmentLookup::EyeDirection;
  // One byte per scene triangle, nonzero = the triangle moves (moving_triangles), or null for a
  // static scene. Not owned.
  const uint8_t* dynamic = nullptr;
};

// Visible triangles per region (near: all vertices within r1 of the axis; far: all at or beyond
// r2; intermediate: the rest). env_map counts what goes into the environment map (far plus the
// intermediate triangles with a vertex at or beyond r2).
// far_dynamic: the far triangles that move (included in far, drawn per frame by Eq. 2 and Eq. 3,
// not in env_map); far_dynamic_shown: how many of them show in at least one pixel of the frame.
struct RegionCounts {
  size_t near = 0, intermediate = 0, far = 0, env_map = 0, far_dynamic = 0, far_dynamic_shown = 0;
};

// A single-state copy of `scene` at animation time tau in [0,1]: vertex v at
// scene.position_at(v, tau), sphere s at scene.sphere_center_at(s, tau); triangles, objects and
// radii unchanged. Render a dynamic scene at tau through this copy (render_frame and
// render_near_far shade with key state 0).
Scene scene_at(const Scene& scene, double tau);

// One byte per triangle of `scene`: 1 where some vertex of the triangle differs between key
// states (the triangle moves), else 0. All 0 for a single-state scene.
std::vector<uint8_t> moving_triangles(const Scene& scene);

// The environment cube map rendered from O: 6 faces of size x size, index (face*size + y)*size + x.
struct EnvironmentMap {
  int size = 0;
  Vec3 centre;
  std::vector<uint8_t> rgb;   // 3 bytes per pixel; kRenderBackground where nothing is hit
  std::vector<float> range;   // |hit - O|; +inf where nothing is hit
  std::vector<uint32_t> tri;  // scene triangle id, or kNoHit
};

// Renders the triangles t with allowed[t] != 0 (scene.triangle_count() bytes) from `centre` into
// a cube map of `size` pixels a side. `rt` must be built from `scene` at tau = 0. Thread-safe.
EnvironmentMap render_environment_map(const Scene& scene, const EmbreeScene& rt, Vec3 centre,
                                      int size, const uint8_t* allowed);

// Where each pixel of a near-far frame comes from, and the scene point it stands for (for the
// discontinuity metric delta, vislib/eval/discontinuity.h, and for epsilon per source):
//  - Geometry: a near triangle, or an intermediate one with the morph off, drawn where it is; the
//    point is the eye ray's hit;
//  - MorphedGeometry: an intermediate triangle drawn displaced by Eq. 1 (morph on); the point is
//    the hit carried back to the undisplaced triangle (same barycentric coordinates on the
//    rest-pose corners), i.e. the scene point before the morph;
//  - EnvironmentMap: looked up in the map; the point is O + range * (lookup direction), the scene
//    point the map shows in that direction (its range from the nearest map pixel);
//  - DynamicFar: a moving far triangle drawn by Eq. 2; the point is the hit minus the Eq. 2
//    displacement (U - O), i.e. the triangle's true position;
//  - None: background; the point is NaN.
enum class PixelSource : uint8_t {
  None = 0,
  Geometry = 1,
  MorphedGeometry = 2,
  EnvironmentMap = 3,
  DynamicFar = 4
};
struct PixelSources {
  std::vector<PixelSource> source;  // per pixel, row-major
  std::vector<Vec3> point;          // per pixel, world coordinates; NaN for None
};

// The near-far frame of the visible triangles `visible` (sorted unique ids < triangle_count())
// seen by `camera`, as described above. `rt` must be built from `scene` at tau = 0 (it renders the
// environment map). camera.eye must be strictly inside r1 of O's axis (the user is in the near
// region). `counts`, if not null, receives the region counts; `sources`, if not null, each pixel's
// source and scene point (above).
Frame render_near_far(const Scene& scene, const EmbreeScene& rt,
                      const std::vector<uint32_t>& visible, const Camera& camera,
                      const NearFarSettings& settings, RegionCounts* counts = nullptr,
                      PixelSources* sources = nullptr);

// The CloVR frame while ring `ring_radius` is injected with the near region at radius big_r
// (object level, CloVR §3, Alg. 1): the triangles (of `visible`) of every object with a visible
// vertex within ring_radius of O's axis (the geometry received so far) are drawn from geometry
// with their vertices displaced by pvs_runtime::inject_vertex (Alg. 1 at R = big_r,
// R_n = near_fraction * big_r: a vertex beyond big_r is drawn where the map showed it); the other
// visible triangles form this ring's environment map, looked up along the eye ray. Animating
// big_r from the previous ring's radius up to ring_radius gives the in-between frames of the
// injection; big_r = ring_radius is the ring's final frame.
// camera.eye's axis distance must be < near_fraction * big_r; 0 < near_fraction < 1;
// 0 < big_r <= ring_radius.
Frame render_progressive(const Scene& scene, const EmbreeScene& rt,
                         const std::vector<uint32_t>& visible, const Camera& camera, Vec3 centre,
                         double big_r, double near_fraction, int env_size, double ring_radius);

// The CloVR per-ring contribution for merging (pvs_runtime::merge_rings): for each ring
// [radii[k-1], radii[k]) of the equal-area sequence `radii`, the number of triangles of `visible`
// whose objects enter the near region in that ring (an object enters with its first visible vertex,
// as in render_progressive), i.e. the visible triangles that change from environment map to
// geometry in that ring. Objects entering at or beyond the last radius are not counted.
std::vector<double> ring_visible_triangle_contribution(const Scene& scene,
                                                       const std::vector<uint32_t>& visible,
                                                       Vec3 centre,
                                                       const std::vector<double>& radii);

// CloVR's completion metrics of `test` against `truth` (same size; tri ids of the same scene):
//  - OVC, object visualization completion: the share of objects with at least one pixel in
//    `truth` that have at least one pixel anywhere in `test`;
//  - object_pixel_agreement: per object of `truth`, the share of its truth pixels at which `test`
//    shows the same object, averaged uniformly over those objects (not CloVR's OFC: per-pixel
//    agreement, unweighted by footprint);
//  - ofc_eq2, CloVR's own OFC (its Eq. 2): sum over the objects of truth of min(F*(o), F(o)) over
//    the sum of F(o), F(o) / F*(o) the object's pixel counts in truth / test, wherever they are
//    (footprints, not per-pixel agreement; capped so that an object grown by a missing occluder
//    does not count more than its truth footprint), i.e. weighted by footprint.
// All are 1 when `truth` shows no object.
struct ObjectCompletion {
  size_t objects = 0;  // objects with a pixel in truth
  double ovc = 1, object_pixel_agreement = 1, ofc_eq2 = 1;
};
ObjectCompletion object_completion(const Scene& scene, const Frame& truth, const Frame& test);

}  // namespace vislib
