// Tests of `pvs info` and `pvs export`: exit codes and messages on bad input, JSON output, and the
// export round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <tuple>

#include "tests/import_test_files.h"
#include "tests/test_support.h"
#include "vislib/scene/import.h"

using namespace vislib_test;
using json = nlohmann::json;

namespace {

GltfSpec triangle() {
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.indices = {0, 1, 2};
  return g;
}

// `pvs info PATH` must fail with exit code 2 and a message naming the file and containing `what`.
void expect_bad_input(const std::string& path, const std::string& what) {
  std::string out;
  int code = run_pvs("info '" + path + "'", &out);
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find(path), std::string::npos) << out;
  EXPECT_NE(out.find(what), std::string::npos) << out;
}

}  // namespace

TEST(CliInfo, BadInputsExitWithCode2AndNameTheFile) {
  std::string dir = temp_dir("cli_bad");
  expect_bad_input(dir + "/missing.gltf", "cannot open");
  GltfSpec g = triangle();
  g.glb = true;
  std::string glb = read_bytes(write_gltf(dir + "/full.glb", g));
  expect_bad_input(write_text(dir + "/truncated.glb", glb.substr(0, glb.size() - 10)), "truncated");
  g = triangle();
  g.position_accessor = 5;
  expect_bad_input(write_gltf(dir + "/accessor.gltf", g), "accessor 5");
  g = triangle();
  g.view_length_extra = 64;
  expect_bad_input(write_gltf(dir + "/view.gltf", g), "bufferView 0");
  g = triangle();
  g.indices = {0, 1, 3};
  expect_bad_input(write_gltf(dir + "/index.gltf", g), "1 indices out of range");
  g = triangle();
  g.positions[8] = INFINITY;
  expect_bad_input(write_gltf(dir + "/inf.gltf", g), "vertex 2 is not finite");
  expect_bad_input(write_text(dir + "/nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
                   "line 2");
  expect_bad_input(write_text(dir + "/scene.fbx", "Kaydara"), "unsupported file format '.fbx'");
  expect_bad_input(write_text(dir + "/s.spheres", "vislib-spheres 1\nstates 1\n1 0 0\n"), "line 3");
  expect_bad_input(write_text(dir + "/garbage.glb", "glTF\x02\0\0\0garbage-garbage-garbage"),
                   "glb");
  expect_bad_input(write_text(dir + "/garbage.gltf", "{ not json"), "invalid JSON");
}

TEST(CliInfo, JsonReportsCountsAndBox) {
  std::string dir = temp_dir("cli_json");
  std::string path = write_gltf(dir + "/t.gltf", triangle());
  std::string out;
  ASSERT_EQ(run_pvs("info --json '" + path + "'", &out), 0) << out;
  json j = json::parse(out);
  EXPECT_EQ(j["triangles"], 1);
  EXPECT_EQ(j["objects"], 1);
  EXPECT_EQ(j["states"], 1);
  EXPECT_EQ(j["bbox"]["max"][0], 1.0);
  EXPECT_EQ(j["degenerate_triangles"], 0);
}

TEST(CliInfo, CountsSeeThroughFromBlendAndMaskMaterialsAndNamePatterns) {
  std::string dir = temp_dir("cli_see_through");
  // A MASK material without a texture or vertex colours has its factor's alpha (1) everywhere,
  // above the cutoff: no hole, opaque. With a texture its alpha may fall below: see-through.
  for (const auto& [mode, textured, expect] :
       {std::tuple{"OPAQUE", false, 0}, std::tuple{"BLEND", false, 1}, std::tuple{"MASK", false, 0},
        std::tuple{"MASK", true, 1}}) {
    GltfSpec g = triangle();
    g.alpha_mode = mode;
    g.base_color_texture = textured;
    std::string out;
    const std::string path = write_gltf(dir + "/" + mode + (textured ? "_tex" : "") + ".gltf", g);
    ASSERT_EQ(run_pvs("info --json '" + path + "'", &out), 0) << out;
    json j = json::parse(out.substr(out.find('{')));
    EXPECT_EQ(j["see_through_triangles"], expect) << mode << textured;
    EXPECT_EQ(j["see_through_objects"], expect) << mode << textured;
  }
  const std::string obj = write_text(dir + "/groups.obj",
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\no glass_a\nf 1 2 3\nf 1 3 2\n"
                                     "o wall\nf 1 2 3\no *water\nf 2 3 1\n");
  std::string out;
  ASSERT_EQ(run_pvs("info --json --see-through 'glass*,[*]*' '" + obj + "'", &out), 0) << out;
  json j = json::parse(out.substr(out.find('{')));
  EXPECT_EQ(j["see_through_triangles"], 3);
  EXPECT_EQ(j["see_through_objects"], 2);
  ASSERT_EQ(run_pvs("info --see-through glass_a '" + obj + "'", &out), 0) << out;
  EXPECT_NE(out.find("2 triangles in 1 objects"), std::string::npos) << out;
  // A pattern that matches nothing is an error naming it.
  EXPECT_EQ(run_pvs("info --see-through 'nothing*' '" + obj + "'", &out), 2) << out;
  EXPECT_NE(out.find("nothing*"), std::string::npos) << out;
}

// A model whose every triangle is see-through (one BLEND material, as many exports are) is
// warned about, naming the share, the material and the option; --opaque by material or by
// object name keeps it opaque and silences the warning; a pattern matching nothing is an error.
TEST(CliInfo, MostlySeeThroughSceneWarnsAndOpaqueKeepsItOpaque) {
  std::string dir = temp_dir("cli_opaque");
  GltfSpec g = triangle();
  g.alpha_mode = "BLEND";
  g.nodes = json::array({{{"mesh", 0}, {"name", "diorama"}}});
  const std::string path = write_gltf(dir + "/blend.gltf", g);
  std::string out;
  ASSERT_EQ(run_pvs("info '" + path + "'", &out), 0) << out;
  EXPECT_NE(out.find("1 of 1 triangles (100.0%) are see-through"), std::string::npos) << out;
  EXPECT_NE(out.find("'mat0'"), std::string::npos) << out;
  EXPECT_NE(out.find("--opaque"), std::string::npos) << out;
  for (const char* pattern : {"mat0", "dio*"}) {
    ASSERT_EQ(run_pvs("info --json --opaque '" + std::string(pattern) + "' '" + path + "'", &out),
              0)
        << out;
    EXPECT_EQ(out.find("see-through, by"), std::string::npos) << out;
    EXPECT_EQ(json::parse(out.substr(out.find('{')))["see_through_triangles"], 0) << pattern;
  }
  EXPECT_EQ(run_pvs("info --opaque 'nothing*' '" + path + "'", &out), 2) << out;
  EXPECT_NE(out.find("nothing*"), std::string::npos) << out;
  // The bake says it too.
  ASSERT_EQ(
      run_pvs("bake '" + path + "' --box 0,0,0,1,1,1 --grid 1,1,1 --res 8 -o '" + dir + "/b.pvs'",
              &out),
      0)
      << out;
  EXPECT_NE(out.find("are see-through"), std::string::npos) << out;
}

TEST(CliInfo, SharedScenesReportTheReadmeTriangleCounts) {
  VISLIB_REQUIRE_SHARED(shared);
  std::string out;
  ASSERT_EQ(run_pvs("info --json " + shared + "/scenes/sauer_fdm6/fdm6.obj", &out), 0) << out;
  EXPECT_EQ(json::parse(out)["triangles"], 9779);
  ASSERT_EQ(
      run_pvs("info --json --states 5 " + shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf",
              &out),
      0);
  EXPECT_EQ(json::parse(out)["states"], 5);
  EXPECT_EQ(json::parse(out)["dynamic"], true);
}

TEST(CliExport, RoundTripKeepsTrianglesObjectsAndExactCoordinates) {
  std::string dir = temp_dir("cli_export");
  GltfSpec g = triangle();
  g.positions = {0.1f, 1e-7f, 12345.678f, 1, 0, 0, 0, 1, 0};
  g.nodes = json::array({{{"mesh", 0}, {"name", "a"}, {"rotation", {0.1, 0.2, 0.3, 0.927}}},
                         {{"mesh", 0}, {"name", "b"}, {"translation", {1e5, 0.3, 0}}}});
  g.scene_nodes = {0, 1};
  std::string in = write_gltf(dir + "/in.gltf", g), out_obj = dir + "/flat.obj";
  std::string out;
  ASSERT_EQ(run_pvs("export '" + in + "' -o '" + out_obj + "'", &out), 0) << out;
  vislib::Scene a = vislib::load_scene(in), b = vislib::load_scene(out_obj);
  ASSERT_EQ(a.triangle_count(), b.triangle_count());
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangle_object, b.triangle_object);
  ASSERT_EQ(b.objects.size(), 2u);
  EXPECT_EQ(b.objects[1].name, "b");
  EXPECT_EQ(a.positions, b.positions);  // %.17g: bit-exact
  ASSERT_EQ(run_pvs("info --json '" + out_obj + "'", &out), 0) << out;
  EXPECT_EQ(json::parse(out)["triangles"], 2);
}

