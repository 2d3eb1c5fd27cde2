// Tests of vislib::load_scene (import.h) and scene_info (scene_info.h) on tiny files made on the
// fly, and on the shared real scenes (skipped when ../shared is absent).
#include "vislib/scene/import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/import_test_files.h"
#include "tests/test_support.h"
#include "vislib/base/error.h"
#include "vislib/scene/scene_info.h"

using namespace vislib;
using namespace vislib_test;
using json = nlohmann::json;

namespace {

Scene load(const std::string& path, int states = 1, std::vector<std::string>* warnings = nullptr) {
  LoadOptions o;
  o.states = states;
  return load_scene(path, o, warnings);
}

}  // namespace

TEST(ImportShared, TriangleCountsMatchTheReadme) {
  VISLIB_REQUIRE_SHARED(shared);
  struct Case {
    const char* file;
    size_t triangles, degenerate;
  } cases[] = {{"sauer_fdm6/fdm6.obj", 9779, 8},
               {"godot_truck_town/town_model.gltf", 30477, 136},
               {"sauer_pandora/pandora.obj", 60810, 116},
               {"godot_occlusion_room/room.glb", 63720, 0},
               {"gk_dream_apartment/dream-apartment.glb", 177934, 2},
               {"khronos_boxanimated/BoxAnimated.gltf", 254, 0},
               {"khronos_fox/Fox.glb", 576, 0}};
  for (const auto& c : cases) {
    Scene s = load(shared + "/scenes/" + c.file);
    SceneInfo info = scene_info(s);
    EXPECT_EQ(info.triangles, c.triangles) << c.file;
    EXPECT_EQ(info.degenerate_triangles, c.degenerate) << c.file;
    EXPECT_EQ(info.out_of_range_indices, 0u) << c.file;
  }
}

TEST(ImportShared, ObjGroupsOfSauerbratenMapsBecomeObjects) {
  VISLIB_REQUIRE_SHARED(shared);
  EXPECT_EQ(load(shared + "/scenes/sauer_fdm6/fdm6.obj").objects.size(), 78u);
  EXPECT_EQ(load(shared + "/scenes/sauer_pandora/pandora.obj").objects.size(), 206u);
}

TEST(ImportShared, MeshoptCompressedApartmentDecodesToTheReadmeBox) {
  VISLIB_REQUIRE_SHARED(shared);
  Box3 b = load(shared + "/scenes/gk_dream_apartment/dream-apartment.glb").bounds();
  EXPECT_NEAR(b.min.x, 0.44, 0.01);
  EXPECT_NEAR(b.max.x, 12.81, 0.01);
  EXPECT_NEAR(b.min.z, -11.43, 0.01);
  EXPECT_NEAR(b.max.y, 2.68, 0.01);
}

