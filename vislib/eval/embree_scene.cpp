// embree_scene.cpp: the Embree 3 wrapper (house style §7; docs/visibility-math.md §8, "Embree"
// bullet).
#include "vislib/eval/embree_scene.h"

#include <embree3/rtcore.h>

#include <atomic>
#include <cassert>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace vislib {

struct EmbreeScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  Vec3 origin;
  size_t triangle_count = 0;
  std::vector<uint8_t> see_through;  // per triangle (empty: none is)
  // Filled by the device error callback (which may run on any thread); raised as an exception by
  // check() on the calling thread, never thrown through Embree's C interface.
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::string message;

  static void on_error(void* user, RTCError code, const char* str) {
    auto* self = static_cast<Impl*>(user);
    std::lock_guard<std::mutex> lock(self->mutex);
    if (self->message.empty())
      self->message = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
    self->failed.store(true, std::memory_order_release);
  }
  void check() {
    if (!failed.load(std::memory_order_acquire)) return;
    std::lock_guard<std::mutex> lock(mutex);
    throw std::runtime_error(message);
  }
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// An intersect context carrying the triangle to ignore (the context is the first member, so the
// filter function can recover the whole struct from args->context).
struct ExcludeContext {
  RTCIntersectContext base;
  uint32_t exclude;
};

// An intersect context carrying a per-triangle mask of the triangles that may be hit.
struct AllowContext {
  RTCIntersectContext base;
  const uint8_t* allowed;
};

void allow_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const AllowContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    if (!ctx->allowed[RTCHitN_primID(args->hit, args->N, i)]) args->valid[i] = 0;
  }
}

void exclude_filter(const RTCFilterFunctionNArguments* args) {
  const auto* ctx = reinterpret_cast<const ExcludeContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    if (RTCHitN_primID(args->hit, args->N, i) == ctx->exclude) args->valid[i] = 0;
  }
}

// An intersect context for hits_through: the see-through triangles (passed through) and the
// candidate hits on them (ray index, triangle, hit distance).
struct ThroughContext {
  RTCIntersectContext base;
  const uint8_t* see_through;
  struct Passed {
    unsigned ray;
    uint32_t tri;
    float t;
  };
  std::vector<Passed> passed;
};

// Embree calls it for every candidate hit no farther than the ray's current tfar, with tfar set
// to the candidate's distance: a see-through candidate is recorded and rejected, so the traversal
// goes on to the first opaque hit, and every see-through hit in front of that one is recorded.
void through_filter(const RTCFilterFunctionNArguments* args) {
  auto* ctx = reinterpret_cast<ThroughContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t tri = RTCHitN_primID(args->hit, args->N, i);
    if (!ctx->see_through[tri]) continue;
    ctx->passed.push_back(
        {RTCRayN_id(args->ray, args->N, i), tri, RTCRayN_tfar(args->ray, args->N, i)});
    args->valid[i] = 0;
  }
}

RTCRayHit make_ray(Vec3 org, Vec3 dir, double tnear) {
  RTCRayHit rh;
  rh.ray.org_x = float(org.x);
  rh.ray.org_y = float(org.y);
  rh.ray.org_z = float(org.z);
  rh.ray.dir_x = float(dir.x);
  rh.ray.dir_y = float(dir.y);
  rh.ray.dir_z = float(dir.z);
  rh.ray.tnear = float(tnear);
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

Hit to_hit(const RTCRayHit& rh) {
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  return {rh.hit.primID, double(rh.ray.tfar)};
}

}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene, double tau, Vec3 origin,
                         const std::string& device_config)
    : impl_(std::make_unique<Impl>()) {
  assert(tau >= 0.0 && tau <= 1.0);
  Impl& im = *impl_;
  im.origin = origin;
  im.triangle_count = scene.triangle_count();
  if (scene.has_see_through()) {
    im.see_through.resize(scene.triangle_count());
    for (size_t t = 0; t < scene.triangle_count(); ++t)
      im.see_through[t] = scene.triangle_see_through(uint32_t(t)) ? 1 : 0;
  }
  im.device = rtcNewDevice(device_config.empty() ? nullptr : device_config.c_str());
  if (!im.device)
    throw std::runtime_error("Embree: rtcNewDevice failed (error " +
                             std::to_string(int(rtcGetDeviceError(nullptr))) + ", config \"" +
                             device_config + "\")");
  rtcSetDeviceErrorFunction(im.device, &Impl::on_error, &im);
  im.scene = rtcNewScene(im.device);
  rtcSetSceneFlags(im.scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_HIGH);
  im.check();

  const size_t nv = scene.vertex_count(), nt = scene.triangle_count();
  if (nt > 0) {
    RTCGeometry geom = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
    if (!v || !idx) {
      rtcReleaseGeometry(geom);
      im.check();
      throw std::runtime_error("Embree: buffer allocation failed");
    }
    const bool single_state = scene.positions.size() == 1;
    for (size_t i = 0; i < nv; ++i) {
      Vec3 p = single_state ? scene.positions[0][i] : scene.position_at(uint32_t(i), tau);
      Vec3 q = p - origin;  // in double, then rounded once
      v[3 * i + 0] = float(q.x);
      v[3 * i + 1] = float(q.y);
      v[3 * i + 2] = float(q.z);
    }
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) idx[3 * t + k] = scene.triangles[t][k];
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(im.scene, geom, 0);  // geomID 0; primID = triangle id
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(im.scene);
  im.check();
}