TEST(CliExport, SpheresGoBesideTheObjAndRoundTrip) {
  std::string dir = temp_dir("cli_export_spheres");
  std::string in = write_text(
      dir + "/s.spheres", "vislib-spheres 1\nstates 2\n0.25 0.1 0.2 0.3 1 2 3\n2 0 0 0 0 0 1e-9\n");
  std::string out;
  ASSERT_EQ(run_pvs("export '" + in + "' -o '" + dir + "/o.obj'", &out), 0) << out;
  vislib::Scene a = vislib::load_scene(in), b = vislib::load_scene(dir + "/o.obj.spheres");
  EXPECT_EQ(a.sphere_radius, b.sphere_radius);
  EXPECT_EQ(a.sphere_centers, b.sphere_centers);
  ASSERT_EQ(run_pvs("export '" + in + "' -o '" + dir + "/t.obj' --time 0.5", &out), 0) << out;
  vislib::Scene c = vislib::load_scene(dir + "/t.obj.spheres");
  ASSERT_EQ(c.state_count(), 1u);
  EXPECT_EQ(c.sphere_centers[0][0], a.sphere_center_at(0, 0.5));
}

TEST(CliExport, TimeSamplesTheAnimation) {
  VISLIB_REQUIRE_SHARED(shared);
  std::string dir = temp_dir("cli_export_time");
  std::string in = shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf", out;
  ASSERT_EQ(run_pvs("export '" + in + "' --states 5 --time 0.5 -o '" + dir + "/m.obj'", &out), 0)
      << out;
  vislib::LoadOptions o;
  o.states = 5;
  vislib::Scene a = vislib::load_scene(in, o), b = vislib::load_scene(dir + "/m.obj");
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  for (uint32_t v = 0; v < a.vertex_count(); ++v)
    ASSERT_EQ(a.position_at(v, 0.5), b.positions[0][v]);
}