TEST(ImportShared, BoxAnimatedWithFiveStatesMovesOnlyTheInnerBox) {
  VISLIB_REQUIRE_SHARED(shared);
  Scene s = load(shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf", 5);
  ASSERT_EQ(s.state_count(), 5u);
  EXPECT_TRUE(s.is_dynamic());
  // Vertices of each object that move between state 0 and some later state.
  std::vector<size_t> moved(s.objects.size(), 0), total(s.objects.size(), 0);
  std::vector<int> obj_of_vertex(s.vertex_count(), -1);
  for (size_t t = 0; t < s.triangle_count(); ++t)
    for (uint32_t v : s.triangles[t]) obj_of_vertex[v] = int(s.triangle_object[t]);
  for (size_t v = 0; v < s.vertex_count(); ++v) {
    if (obj_of_vertex[v] < 0) continue;
    ++total[obj_of_vertex[v]];
    for (size_t k = 1; k < 5; ++k)
      if (s.positions[k][v] != s.positions[0][v]) {
        ++moved[obj_of_vertex[v]];
        break;
      }
  }
  ASSERT_EQ(s.objects.size(), 2u);
  int moving = moved[0] ? 0 : 1;
  EXPECT_EQ(moved[moving], total[moving]);  // the whole inner box moves
  EXPECT_EQ(moved[1 - moving], 0u);         // the shell stays
  // The inner box (62 triangles) rises: its highest point goes up at some state.
  double y0 = -1e9, ymax = -1e9;
  for (size_t v = 0; v < s.vertex_count(); ++v)
    if (obj_of_vertex[v] == moving) {
      y0 = std::max(y0, s.positions[0][v].y);
      for (size_t k = 0; k < 5; ++k) ymax = std::max(ymax, s.positions[k][v].y);
    }
  EXPECT_GT(ymax, y0 + 0.1);
}

TEST(ImportShared, FoxIsSkinnedAndAnimated) {
  VISLIB_REQUIRE_SHARED(shared);
  std::vector<std::string> warnings;
  LoadOptions o;
  o.states = 4;
  o.animation = 1;  // "Walk"
  Scene s = load_scene(shared + "/scenes/khronos_fox/Fox.glb", o, &warnings);
  EXPECT_EQ(s.state_count(), 4u);
  EXPECT_TRUE(s.is_dynamic());
  Box3 b = s.bounds();  // rest pose in state 0 spans the README box (about 160 units long)
  EXPECT_GT(b.max.z - b.min.z, 140.0);
}

TEST(ImportObj, GroupsAndObjectsBecomeNamedObjects) {
  std::string dir = temp_dir("obj_groups");
  std::string path = write_text(dir + "/g.obj",
                                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0 1.0\n"
                                "f 1 2 3\n"
                                "g walls\nf 1/1/1 2/2/2 4/4/4\nf 2//1 4//1 3//1\n"
                                "o door\nf -1 -2 -3\n"
                                "g walls\nf 1 2 3 4\n");
  Scene s = load(path);
  ASSERT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(s.objects[0].name, "default");
  EXPECT_EQ(s.objects[1].name, "walls");
  EXPECT_EQ(s.objects[2].name, "door");
  ASSERT_EQ(s.triangle_count(), 6u);  // the quad is fan-triangulated into 2
  EXPECT_EQ(s.triangle_object, (std::vector<uint32_t>{0, 1, 1, 2, 1, 1}));
  EXPECT_EQ(s.triangles[3], (std::array<uint32_t, 3>{3, 2, 1}));  // negative indices
  EXPECT_EQ(s.triangles[5], (std::array<uint32_t, 3>{0, 2, 3}));
}

TEST(ImportObj, DegenerateFacesAreKeptAndCounted) {
  std::string dir = temp_dir("obj_degenerate");
  std::string path = write_text(dir + "/d.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n");
  Scene s = load(path);
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(scene_info(s).degenerate_triangles, 2u);
}

TEST(ImportObj, OutOfRangeFaceIndexNamesTheLine) {
  std::string dir = temp_dir("obj_range");
  std::string path = write_text(dir + "/r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n");
  try {
    load(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 5"), std::string::npos) << e.what();
    EXPECT_EQ(e.path(), path);
  }
}

TEST(ImportGltf, TriangleStripAndFanFollowTheSpecOrder) {
  std::string dir = temp_dir("gltf_strip");
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0};
  GltfSpec strip;
  strip.positions = pos;
  strip.indices = {0, 1, 2, 3, 4};
  strip.mode = 5;
  Scene s = load(write_gltf(dir + "/strip.gltf", strip));
  ASSERT_EQ(s.triangle_count(), 3u);
  EXPECT_EQ(s.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(s.triangles[1], (std::array<uint32_t, 3>{1, 3, 2}));
  EXPECT_EQ(s.triangles[2], (std::array<uint32_t, 3>{2, 3, 4}));
  GltfSpec fan = strip;
  fan.mode = 6;
  s = load(write_gltf(dir + "/fan.gltf", fan));
  ASSERT_EQ(s.triangle_count(), 3u);
  EXPECT_EQ(s.triangles[0], (std::array<uint32_t, 3>{1, 2, 0}));
  EXPECT_EQ(s.triangles[2], (std::array<uint32_t, 3>{3, 4, 0}));
}

TEST(ImportGltf, NonIndexedTrianglesAndPointsAreSkippedWithWarning) {
  std::string dir = temp_dir("gltf_nonindexed");
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  Scene s = load(write_gltf(dir + "/a.gltf", g));
  EXPECT_EQ(s.triangle_count(), 1u);
  g.mode = 0;
  std::vector<std::string> warnings;
  s = load(write_gltf(dir + "/p.gltf", g), 1, &warnings);
  EXPECT_EQ(s.triangle_count(), 0u);
  EXPECT_EQ(warnings.size(), 1u);
}

TEST(ImportGltf, NodeHierarchyComposesTransformsInOrder) {
  std::string dir = temp_dir("gltf_hierarchy");
  GltfSpec g;
  g.positions = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  // root: translate (10,0,0); child: rotate 90 deg about z, scale 2; grandchild has the mesh and
  // a matrix translating by (0,0,5).
  double h = std::sqrt(0.5);
  g.nodes = json::array(
      {{{"name", "root"}, {"translation", {10, 0, 0}}, {"children", {1}}},
       {{"name", "mid"}, {"rotation", {0, 0, h, h}}, {"scale", {2, 2, 2}}, {"children", {2}}},
       {{"name", "leaf"},
        {"mesh", 0},
        {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}}});
  g.scene_nodes = {0};
  Scene s = load(write_gltf(dir + "/h.gltf", g));
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "leaf");
  // (1,0,0) -> (1,0,5) -> rotate: (0,1,5) -> scale: (0,2,10) -> translate: (10,2,10)
  Vec3 p = s.positions[0][0];
  EXPECT_NEAR(p.x, 10, 1e-12);
  EXPECT_NEAR(p.y, 2, 1e-12);
  EXPECT_NEAR(p.z, 10, 1e-12);
}

TEST(ImportGltf, InstancedMeshGivesOneObjectPerNode) {
  std::string dir = temp_dir("gltf_instancing");
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.indices = {0, 1, 2};
  g.nodes = json::array({{{"mesh", 0}, {"translation", {0, 0, 0}}},
                         {{"mesh", 0}, {"translation", {5, 0, 0}}, {"name", "copy"}}});
  g.scene_nodes = {0, 1};
  Scene s = load(write_gltf(dir + "/i.gltf", g));
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[0].name, "mesh0");  // no node name: the mesh name
  EXPECT_EQ(s.objects[1].name, "copy");
  ASSERT_EQ(s.triangle_count(), 2u);
  EXPECT_EQ(s.corners(1)[1].x, 6.0);
  EXPECT_EQ(s.triangle_object, (std::vector<uint32_t>{0, 1}));
}

