#include "vislib/scene/generate.h"

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <map>
#include <utility>

#include "tests/test_support.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/write_gltf.h"
#include "vislib/scene/write_spheres.h"

using namespace vislib;

namespace {

CityOptions small_city(uint64_t seed) {
  CityOptions o;
  o.blocks_x = 3;
  o.blocks_z = 2;
  o.panel_size = 4;
  o.max_height = 80;  // tall enough for setback tiers
  o.seed = seed;
  return o;
}

GrassOptions small_grass(uint64_t seed) {
  GrassOptions o;
  o.size = 10;
  o.density = 5;
  o.states = 4;
  o.seed = seed;
  return o;
}

SphereOptions small_spheres(uint64_t seed) {
  SphereOptions o;
  o.count = 200;
  o.area = 30;
  o.seed = seed;
  return o;
}

// Parses GLB bytes with tinygltf; returns the triangle count over all primitives (0 on failure).
size_t glb_triangles(const std::string& glb, tinygltf::Model* model_out = nullptr) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = loader.LoadBinaryFromMemory(&model, &err, &warn,
                                        reinterpret_cast<const unsigned char*>(glb.data()),
                                        unsigned(glb.size()));
  EXPECT_TRUE(ok) << err;
  if (!ok) return 0;
  size_t tris = 0;
  for (const auto& mesh : model.meshes)
    for (const auto& prim : mesh.primitives) {
      EXPECT_EQ(prim.mode, TINYGLTF_MODE_TRIANGLES);
      tris += model.accessors[size_t(prim.indices)].count / 3;
    }
  if (model_out) *model_out = std::move(model);
  return tris;
}

}  // namespace

TEST(Generate, SameSeedGivesIdenticalFiles) {
  EXPECT_EQ(scene_to_glb(generate_city(small_city(7))), scene_to_glb(generate_city(small_city(7))));
  EXPECT_EQ(scene_to_glb(generate_grass(small_grass(7))),
            scene_to_glb(generate_grass(small_grass(7))));
  EXPECT_EQ(spheres_to_text(generate_spheres(small_spheres(7))),
            spheres_to_text(generate_spheres(small_spheres(7))));
}

TEST(Generate, DifferentSeedsGiveDifferentScenes) {
  EXPECT_NE(scene_to_glb(generate_city(small_city(1))), scene_to_glb(generate_city(small_city(2))));
  EXPECT_NE(scene_to_glb(generate_grass(small_grass(1))),
            scene_to_glb(generate_grass(small_grass(2))));
  EXPECT_NE(spheres_to_text(generate_spheres(small_spheres(1))),
            spheres_to_text(generate_spheres(small_spheres(2))));
}

TEST(Generate, CityTriangleCountFollowsTarget) {
  for (uint64_t target : {30000ull, 200000ull, 1000000ull}) {
    CityOptions o;
    o.target_triangles = target;
    o.auto_blocks = true;
    size_t n = generate_city(o).triangle_count();
    EXPECT_NEAR(double(n), double(target), 0.1 * double(target)) << "target " << target;
  }
  CityOptions fixed = small_city(3);
  fixed.target_triangles = 50000;
  EXPECT_NEAR(double(generate_city(fixed).triangle_count()), 50000.0, 5000.0);
  CityOptions plain = small_city(3);
  EXPECT_EQ(generate_city(plain).triangle_count(), city_triangle_count(plain));
}

TEST(Generate, GrassTriangleCountFollowsTarget) {
  GrassOptions o = small_grass(1);
  o.target_triangles = 123456;
  Scene s = generate_grass(o);
  EXPECT_NEAR(double(s.triangle_count()), 123456.0, 3.0);
  GrassOptions more = o;
  more.target_triangles = 2 * o.target_triangles;
  EXPECT_GT(generate_grass(more).triangle_count(), s.triangle_count());
}