EmbreeScene::~EmbreeScene() = default;
EmbreeScene::EmbreeScene(EmbreeScene&&) noexcept = default;
EmbreeScene& EmbreeScene::operator=(EmbreeScene&&) noexcept = default;

Vec3 EmbreeScene::origin() const {
  return impl_->origin;
}
size_t EmbreeScene::triangle_count() const {
  return impl_->triangle_count;
}

Hit EmbreeScene::first_hit(Vec3 eye_world, Vec3 dir, double tnear) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh = make_ray(eye_world - impl_->origin, dir, tnear);
  rtcIntersect1(impl_->scene, &ctx, &rh);
  impl_->check();
  return to_hit(rh);
}

Hit EmbreeScene::first_hit_excluding(Vec3 eye_world, Vec3 dir, double tnear,
                                     uint32_t exclude_tri) const {
  ExcludeContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.base.filter = &exclude_filter;
  ctx.exclude = exclude_tri;
  RTCRayHit rh = make_ray(eye_world - impl_->origin, dir, tnear);
  rtcIntersect1(impl_->scene, &ctx.base, &rh);
  impl_->check();
  return to_hit(rh);
}

void EmbreeScene::first_hits(Vec3 eye_world, const Vec3* dirs, size_t count, double tnear,
                             Hit* out) const {
  first_hits_among(eye_world, dirs, count, tnear, nullptr, out);
}

void EmbreeScene::first_hits_among(Vec3 eye_world, const Vec3* dirs, size_t count, double tnear,
                                   const uint8_t* allowed, Hit* out) const {
  AllowContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  ctx.base.filter = allowed ? &allow_filter : nullptr;
  ctx.allowed = allowed;
  const Vec3 org = eye_world - impl_->origin;
  std::vector<RTCRayHit> rays(count);
  for (size_t i = 0; i < count; ++i) rays[i] = make_ray(org, dirs[i], tnear);
  rtcIntersect1M(impl_->scene, &ctx.base, rays.data(), unsigned(count), sizeof(RTCRayHit));
  for (size_t i = 0; i < count; ++i) out[i] = to_hit(rays[i]);
  impl_->check();
}

void EmbreeScene::first_hits_from(const Vec3* eyes_world, const Vec3* dirs, size_t count,
                                  double tnear, const uint8_t* allowed, Hit* out) const {
  AllowContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  ctx.base.filter = allowed ? &allow_filter : nullptr;
  ctx.allowed = allowed;
  std::vector<RTCRayHit> rays(count);
  for (size_t i = 0; i < count; ++i)
    rays[i] = make_ray(eyes_world[i] - impl_->origin, dirs[i], tnear);
  rtcIntersect1M(impl_->scene, &ctx.base, rays.data(), unsigned(count), sizeof(RTCRayHit));
  for (size_t i = 0; i < count; ++i) out[i] = to_hit(rays[i]);
  impl_->check();
}

bool EmbreeScene::has_see_through() const {
  return !impl_->see_through.empty();
}

void EmbreeScene::hits_through(Vec3 eye_world, const Vec3* dirs, size_t count, double tnear,
                               Hit* out, std::vector<uint32_t>& passed) const {
  if (impl_->see_through.empty()) {  // nothing to pass through
    first_hits(eye_world, dirs, count, tnear, out);
    return;
  }
  ThroughContext ctx;
  rtcInitIntersectContext(&ctx.base);
  ctx.base.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  ctx.base.filter = &through_filter;
  ctx.see_through = impl_->see_through.data();
  const Vec3 org = eye_world - impl_->origin;
  std::vector<RTCRayHit> rays(count);
  for (size_t i = 0; i < count; ++i) {
    rays[i] = make_ray(org, dirs[i], tnear);
    rays[i].ray.id = unsigned(i);
  }
  rtcIntersect1M(impl_->scene, &ctx.base, rays.data(), unsigned(count), sizeof(RTCRayHit));
  for (size_t i = 0; i < count; ++i) out[i] = to_hit(rays[i]);
  for (const ThroughContext::Passed& p : ctx.passed)
    if (p.t <= rays[p.ray].ray.tfar) passed.push_back(p.tri);
  impl_->check();
}

}  // namespace vislib