TEST(ImportGltf, GlbWithBinChunkLoads) {
  std::string dir = temp_dir("glb_ok");
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.indices = {0, 1, 2};
  g.glb = true;
  EXPECT_EQ(load(write_gltf(dir + "/a.glb", g)).triangle_count(), 1u);
}

TEST(ImportGltf, ImageOnlyRequiredExtensionIsIgnoredButGeometryOneIsRejected) {
  std::string dir = temp_dir("gltf_ext");
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.extensions_required = {"EXT_texture_webp"};
  EXPECT_EQ(load(write_gltf(dir + "/w.gltf", g)).triangle_count(), 1u);
  g.extensions_required = {"KHR_draco_mesh_compression"};
  EXPECT_THROW(load(write_gltf(dir + "/d.gltf", g)), InputError);
}

TEST(ImportGltf, BadInputsThrowInputErrorNamingTheProblem) {
  std::string dir = temp_dir("gltf_bad");
  struct Case {
    const char* name;
    std::function<void(GltfSpec&)> edit;
    const char* expect;
  } cases[] = {
      {"bad_accessor", [](GltfSpec& g) { g.position_accessor = 7; }, "accessor 7"},
      {"bad_view", [](GltfSpec& g) { g.view_length_extra = 400; }, "bufferView 0"},
      {"index_range", [](GltfSpec& g) { g.indices = {0, 1, 9, 0, 1, 12}; },
       "2 indices out of range"},
      {"nan", [](GltfSpec& g) { g.positions[4] = NAN; }, "vertex 1 is not finite"},
      {"bad_component", [](GltfSpec& g) { g.position_component_type = 5124; }, "accessor 0"},
      {"count_overflow", [](GltfSpec& g) { g.position_count_override = 1000; }, "accessor 0"},
  };
  for (auto& c : cases) {
    GltfSpec g;
    g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    g.indices = {0, 1, 2};
    c.edit(g);
    std::string path = write_gltf(dir + "/" + c.name + ".gltf", g);
    try {
      load(path);
      ADD_FAILURE() << c.name << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos)
          << c.name << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(ImportGltf, TruncatedGlbIsReportedWithPath) {
  std::string dir = temp_dir("glb_truncated");
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.indices = {0, 1, 2};
  g.glb = true;
  std::string full = write_gltf(dir + "/full.glb", g);
  std::string bytes = read_bytes(full);
  for (size_t cut : {size_t(3), size_t(15), bytes.size() / 2, bytes.size() - 1}) {
    std::string path = write_text(dir + "/cut.glb", bytes.substr(0, cut));
    try {
      load(path);
      ADD_FAILURE() << "cut at " << cut << ": no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), path);
      EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    }
  }
}

TEST(ImportSpheres, ReadsStatesAndNamesSpheres) {
  std::string dir = temp_dir("spheres_ok");
  std::string path = write_text(dir + "/s.spheres",
                                "# made by hand\nvislib-spheres 1\n\nstates 2\n"
                                "0.5 0 0 0 0 1 0  # rising\n1.5 4 0 0 4 0 0\n");
  Scene s = load(path);
  ASSERT_EQ(s.sphere_count(), 2u);
  EXPECT_EQ(s.state_count(), 2u);
  EXPECT_EQ(s.objects[1].name, "sphere1");
  EXPECT_EQ(s.sphere_center_at(0, 0.5), (Vec3{0, 0.5, 0}));
  EXPECT_EQ(s.sphere_radius[1], 1.5);
  EXPECT_EQ(scene_info(s).spheres, 2u);
}

TEST(ImportSpheres, MalformedLineNamesTheLineNumber) {
  std::string dir = temp_dir("spheres_bad");
  std::string path =
      write_text(dir + "/s.spheres", "vislib-spheres 1\nstates 2\n0.5 0 0 0 0 1 0\n1 2 3\n");
  try {
    load(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 4"), std::string::npos) << e.what();
  }
}

// A `mesh` line adds a static mesh before the spheres (triangles first, then
// spheres); a bad mesh line names the sphere file and its line.
TEST(ImportSpheres, MeshLineAddsAGroundBeforeTheSpheres) {
  std::string dir = temp_dir("spheres_mesh");
  write_text(dir + "/ground.obj",
             "o ground\nv -9 0 -9\nv 9 0 -9\nv 9 0 9\nv -9 0 9\nf 1 3 2\nf 1 4 3\n");
  std::string path = write_text(dir + "/s.spheres",
                                "vislib-spheres 1\nstates 2\nmesh ground.obj\n0.5 0 1 0 0 2 0\n");
  Scene s = load(path);
  EXPECT_EQ(s.triangle_count(), 2u);
  ASSERT_EQ(s.sphere_count(), 1u);
  EXPECT_EQ(s.state_count(), 2u);
  EXPECT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[s.sphere_object[0]].name, "sphere0");
  EXPECT_EQ(s.sphere_center_at(0, 1.0), (Vec3{0, 2, 0}));
  EXPECT_EQ(s.position_at(s.triangles[0][0], 1.0), (Vec3{-9, 0, -9}));
  for (const char* bad : {"mesh missing.obj", "mesh a b", "mesh s.spheres"}) {
    std::string p2 =
        write_text(dir + "/bad.spheres", std::string("vislib-spheres 1\nstates 2\n") + bad + "\n");
    try {
      load(p2);
      ADD_FAILURE() << bad << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.spheres"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
    }
  }
}

TEST(Import, UnsupportedExtensionAndMissingFileThrowInputError) {
  std::string dir = temp_dir("import_misc");
  EXPECT_THROW(load(write_text(dir + "/a.fbx", "x")), InputError);
  EXPECT_THROW(load(dir + "/missing.obj"), InputError);
  EXPECT_THROW(load(dir + "/missing.glb"), InputError);
  EXPECT_THROW(load(dir + "/missing.ply"), InputError);
}

TEST(SceneInfo, CountsDuplicatesNonFiniteAndOutOfRange) {
  Scene s;
  s.positions = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {NAN, 0, 0}}};
  s.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 1, 7}};
  s.triangle_object = {0, 0, 0};
  s.objects = {{"a"}};
  SceneInfo info = scene_info(s);
  EXPECT_EQ(info.duplicate_vertices, 1u);
  EXPECT_EQ(info.nonfinite_vertices, 1u);
  EXPECT_EQ(info.out_of_range_indices, 1u);
  EXPECT_EQ(info.degenerate_triangles, 1u);  // (0,1,3): zero area
  json j = json::parse(to_json(info));
  for (const char* key : {"triangles", "objects", "states", "spheres", "bbox",
                          "degenerate_triangles", "nonfinite_vertices", "duplicate_vertices",
                          "out_of_range_indices", "origin_offset", "far_from_origin"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(ImportMesh, OffKeepsFaceOrder) {
  std::string dir = temp_dir("off_ok");
  std::string path = write_text(
      dir + "/q.off", "OFF\n5 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 2 0\n3 0 1 2\n4 1 3 4 2\n");
  Scene s = load(path);
  ASSERT_EQ(s.triangle_count(), 3u);  // the quad is fan-triangulated
  EXPECT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "q");
  EXPECT_EQ(s.vertex_count(), 5u);
}