TEST(Generate, CityBuildingsAreClosedOutwardAndNonDegenerate) {
  for (double panel : {0.0, 4.0, 7.3}) {
    SCOPED_TRACE("panel " + std::to_string(panel));
    CityOptions o = small_city(5);
    o.panel_size = panel;
    Scene s = generate_city(o);
    ASSERT_EQ(s.objects[0].name, "ground");
    int setbacks = 0;
    for (uint32_t obj = 1; obj < s.objects.size(); ++obj) {
      std::map<std::pair<uint32_t, uint32_t>, int> directed;
      double volume = 0;
      Box3 base, top;  // footprint at y = 0 and at the roof
      double roof = 0;
      for (uint32_t t = 0; t < s.triangle_count(); ++t) {
        if (s.triangle_object[t] != obj) continue;
        const auto& tri = s.triangles[t];
        auto c = s.corners(t);
        EXPECT_GT(length(cross(c[1] - c[0], c[2] - c[0])), 1e-6) << s.objects[obj].name;
        volume += dot(c[0], cross(c[1], c[2])) / 6;
        for (int e = 0; e < 3; ++e) ++directed[{tri[e], tri[(e + 1) % 3]}];
        for (auto& p : c) {
          if (p.y == 0) base.extend(p);
          roof = std::max(roof, p.y);
        }
      }
      for (uint32_t t = 0; t < s.triangle_count(); ++t)
        if (s.triangle_object[t] == obj)
          for (auto& p : s.corners(t))
            if (p.y == roof) top.extend(p);
      if (top.min.x > base.min.x && top.max.x < base.max.x) ++setbacks;
      // Closed with consistent winding: each directed edge once, and its reverse once.
      for (const auto& [edge, count] : directed) {
        EXPECT_EQ(count, 1) << s.objects[obj].name;
        auto rev = directed.find({edge.second, edge.first});
        EXPECT_TRUE(rev != directed.end() && rev->second == 1) << s.objects[obj].name;
      }
      EXPECT_GT(volume, 0) << s.objects[obj].name << " is not wound outward";
    }
    EXPECT_GT(setbacks, 0) << "expected some buildings with setback tiers";
  }
}

TEST(Generate, CityObjectsAreContiguousAndNamed) {
  Scene s = generate_city(small_city(5));
  EXPECT_TRUE(std::is_sorted(s.triangle_object.begin(), s.triangle_object.end()));
  EXPECT_EQ(s.objects[1].name.rfind("building_", 0), 0u);
  EXPECT_FALSE(s.is_dynamic());
}

TEST(Generate, GrassBladeBasesStayFixedAndTerrainIsStatic) {
  Scene s = generate_grass(small_grass(4));
  ASSERT_EQ(s.state_count(), 4u);
  ASSERT_EQ(s.objects[0].name, "terrain");
  EXPECT_TRUE(s.is_dynamic());
  size_t moving = 0;
  for (size_t v = 0; v < s.vertex_count(); ++v)
    for (size_t k = 1; k < s.state_count(); ++k)
      if (s.positions[k][v] != s.positions[0][v]) {
        ++moving;
        break;
      }
  for (uint32_t t = 0; t < s.triangle_count(); ++t) {
    auto c = s.corners(t);
    EXPECT_GT(length(cross(c[1] - c[0], c[2] - c[0])), 0) << "triangle " << t;
    if (s.triangle_object[t] == 0) {
      for (uint32_t v : s.triangles[t])
        for (size_t k = 1; k < s.state_count(); ++k)
          EXPECT_EQ(s.positions[k][v], s.positions[0][v]);
    }
  }
  // Each 3-triangle blade has 5 vertices, the 2 base ones fixed.
  size_t blades = (s.triangle_count() - 2 * 10 * 10) / 3;
  EXPECT_EQ(moving, blades * 3);
}

TEST(Generate, SpheresStayAboveGroundAndInsideArea) {
  SphereOptions o = small_spheres(9);
  o.duration = 20;  // long enough for many bounces
  Scene s = generate_spheres(o);
  ASSERT_EQ(s.sphere_centers.size(), size_t(o.states));
  ASSERT_EQ(s.sphere_count(), size_t(o.count));
  EXPECT_TRUE(s.is_dynamic());
  for (const auto& state : s.sphere_centers)
    for (size_t i = 0; i < state.size(); ++i) {
      EXPECT_GE(state[i].y, o.radius - 1e-9);
      EXPECT_LE(std::abs(state[i].x), o.area / 2 - o.radius + 1e-9);
      EXPECT_LE(std::abs(state[i].z), o.area / 2 - o.radius + 1e-9);
    }
  EXPECT_EQ(s.objects[17].name, "sphere17");
}