TEST(CliExport, GlbKeepsTheIdOrderAndRefusesObjectsOutOfIdOrder) {
  std::string dir = temp_dir("cli_export_glb");
  const std::string verts = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  // Objects a, a, b, c, c in id order: the GLB's meshes in order give the ids back.
  std::string in = write_text(dir + "/in.obj", verts +
                                                   "o a\nf 1 2 3\nf 1 2 4\no b\nf 2 3 4\n"
                                                   "o c\nf 1 3 4\nf 3 2 1\n");
  std::string out;
  ASSERT_EQ(run_pvs("export '" + in + "' -o '" + dir + "/s.glb'", &out), 0) << out;
  vislib::Scene a = vislib::load_scene(in), b = vislib::load_scene(dir + "/s.glb");
  EXPECT_EQ(b.triangle_object, a.triangle_object);
  ASSERT_EQ(b.triangle_count(), a.triangle_count());
  for (uint32_t t = 0; t < a.triangle_count(); ++t)
    EXPECT_EQ(b.corners(t, 0), a.corners(t, 0)) << "triangle " << t;
  // Object a again after b: reading the meshes in order would not give the ids.
  std::string bad =
      write_text(dir + "/bad.obj", verts + "o a\nf 1 2 3\no b\nf 2 3 4\no a\nf 1 3 4\n");
  EXPECT_EQ(run_pvs("export '" + bad + "' -o '" + dir + "/bad.glb'", &out), 2) << out;
  EXPECT_NE(out.find("not in id order"), std::string::npos) << out;
  EXPECT_NE(out.find(bad), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad.glb"));
}
