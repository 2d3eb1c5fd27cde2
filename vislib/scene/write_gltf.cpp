// write_gltf.cpp: GLB writer (glTF 2.0 spec, section 4.4 "Binary glTF layout"). Writes the bytes
// directly (JSON chunk + BIN chunk) so that a scene of tens of millions of triangles is copied
// into the output once; the JSON is built with nlohmann::ordered_json for a stable key order.
#include "vislib/scene/write_gltf.h"

#include <cassert>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace vislib {

namespace {

using Json = nlohmann::ordered_json;

constexpr uint32_t kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr uint32_t kFloat = 5126, kUnsignedInt = 5125;

// Triangles of one object, re-indexed over the vertices it uses.
struct ObjectMesh {
  std::vector<uint32_t> indices;   // local vertex ids, 3 per triangle
  std::vector<uint32_t> vertices;  // local -> scene vertex id
  bool dynamic = false;
};

struct MinMax {
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {-std::numeric_limits<float>::max(), -std::numeric_limits<float>::max(),
                 -std::numeric_limits<float>::max()};
  void extend(const float* v) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = v[i] < lo[i] ? v[i] : lo[i];
      hi[i] = v[i] > hi[i] ? v[i] : hi[i];
    }
  }
};

// Float position of vertex `v` in state `k`, as a displacement from state 0 when `k` > 0.
void vertex_float(const Scene& s, uint32_t v, size_t k, float out[3]) {
  Vec3 p = k == 0 ? s.positions[0][v] : s.positions[k][v] - s.positions[0][v];
  out[0] = float(p.x);
  out[1] = float(p.y);
  out[2] = float(p.z);
}

Json vec3_json(const float* v) {
  return Json::array({double(v[0]), double(v[1]), double(v[2])});
}

}  // namespace