TEST(Generate, SphereTextFollowsTheFormat) {
  Scene s = generate_spheres(small_spheres(2));
  std::string text = spheres_to_text(s);
  EXPECT_EQ(text.rfind("vislib-spheres 1\n", 0), 0u);
  EXPECT_NE(text.find("\nstates 25\n"), std::string::npos);
  // Header, comment, states line, one line per sphere; each with 1 + 3K numbers.
  size_t lines = std::count(text.begin(), text.end(), '\n');
  EXPECT_EQ(lines, 3 + s.sphere_count());
  size_t first = text.find("\nstates 25\n") + 11;
  std::string line = text.substr(first, text.find('\n', first) - first);
  EXPECT_EQ(std::count(line.begin(), line.end(), ' '), 3 * 25);
  EXPECT_EQ(std::stod(line.substr(0, line.find(' '))), 4.0);
  EXPECT_EQ(std::stod(line.substr(line.find(' ') + 1)), s.sphere_centers[0][0].x);
}

TEST(Generate, GlbParsesBackWithSameTriangles) {
  Scene city = generate_city(small_city(1));
  tinygltf::Model model;
  EXPECT_EQ(glb_triangles(scene_to_glb(city), &model), city.triangle_count());
  ASSERT_EQ(model.nodes.size(), city.objects.size());
  EXPECT_EQ(model.nodes[0].name, "ground");
  EXPECT_TRUE(model.animations.empty());
  // First building: same vertex positions (as float) in the same order as the scene.
  const auto& prim = model.meshes[size_t(model.nodes[1].mesh)].primitives[0];
  const auto& ia = model.accessors[size_t(prim.indices)];
  const auto& pa = model.accessors[size_t(prim.attributes.at("POSITION"))];
  const auto& iv = model.bufferViews[size_t(ia.bufferView)];
  const auto& pv = model.bufferViews[size_t(pa.bufferView)];
  const auto* idx = reinterpret_cast<const uint32_t*>(model.buffers[0].data.data() + iv.byteOffset);
  const auto* pos = reinterpret_cast<const float*>(model.buffers[0].data.data() + pv.byteOffset);
  size_t first = size_t(std::find(city.triangle_object.begin(), city.triangle_object.end(), 1u) -
                        city.triangle_object.begin());
  for (size_t t = 0; t < ia.count / 3; ++t)
    for (int c = 0; c < 3; ++c) {
      Vec3 want = city.positions[0][city.triangles[first + t][c]];
      const float* got = pos + 3 * idx[3 * t + c];
      EXPECT_EQ(got[0], float(want.x));
      EXPECT_EQ(got[1], float(want.y));
      EXPECT_EQ(got[2], float(want.z));
    }
}

TEST(Generate, AnimatedGlbHasMorphTargetsPerState) {
  Scene grass = generate_grass(small_grass(3));
  tinygltf::Model model;
  EXPECT_EQ(glb_triangles(scene_to_glb(grass), &model), grass.triangle_count());
  ASSERT_EQ(model.animations.size(), 1u);
  EXPECT_EQ(model.animations[0].channels.size(), grass.objects.size() - 1);  // terrain is static
  EXPECT_TRUE(model.meshes[0].primitives[0].targets.empty());
  ASSERT_GT(model.meshes.size(), 1u);
  const auto& prim = model.meshes[1].primitives[0];
  EXPECT_EQ(prim.targets.size(), grass.state_count() - 1);
  EXPECT_EQ(model.meshes[1].weights.size(), grass.state_count() - 1);
  EXPECT_EQ(model.animations[0].channels[0].target_path, "weights");
}

TEST(Generate, CliWritesFilesAndRefusesWrongExtensions) {
  std::string dir = vislib_test::temp_dir("generate_cli");
  std::string out;
  EXPECT_EQ(vislib_test::run_pvs("generate city --blocks 2,2 --seed 3 -o " + dir + "/c.glb", &out),
            0)
      << out;
  EXPECT_NE(out.find("triangles"), std::string::npos) << out;
  EXPECT_EQ(read_file(dir + "/c.glb"), [] {
    CityOptions o;
    o.blocks_x = o.blocks_z = 2;
    o.seed = 3;
    return scene_to_glb(generate_city(o));
  }());
  EXPECT_EQ(vislib_test::run_pvs("generate spheres --count 10 -o " + dir + "/s.spheres", &out), 0)
      << out;
  EXPECT_EQ(vislib_test::run_pvs("generate grass --size 4 -o " + dir + "/g.obj", &out), 2) << out;
  EXPECT_NE(out.find(".glb"), std::string::npos) << out;
  EXPECT_EQ(vislib_test::run_pvs("generate spheres -o " + dir + "/s.glb", &out), 2) << out;
  EXPECT_EQ(vislib_test::run_pvs("generate city --blocks 0,2 -o " + dir + "/c.glb", &out), 2)
      << out;
}
