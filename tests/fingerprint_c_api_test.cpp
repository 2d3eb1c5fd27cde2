// The scene fingerprint from an engine's own buffers (pvs_rt_scene_fingerprint) equals
// the bake's (vislib::scene_fingerprint, what `pvs bake` writes into the PVS header), with the
// meshes taken as the id map's runs (vislib/scene/id_map.h, `pvs export --id-map`).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "runtime/pvs_runtime_c.h"
#include "scene_builders.h"
#include "test_support.h"
#include "vislib/scene/id_map.h"
#include "vislib/scene/import.h"
#include "vislib/scene/scene_fingerprint.h"

namespace {

// One pvs_rt_mesh per id-map run, with the world-space positions (node transforms applied, in
// double, as vislib's importer does) and indices local to the run's vertex block, all key states.
struct EngineBuffers {
  std::vector<std::vector<double>> positions;
  std::vector<std::vector<uint32_t>> indices;
  std::vector<pvs_rt_mesh> meshes;
};

EngineBuffers engine_buffers(const vislib::Scene& scene, const vislib::IdMap& map) {
  EngineBuffers b;
  for (const vislib::IdRun& run : map.runs) {
    std::vector<double> pos;
    for (const auto& state : scene.positions)
      for (uint32_t v = run.first_vertex; v < run.first_vertex + run.vertex_count; ++v) {
        const vislib::Vec3 p = state[v];
        pos.insert(pos.end(), {p.x, p.y, p.z});
      }
    std::vector<uint32_t> idx;
    for (uint32_t t = run.first_triangle; t < run.first_triangle + run.triangle_count; ++t)
      for (uint32_t v : scene.triangles[t]) idx.push_back(v - run.first_vertex);
    b.positions.push_back(std::move(pos));
    b.indices.push_back(std::move(idx));
  }
  for (size_t m = 0; m < map.runs.size(); ++m)
    b.meshes.push_back({nullptr, b.positions[m].data(), map.runs[m].vertex_count,
                        b.indices[m].data(), map.runs[m].triangle_count, map.runs[m].object,
                        nullptr});
  return b;
}

}  // namespace

TEST(FingerprintCApi, EnginesMeshBuffersGiveTheBakesFingerprintForTheCity) {
  const vislib::Scene scene = vislib::load_scene(std::string(VISLIB_SOURCE_DIR) + "/data/city.glb");
  const vislib::IdMap map = vislib::id_map(scene);
  ASSERT_TRUE(map.vertices_tiled);
  ASSERT_GT(map.runs.size(), 10u);
  EngineBuffers b = engine_buffers(scene, map);
  uint64_t fp = 0;
  ASSERT_EQ(
      pvs_rt_scene_fingerprint(b.meshes.data(), b.meshes.size(), uint32_t(scene.positions.size()),
                               uint32_t(scene.objects.size()), &fp),
      PVS_RT_OK)
      << pvs_rt_last_error();
  EXPECT_EQ(fp, vislib::scene_fingerprint(scene));
  // One coordinate of one vertex off by one ulp: another asset, another fingerprint.
  b.positions[3][4] = std::nextafter(b.positions[3][4], 1e9);
  uint64_t moved = 0;
  ASSERT_EQ(pvs_rt_scene_fingerprint(b.meshes.data(), b.meshes.size(), 1,
                                     uint32_t(scene.objects.size()), &moved),
            PVS_RT_OK);
  EXPECT_NE(moved, fp);
}

TEST(FingerprintCApi, KeyStatesAndPerTriangleObjectsMatchTheBake) {
  // Two objects of quads in two key states.
  vislib::Scene s;
  vislib_test::add_quad(s, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
  vislib_test::add_quad(s, {2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 1, 0});
  s.positions.push_back(s.positions[0]);
  for (auto& p : s.positions[1]) p.y += 0.25;
  const vislib::IdMap map = vislib::id_map(s);
  ASSERT_EQ(map.runs.size(), 2u);
  EngineBuffers b = engine_buffers(s, map);
  uint64_t fp = 0;
  ASSERT_EQ(pvs_rt_scene_fingerprint(b.meshes.data(), 2, 2, uint32_t(s.objects.size()), &fp),
            PVS_RT_OK)
      << pvs_rt_last_error();
  EXPECT_EQ(fp, vislib::scene_fingerprint(s));
  // The same scene as one buffer with an object per triangle.
  std::vector<double> all;
  for (const auto& state : s.positions)
    for (const auto& p : state) all.insert(all.end(), {p.x, p.y, p.z});
  std::vector<uint32_t> idx;
  for (const auto& t : s.triangles) idx.insert(idx.end(), t.begin(), t.end());
  pvs_rt_mesh one{nullptr,
                  all.data(),
                  s.vertex_count(),
                  idx.data(),
                  s.triangle_count(),
                  0,
                  s.triangle_object.data()};
  uint64_t fp_one = 0;
  ASSERT_EQ(pvs_rt_scene_fingerprint(&one, 1, 2, uint32_t(s.objects.size()), &fp_one), PVS_RT_OK);
  EXPECT_EQ(fp_one, fp);
}
