// embree_scene.h: the one RAII wrapper around Embree 3 (house style §7).
//
// An EmbreeScene owns an Embree device and a scene built from the triangles of a vislib::Scene at
// one animation time tau. Embree primitive ids are the vislib triangle ids (one geometry, triangles
// in order). The scene is built with RTC_SCENE_FLAG_ROBUST, build quality high, and
// RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION (used only by first_hit_excluding).
//
// Precision (docs/visibility-math.md §6, §8): Embree works in float. The wrapper stores each vertex
// as float(p - origin) with the subtraction done in double, and every query subtracts the same
// origin from its eye position in double before rounding to float. Choose the origin near the
// eyes (e.g. v0 of a segment): float error then scales with the distance to the eye, not with
// the distance to the world origin.
//
// Rays: the direction is the un-normalised cubemap direction d (F.d = 1), so Embree's hit.t is the
// view depth lambda. A hit counts at lambda in (tnear, inf) as Embree decides it in float.
// Degenerate triangles are passed through; Embree never reports them.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Triangle id of "nothing hit".
constexpr uint32_t kNoHit = std::numeric_limits<uint32_t>::max();

struct Hit {
  uint32_t tri = kNoHit;                                    // triangle id, or kNoHit
  double lambda = std::numeric_limits<double>::infinity();  // depth along d (inf when kNoHit)
};

class EmbreeScene {
 public:
  // Builds the scene from `scene`'s triangles at animation time `tau` in [0,1]
  // (Scene::position_at), relative to `origin` (world coordinates). `device_config` is passed to
  // rtcNewDevice (e.g. "threads=1"; empty = Embree's defaults).
  // Throws std::runtime_error when Embree reports an error (the device error callback is turned
  // into an exception at the end of each wrapper call). The BVH build uses Embree's own
  // TBB-based builder, so it honours an active tbb::global_control.
  EmbreeScene(const Scene& scene, double tau, Vec3 origin, const std::string& device_config = "");
  ~EmbreeScene();
  EmbreeScene(EmbreeScene&&) noexcept;
  EmbreeScene& operator=(EmbreeScene&&) noexcept;
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  Vec3 origin() const;
  size_t triangle_count() const;

  // Nearest triangle hit by the ray eye_world + lambda*dir with lambda > tnear (float decision),
  // and its lambda; Hit{} when nothing. `dir` must be finite and non-zero; `tnear` >= 0.
  // Thread-safe (const queries may run concurrently); deterministic for a given built scene.
  Hit first_hit(Vec3 eye_world, Vec3 dir, double tnear) const;

  // As first_hit, but triangle `exclude_tri` is ignored (an intersect-context filter function):
  // the next-nearest other surface along the ray. Thread-safe.
  Hit first_hit_excluding(Vec3 eye_world, Vec3 dir, double tnear, uint32_t exclude_tri) const;

  // Batch form of first_hit for `count` rays from one eye (e.g. one cubemap row), through Embree's
  // coherent ray stream (rtcIntersect1M; about 4x faster than single rays on a cubemap row).
  // out[i] equals first_hit(eye_world, dirs[i], tnear) except on numerically marginal rays: the
  // stream's packet kernels may pick the other triangle when the ray passes through a shared
  // edge (measured: 2 of 3.1M rays on a 270k-triangle box city, both flagged by
  // RayOracle::is_ambiguous). `dirs` and `out` must hold `count` elements. Thread-safe;
  // deterministic (the result does not depend on which thread runs the call).
  void first_hits(Vec3 eye_world, const Vec3* dirs, size_t count, double tnear, Hit* out) const;

  // As first_hits, but only triangles t with allowed[t] != 0 can be hit: an intersect-context
  // filter on the same BVH and the same ray stream, so the answer is first_hits restricted to the
  // allowed triangles (a ray whose first hit is allowed gets exactly that hit, lambda included).
  // `allowed` must hold triangle_count() bytes, or be null (then identical to first_hits).
  // Thread-safe; deterministic.
  void first_hits_among(Vec3 eye_world, const Vec3* dirs, size_t count, double tnear,
                        const uint8_t* allowed, Hit* out) const;

  // As first_hits_among, but ray i starts at eyes_world[i] (e.g. the eyes of an ODS row, one per
  // column, vislib/render/ods_render.h). Each origin is made relative to origin() in double
  // before rounding to float. `eyes_world`, `dirs` and `out` must hold `count` elements.
  // Thread-safe; deterministic.
  void first_hits_from(const Vec3* eyes_world, const Vec3* dirs, size_t count, double tnear,
                       const uint8_t* allowed, Hit* out) const;

  // True when the scene was built with a see-through object (Object::see_through). The queries
  // above ignore the class: they return the first surface, see-through or not.
  bool has_see_through() const;

  // The see-through rule (docs/visibility.md "See-through triangles") for `count` rays from
  // one eye: out[i] is ray i's first opaque hit (see-through triangles are passed through by an
  // intersect filter), and `passed` gets the id of every see-through triangle a ray hits at
  // lambda > tnear no farther than its first opaque hit (as Embree decides it in float; a tie
  // counts), in no particular order and possibly more than once. Thread-safe; deterministic.
  void hits_through(Vec3 eye_world, const Vec3* dirs, size_t count, double tnear, Hit* out,
                    std::vector<uint32_t>& passed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vislib
