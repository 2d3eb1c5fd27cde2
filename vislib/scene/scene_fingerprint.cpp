// scene_fingerprint.cpp: FNV-1a 64 over the documented byte stream of a scene.
#include "vislib/scene/scene_fingerprint.h"

#include <cstring>
#include <string>

#include "pvs_format/pvs_format.h"

namespace vislib {
namespace {

void put_u32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
void put_u64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
void put_f64(std::string& out, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  put_u64(out, bits);
}

}  // namespace

uint64_t scene_fingerprint(const Scene& scene) {
  static const char kTag[] = "vislib-scene-fingerprint-1";
  std::string buf(kTag, sizeof kTag - 1);
  put_u64(buf, scene.positions.size());
  put_u64(buf, scene.vertex_count());
  put_u64(buf, scene.triangle_count());
  put_u64(buf, scene.objects.size());
  uint64_t hash = pvs::fnv1a64(buf.data(), buf.size());
  // Hash in chunks so that a large scene never needs a second copy of itself.
  const size_t kChunk = 1 << 16;
  for (const auto& state : scene.positions) {
    buf.clear();
    for (const Vec3& p : state) {
      put_f64(buf, p.x);
      put_f64(buf, p.y);
      put_f64(buf, p.z);
      if (buf.size() >= kChunk) {
        hash = pvs::fnv1a64(buf.data(), buf.size(), hash);
        buf.clear();
      }
    }
    hash = pvs::fnv1a64(buf.data(), buf.size(), hash);
  }
  buf.clear();
  for (size_t t = 0; t < scene.triangles.size(); ++t) {
    for (uint32_t v : scene.triangles[t]) put_u32(buf, v);
    put_u32(buf, scene.triangle_object[t]);
    if (buf.size() >= kChunk) {
      hash = pvs::fnv1a64(buf.data(), buf.size(), hash);
      buf.clear();
    }
  }
  return pvs::fnv1a64(buf.data(), buf.size(), hash);
}

}  // namespace vislib
