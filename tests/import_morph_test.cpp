// Tests of glTF morph targets in vislib::load_scene (import_gltf.cpp): POSITION targets, default /
// node / animated weights, the morph-then-transform order, and the round trip of animated
// generated scenes through scene_to_glb (which writes motion as morph targets).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "tests/import_test_files.h"
#include "tests/test_support.h"
#include "vislib/base/error.h"
#include "vislib/scene/generate.h"
#include "vislib/scene/import.h"
#include "vislib/scene/write_gltf.h"

using namespace vislib;
using namespace vislib_test;
using json = nlohmann::json;

namespace {

Scene load(const std::string& path, int states = 1, std::vector<std::string>* warnings = nullptr) {
  LoadOptions o;
  o.states = states;
  return load_scene(path, o, warnings);
}

// A .gltf with one buffer (a data URI) built from float/uint32 arrays, one bufferView each.
struct Builder {
  std::string bin;
  json doc;
  Builder() {
    doc["asset"] = {{"version", "2.0"}};
    doc["bufferViews"] = json::array();
    doc["accessors"] = json::array();
  }
  size_t view(const void* data, size_t bytes) {
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
    bin.append(static_cast<const char*>(data), bytes);
    return doc["bufferViews"].size() - 1;
  }
  // Float accessor of `type` ("SCALAR", "VEC3") over `v`.
  int floats(const std::vector<float>& v, const char* type) {
    size_t n = std::string(type) == "VEC3" ? 3 : 1;
    json a = {{"bufferView", view(v.data(), 4 * v.size())}, {"componentType", 5126},
              {"count", v.size() / n}, {"type", type}};
    if (n == 1 && !v.empty()) {
      a["min"] = {*std::min_element(v.begin(), v.end())};
      a["max"] = {*std::max_element(v.begin(), v.end())};
    }
    doc["accessors"].push_back(a);
    return int(doc["accessors"].size() - 1);
  }
  // VEC3 float accessor of `count` zeros (no bufferView) with sparse replacements.
  int sparse_vec3(size_t count, const std::vector<uint32_t>& indices, const std::vector<float>& values) {
    size_t iv = view(indices.data(), 4 * indices.size()), vv = view(values.data(), 4 * values.size());
    doc["accessors"].push_back(
        {{"componentType", 5126}, {"count", count}, {"type", "VEC3"},
         {"sparse", {{"count", indices.size()},
                     {"indices", {{"bufferView", iv}, {"componentType", 5125}}},
                     {"values", {{"bufferView", vv}}}}}});
    return int(doc["accessors"].size() - 1);
  }
  std::string write(const std::string& path) {
    doc["buffers"] = json::array(
        {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return write_text(path, doc.dump());
  }
};

// One triangle (0,0,0) (1,0,0) (0,1,0) with one morph target moving every vertex by (0,0,2),
// mesh weights [0.5], node 0 holding the mesh; `edit` changes the document before it is written.
std::string one_target_gltf(const std::string& path,
                            const std::function<void(Builder&)>& edit = nullptr) {
  Builder b;
  int pos = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  int target = b.floats({0, 0, 2, 0, 0, 2, 0, 0, 2}, "VEC3");
  b.doc["meshes"] = json::array({{{"name", "m"},
                                  {"weights", {0.5}},
                                  {"primitives", json::array({{{"attributes", {{"POSITION", pos}}},
                                                                {"targets", json::array({{{"POSITION", target}}})}}})}}});
  b.doc["nodes"] = json::array({{{"name", "n"}, {"mesh", 0}}});
  b.doc["scenes"] = json::array({{{"nodes", {0}}}});
  b.doc["scene"] = 0;
  if (edit) edit(b);
  return b.write(path);
}

// Adds an animation of node 0's weights: keys at `times`, `values` (per key: the weights, or for
// CUBICSPLINE in-tangents, values, out-tangents), `interp`.
void add_weights_animation(Builder& b, const std::vector<float>& times,
                           const std::vector<float>& values, const char* interp) {
  int in = b.floats(times, "SCALAR"), out = b.floats(values, "SCALAR");
  b.doc["animations"] = json::array(
      {{{"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "weights"}}}}})},
        {"samplers", json::array({{{"input", in}, {"output", out}, {"interpolation", interp}}})}}});
}

std::vector<double> z_of_states(const Scene& s, uint32_t vertex) {
  std::vector<double> z;
  for (const auto& p : s.positions) z.push_back(p[vertex].z);
  return z;
}

}  // namespace

TEST(ImportGltfMorph, DefaultWeightHalfGivesHalfWayPositions) {
  std::string dir = temp_dir("morph_half");
  std::vector<std::string> warnings;
  Scene s = load(one_target_gltf(dir + "/half.gltf"), 1, &warnings);
  ASSERT_EQ(s.state_count(), 1u);
  ASSERT_EQ(s.vertex_count(), 3u);
  EXPECT_EQ(s.positions[0][0], (Vec3{0, 0, 1}));
  EXPECT_EQ(s.positions[0][1], (Vec3{1, 0, 1}));
  EXPECT_EQ(s.positions[0][2], (Vec3{0, 1, 1}));
  EXPECT_TRUE(warnings.empty()) << warnings[0];
}

TEST(ImportGltfMorph, NodeWeightsOverrideMeshWeights) {
  std::string dir = temp_dir("morph_node");
  Scene s = load(one_target_gltf(dir + "/node.gltf", [](Builder& b) {
    b.doc["nodes"][0]["weights"] = {0.25};
  }));
  EXPECT_EQ(s.positions[0][1], (Vec3{1, 0, 0.5}));
}

TEST(ImportGltfMorph, TargetIsAppliedBeforeTheNodeTransform) {
  std::string dir = temp_dir("morph_order");
  // Scale 2 then translate x by 10: the half-way displacement (0,0,1) is scaled too.
  Scene s = load(one_target_gltf(dir + "/order.gltf", [](Builder& b) {
    b.doc["nodes"][0]["scale"] = {2, 2, 2};
    b.doc["nodes"][0]["translation"] = {10, 0, 0};
  }));
  EXPECT_EQ(s.positions[0][1], (Vec3{12, 0, 2}));
}

TEST(ImportGltfMorph, SparseTargetMovesOnlyItsVertices) {
  std::string dir = temp_dir("morph_sparse");
  Scene s = load(one_target_gltf(dir + "/sparse.gltf", [](Builder& b) {
    int t = b.sparse_vec3(3, {2}, {0, 0, 4});
    b.doc["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = t;
  }));
  EXPECT_EQ(s.positions[0][0], (Vec3{0, 0, 0}));
  EXPECT_EQ(s.positions[0][1], (Vec3{1, 0, 0}));
  EXPECT_EQ(s.positions[0][2], (Vec3{0, 1, 2}));
}

TEST(ImportGltfMorph, AnimatedWeightsAreSampledAtTheStateTimes) {
  std::string dir = temp_dir("morph_anim");
  // Keys at t = 0 and 2; states 3 sample t = 0, 1, 2.
  auto with = [&](const char* name, const char* interp, std::vector<float> values) {
    return one_target_gltf(dir + "/" + name + ".gltf", [&](Builder& b) {
      add_weights_animation(b, {0, 2}, values, interp);
    });
  };
  std::string linear = with("linear", "LINEAR", {0, 1});
  EXPECT_EQ(z_of_states(load(linear, 3), 1), (std::vector<double>{0, 1, 2}));
  // states = 1 is the rest pose: the default weight 0.5, not the animation's value at t = 0.
  EXPECT_EQ(z_of_states(load(linear, 1), 1), (std::vector<double>{1}));
  EXPECT_EQ(z_of_states(load(with("step", "STEP", {0, 1}), 3), 1), (std::vector<double>{0, 0, 2}));
  // CUBICSPLINE: (in-tangent, value, out-tangent) per key. Zero tangents give the smoothstep
  // through the values (0 -> 1), 0.5 at the middle: the value slot is read.
  EXPECT_EQ(z_of_states(load(with("cubic0", "CUBICSPLINE", {0, 0, 0, 0, 1, 0}), 3), 1),
            (std::vector<double>{0, 1, 2}));
  Scene c = load(with("cubic1", "CUBICSPLINE", {0, 0, 2, 0, 0, 2}), 3);
  // Values 0 at both keys, out-tangent of key 0 = 2 per second, in-tangent of key 1 = 0: at the
  // middle h10(1/2) * dt * 2 = 1/8 * 2 * 2 = 0.5, so z = 1 (swapped tangent slots would give -1).
  EXPECT_EQ(z_of_states(c, 1), (std::vector<double>{0, 1, 0}));
}

TEST(ImportGltfMorph, WeightsOfFourTargetsAreInterpolatedLinearlyNotAsQuaternions) {
  std::string dir = temp_dir("morph_four");
  // Four targets, each moving z by 1: z = sum of the weights. Keys (1,0,0,0) -> (0,0,0,1): a
  // quaternion slerp would give 2 * sqrt(1/2) at the middle, linear gives 1.
  std::string path = one_target_gltf(dir + "/four.gltf", [](Builder& b) {
    int t = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    json targets = json::array();
    for (int i = 0; i < 4; ++i) targets.push_back({{"POSITION", t}});
    b.doc["meshes"][0]["primitives"][0]["targets"] = targets;
    b.doc["meshes"][0]["weights"] = {0, 0, 0, 0};
    add_weights_animation(b, {0, 2}, {1, 0, 0, 0, 0, 0, 0, 1}, "LINEAR");
  });
  EXPECT_EQ(z_of_states(load(path, 3), 0), (std::vector<double>{1, 1, 1}));
}

TEST(ImportGltfMorph, BadTargetsAndWeightsThrowInputErrorNamingTheAccessor) {
  std::string dir = temp_dir("morph_bad");
  struct Case {
    const char* name;
    std::function<void(Builder&)> edit;
    const char* expect;
  } cases[] = {
      {"target_count",
       [](Builder& b) {
         b.doc["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = b.floats({0, 0, 2, 0, 0, 2}, "VEC3");
       },
       "accessor 2 (POSITION of morph target 0 of mesh 0 primitive 0): 2 elements"},
      {"target_type",
       [](Builder& b) {
         b.doc["meshes"][0]["primitives"][0]["targets"][0]["POSITION"] = b.floats({0, 0, 2}, "SCALAR");
       },
       "accessor 2 (POSITION of morph target 0"},
      {"mesh_weights", [](Builder& b) { b.doc["meshes"][0]["weights"] = {0.5, 0.5}; },
       "mesh 0: weights has 2 numbers"},
      {"node_weights", [](Builder& b) { b.doc["nodes"][0]["weights"] = {1, 2, 3}; },
       "node 0: weights has 3 numbers"},
      {"animated_weights",
       [](Builder& b) { add_weights_animation(b, {0, 1}, {0, 1, 1}, "LINEAR"); },
       "accessor 3 (output of animation 0 channel 0): 3 values"},
  };
  for (auto& c : cases) {
    std::string path = one_target_gltf(dir + "/" + c.name + ".gltf", c.edit);
    try {
      load(path, 3);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << c.name << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(ImportGltfMorph, GeneratedGrassRoundTripsThroughGlbInEveryState) {
  GrassOptions o;
  o.size = 10;
  o.target_triangles = 3000;
  o.states = 4;
  Scene g = generate_grass(o);
  ASSERT_TRUE(g.is_dynamic());
  std::string path = temp_dir("morph_grass") + "/grass.glb";
  {
    std::ofstream out(path, std::ios::binary);
    out << scene_to_glb(g);
  }
  std::vector<std::string> warnings;
  Scene s = load(path, 4, &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings[0];
  ASSERT_EQ(s.state_count(), 4u);
  ASSERT_EQ(s.triangle_count(), g.triangle_count());
  EXPECT_EQ(s.vertex_count(), g.vertex_count());
  // Positions go through float: state 0 as float, later states as float displacements from it.
  const Box3 box = g.bounds();
  const double size = std::max({box.max.x - box.min.x, box.max.y - box.min.y, box.max.z - box.min.z});
  const double tol = 1e-5 * size;
  double worst = 0;
  for (size_t k = 0; k < 4; ++k)
    for (uint32_t t = 0; t < g.triangle_count(); ++t) {
      auto a = g.corners(t, k), b = s.corners(t, k);
      for (int i = 0; i < 3; ++i)
        worst = std::max({worst, std::abs(a[i].x - b[i].x), std::abs(a[i].y - b[i].y),
                          std::abs(a[i].z - b[i].z)});
    }
  EXPECT_LE(worst, tol) << "largest coordinate error " << worst << " m, scene size " << size << " m";
}

TEST(ImportGltfMorph, PvsInfoReportsTenDynamicStatesOfGeneratedGrass) {
  std::string dir = temp_dir("morph_cli");
  std::string out;
  ASSERT_EQ(run_pvs("generate grass --size 10 --target-triangles 2000 -o '" + dir + "/g.glb'", &out), 0) << out;
  ASSERT_EQ(run_pvs("info '" + dir + "/g.glb' --states 10", &out), 0) << out;
  EXPECT_NE(out.find("10 (dynamic)"), std::string::npos) << out;
}
