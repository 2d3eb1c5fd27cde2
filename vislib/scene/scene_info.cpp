#include "vislib/scene/scene_info.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <unordered_set>

namespace vislib {

namespace {

struct BitsHash {
  size_t operator()(const std::array<uint64_t, 3>& k) const {
    uint64_t h = 1469598103934665603ull;
    for (uint64_t x : k) h = (h ^ x) * 1099511628211ull + (h >> 29);
    return size_t(h);
  }
};

std::array<uint64_t, 3> bits_of(Vec3 p) {
  std::array<uint64_t, 3> k;
  for (int i = 0; i < 3; ++i) {
    double d = p[i];
    std::memcpy(&k[i], &d, 8);
  }
  return k;
}

}  // namespace

bool far_from_origin(const Box3& b) {
  if (b.empty()) return false;
  double offset = length((b.min + b.max) * 0.5), diagonal = length(b.max - b.min);
  return offset > kFarFromOriginUnits && offset > kFarFromOriginDiagonals * diagonal;
}

std::string see_through_warning(const Scene& scene, const std::string& name) {
  const size_t see = scene.see_through_triangle_count(), all = scene.triangle_count();
  if (all == 0 || double(see) <= kSeeThroughWarnShare * double(all)) return "";
  constexpr size_t kNamesShown = 4;  // of each kind; the rest are counted
  std::vector<std::string> materials, objects;
  auto add = [](std::vector<std::string>& list, const std::string& n) {
    if (std::find(list.begin(), list.end(), n) == list.end()) list.push_back(n);
  };
  for (const Object& o : scene.objects) {
    if (!o.see_through) continue;
    if (o.alpha_materials.empty()) add(objects, o.name);
    for (const std::string& m : o.alpha_materials) add(materials, m);
  }
  auto listed = [](const std::vector<std::string>& list) {
    std::string t;
    for (size_t i = 0; i < list.size() && i < kNamesShown; ++i)
      t += (i ? ", '" : "'") + list[i] + "'";
    if (list.size() > kNamesShown)
      t += " and " + std::to_string(list.size() - kNamesShown) + " more";
    return t;
  };
  char share[96];
  std::snprintf(share, sizeof share, "%zu of %zu triangles (%.1f%%)", see, all,
                100.0 * double(see) / double(all));
  std::string why;
  if (!materials.empty()) why += "materials " + listed(materials) + " (alpha mode BLEND or MASK)";
  if (!objects.empty()) why += (why.empty() ? "objects " : " and objects ") + listed(objects);
  return name + ": " + share + " are see-through, by " + why +
         ": they hide nothing, so every view cell sees through them; keep the solid ones opaque "
         "with --opaque PATTERNS (object or material names; docs/scene-model.md \"See-through "
         "objects\")";
}

SceneInfo scene_info(const Scene& s) {
  SceneInfo info;
  info.triangles = s.triangle_count();
  info.vertices = s.vertex_count();
  info.objects = s.objects.size();
  for (const Object& o : s.objects) info.see_through_objects += o.see_through ? 1 : 0;
  info.see_through_triangles = s.see_through_triangle_count();
  info.states = s.state_count();
  info.spheres = s.sphere_count();
  info.dynamic = s.is_dynamic();
  info.bbox = s.bounds();
  if (!info.bbox.empty()) info.diagonal = length(info.bbox.max - info.bbox.min);
  if (!info.bbox.empty()) info.origin_offset = length((info.bbox.min + info.bbox.max) * 0.5);
  info.far_from_origin = far_from_origin(info.bbox);
  size_t n = s.vertex_count();
  for (size_t v = 0; v < n; ++v)
    for (const auto& state : s.positions)
      if (v < state.size() && !is_finite(state[v])) {
        ++info.nonfinite_vertices;
        break;
      }
  if (n) {
    std::unordered_set<std::array<uint64_t, 3>, BitsHash> seen;
    seen.reserve(n);
    for (const Vec3& p : s.positions[0])
      if (!seen.insert(bits_of(p)).second) ++info.duplicate_vertices;
  }
  for (const auto& t : s.triangles) {
    bool bad = false;
    for (uint32_t i : t)
      if (i >= n) ++info.out_of_range_indices, bad = true;
    if (bad) continue;
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++info.degenerate_triangles;
      continue;
    }
    const auto& p = s.positions[0];
    Vec3 c = cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]);
    if (c.x == 0 && c.y == 0 && c.z == 0) ++info.degenerate_triangles;
  }
  return info;
}

std::string to_json(const SceneInfo& info, int indent) {
  nlohmann::json j;
  j["triangles"] = info.triangles;
  j["vertices"] = info.vertices;
  j["objects"] = info.objects;
  j["see_through_objects"] = info.see_through_objects;
  j["see_through_triangles"] = info.see_through_triangles;
  j["states"] = info.states;
  j["spheres"] = info.spheres;
  j["dynamic"] = info.dynamic;
  if (info.bbox.empty()) {
    j["bbox"] = nullptr;
  } else {
    j["bbox"] = {{"min", {info.bbox.min.x, info.bbox.min.y, info.bbox.min.z}},
                 {"max", {info.bbox.max.x, info.bbox.max.y, info.bbox.max.z}}};
  }
  j["diagonal"] = info.diagonal;
  j["origin_offset"] = info.origin_offset;
  j["far_from_origin"] = info.far_from_origin;
  j["degenerate_triangles"] = info.degenerate_triangles;
  j["nonfinite_vertices"] = info.nonfinite_vertices;
  j["duplicate_vertices"] = info.duplicate_vertices;
  j["out_of_range_indices"] = info.out_of_range_indices;
  return j.dump(indent);
}

}  // namespace vislib