std::string scene_to_glb(const Scene& scene) {
  const size_t K = scene.positions.size() ? scene.positions.size() : 1;
  const size_t nobj = scene.objects.size();
  assert(scene.triangle_object.size() == scene.triangles.size());

  // Bucket triangles by object (stable: id order within an object), then re-index.
  std::vector<ObjectMesh> meshes(nobj);
  {
    std::vector<size_t> count(nobj, 0);
    for (uint32_t o : scene.triangle_object) {
      assert(o < nobj);
      ++count[o];
    }
    for (size_t o = 0; o < nobj; ++o) meshes[o].indices.reserve(3 * count[o]);
    std::vector<uint32_t> local(scene.vertex_count(), UINT32_MAX);
    std::vector<uint32_t> touched;
    std::vector<size_t> order;  // triangle ids grouped by object
    order.reserve(scene.triangles.size());
    std::vector<size_t> start(nobj + 1, 0);
    for (size_t o = 0; o < nobj; ++o) start[o + 1] = start[o] + count[o];
    order.resize(scene.triangles.size());
    std::vector<size_t> fill(start.begin(), start.end() - 1);
    for (size_t t = 0; t < scene.triangles.size(); ++t) order[fill[scene.triangle_object[t]]++] = t;
    for (size_t o = 0; o < nobj; ++o) {
      ObjectMesh& m = meshes[o];
      for (size_t i = start[o]; i < start[o + 1]; ++i)
        for (uint32_t v : scene.triangles[order[i]]) {
          assert(v < scene.vertex_count());
          if (local[v] == UINT32_MAX) {
            local[v] = uint32_t(m.vertices.size());
            m.vertices.push_back(v);
          }
          m.indices.push_back(local[v]);
        }
      for (uint32_t v : m.vertices) {
        local[v] = UINT32_MAX;
        for (size_t k = 1; k < K && !m.dynamic; ++k)
          if (scene.positions[k][v] != scene.positions[0][v]) m.dynamic = true;
      }
    }
  }

  // JSON and the BIN layout: per object indices, positions, then K-1 targets if dynamic; then the
  // animation's time and weight keyframes.
  Json j;
  j["asset"] = {{"version", "2.0"}, {"generator", "vislib scene_to_glb"}};
  j["scene"] = 0;
  Json nodes = Json::array(), meshes_json = Json::array(), views = Json::array(),
       accessors = Json::array(), channels = Json::array(), samplers = Json::array();
  uint64_t offset = 0;
  auto add_view = [&](uint64_t bytes, uint32_t target) {
    Json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    views.push_back(v);
    offset += bytes;
    return views.size() - 1;
  };
  auto add_accessor = [&](size_t view, uint32_t type, size_t count, const char* kind) {
    accessors.push_back(
        {{"bufferView", view}, {"componentType", type}, {"count", count}, {"type", kind}});
    return accessors.size() - 1;
  };
  bool animated = false;
  for (const auto& m : meshes) animated = animated || m.dynamic;
  size_t time_accessor = 0, weight_accessor = 0;
  if (animated) {
    time_accessor = add_accessor(add_view(4 * K, 0), kFloat, K, "SCALAR");
    accessors[time_accessor]["min"] = {0.0};
    accessors[time_accessor]["max"] = {double(K - 1)};
    weight_accessor = add_accessor(add_view(4 * K * (K - 1), 0), kFloat, K * (K - 1), "SCALAR");
  }
  float f[3];
  for (size_t o = 0; o < nobj; ++o) {
    const ObjectMesh& m = meshes[o];
    Json node = {{"name", scene.objects[o].name}};
    if (!m.indices.empty()) {
      size_t ia = add_accessor(add_view(4 * m.indices.size(), kElementArrayBuffer), kUnsignedInt,
                               m.indices.size(), "SCALAR");
      Json prim = {{"attributes", Json::object()}, {"indices", ia}, {"mode", 4}};
      const size_t states = m.dynamic ? K : 1;
      Json targets = Json::array();
      for (size_t k = 0; k < states; ++k) {
        MinMax mm;
        for (uint32_t v : m.vertices) {
          vertex_float(scene, v, k, f);
          mm.extend(f);
        }
        size_t pa = add_accessor(add_view(12 * m.vertices.size(), kArrayBuffer), kFloat,
                                 m.vertices.size(), "VEC3");
        accessors[pa]["min"] = vec3_json(mm.lo);
        accessors[pa]["max"] = vec3_json(mm.hi);
        if (k == 0)
          prim["attributes"]["POSITION"] = pa;
        else
          targets.push_back({{"POSITION", pa}});
      }
      if (m.dynamic) prim["targets"] = targets;
      Json mesh = {{"name", scene.objects[o].name}, {"primitives", Json::array({prim})}};
      if (m.dynamic) {
        mesh["weights"] = std::vector<double>(K - 1, 0.0);
        samplers.push_back(
            {{"input", time_accessor}, {"interpolation", "LINEAR"}, {"output", weight_accessor}});
        channels.push_back(
            {{"sampler", samplers.size() - 1}, {"target", {{"node", o}, {"path", "weights"}}}});
      }
      node["mesh"] = meshes_json.size();
      meshes_json.push_back(mesh);
    }
    nodes.push_back(node);
  }
  Json root_nodes = Json::array();
  for (size_t o = 0; o < nobj; ++o) root_nodes.push_back(o);
  j["scenes"] = Json::array({{{"nodes", root_nodes}}});
  j["nodes"] = nodes;
  if (!meshes_json.empty()) j["meshes"] = meshes_json;
  if (animated)
    j["animations"] =
        Json::array({{{"name", "states"}, {"channels", channels}, {"samplers", samplers}}});
  if (!accessors.empty()) {
    j["accessors"] = accessors;
    j["bufferViews"] = views;
    j["buffers"] = Json::array({{{"byteLength", offset}}});
  }

  std::string json = j.dump();
  json.append((4 - json.size() % 4) % 4, ' ');
  const uint64_t bin = offset;  // every view is a multiple of 4 bytes
  const uint64_t total = 12 + 8 + json.size() + (bin ? 8 + bin : 0);
  if (total > 0xFFFFFFFFull)
    throw std::runtime_error("scene too large for GLB: " + std::to_string(total) +
                             " bytes exceed the 4 GiB limit of the format");

  std::string out(size_t(total), '\0');
  char* p = out.data();
  auto put32 = [&](uint32_t v) {
    std::memcpy(p, &v, 4);  // GLB is little-endian, as are our targets
    p += 4;
  };
  put32(0x46546C67);  // "glTF"
  put32(2);
  put32(uint32_t(total));
  put32(uint32_t(json.size()));
  put32(0x4E4F534A);  // "JSON"
  std::memcpy(p, json.data(), json.size());
  p += json.size();
  if (bin) {
    put32(uint32_t(bin));
    put32(0x004E4942);  // "BIN\0"
    auto putf = [&](float v) {
      std::memcpy(p, &v, 4);
      p += 4;
    };
    if (animated) {
      for (size_t k = 0; k < K; ++k) putf(float(k));
      for (size_t k = 0; k < K; ++k)
        for (size_t t = 0; t + 1 < K; ++t) putf(k > 0 && t == k - 1 ? 1.0f : 0.0f);
    }
    for (const auto& m : meshes) {
      if (m.indices.empty()) continue;
      std::memcpy(p, m.indices.data(), 4 * m.indices.size());
      p += 4 * m.indices.size();
      for (size_t k = 0; k < (m.dynamic ? K : 1); ++k)
        for (uint32_t v : m.vertices) {
          vertex_float(scene, v, k, f);
          std::memcpy(p, f, 12);
          p += 12;
        }
    }
  }
  assert(p == out.data() + out.size());
  return out;
}

}  // namespace vislib
