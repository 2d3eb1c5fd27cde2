// pvs bake on dynamic scenes and sphere files: spheres are ids after the triangles (triangle
// granularity) or their objects; an animated glTF is baked over all its sampled states, and its
// fingerprint covers every state (inspect must load it with the same --states).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <vector>

#include "tests/test_support.h"

using vislib_test::run_pvs;

TEST(BakeDynamic, SphereFileBakesSphereIdsAfterTheTriangles) {
  std::string dir = vislib_test::temp_dir("bake_spheres");
  std::string out;
  ASSERT_EQ(run_pvs("generate spheres --count 40 --states 3 --area 20 --radius 1 --seed 2 -o " +
                        dir + "/s.spheres",
                    &out),
            0)
      << out;
  ASSERT_EQ(run_pvs("bake " + dir + "/s.spheres --box -8,1,-8,8,2,8 --grid 1,1,1 --res 32 -o " +
                        dir + "/s.pvs",
                    &out),
            0)
      << out;
  ASSERT_EQ(run_pvs("inspect " + dir + "/s.pvs --cell 0 --json 2>/dev/null", &out), 0) << out;
  auto j = nlohmann::json::parse(out.substr(out.find('{')));
  // Universe: 0 triangles + 40 spheres. The 40 spheres of radius 1 over a 20 x 20 area are all
  // seen from the box above them (bake of one cell): the exact set is every id 0..39.
  std::vector<uint32_t> all(40);
  for (uint32_t i = 0; i < 40; ++i) all[i] = i;
  EXPECT_EQ(j["visible_count"].get<int>(), 40);
  EXPECT_EQ(j["visible"].get<std::vector<uint32_t>>(), all);
}

TEST(BakeDynamic, AnimatedGltfBakesAllStatesAndInspectNeedsTheSameStates) {
  VISLIB_REQUIRE_SHARED(shared);
  std::string dir = vislib_test::temp_dir("bake_anim");
  std::string scene = shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf", out;
  ASSERT_EQ(run_pvs("bake " + scene + " --states 5 --box -3,0,1,3,1,3 --grid 2,1,1 --res 32 -o " +
                        dir + "/b.pvs",
                    &out),
            0)
      << out;
  EXPECT_EQ(run_pvs("inspect " + dir + "/b.pvs --scene " + scene + " --states 5 --cell 0", &out), 0)
      << out;
  EXPECT_EQ(run_pvs("inspect " + dir + "/b.pvs --scene " + scene + " --cell 0", &out), 2) << out;
  EXPECT_NE(out.find("fingerprint"), std::string::npos) << out;
}
