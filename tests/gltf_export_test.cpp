// Tests of the glTF export of a visible set (pvs inspect --export-gltf): what a
// viewer needs survives (materials, textures, normals, UVs, copyright), the triangles come back
// in order, and the Khronos glTF validator finds no error in the export of every shared scene.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "tests/scene_builders.h"
#include "tests/test_support.h"
#include "vislib/bake/scene_subset.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/appearance.h"
#include "vislib/scene/import.h"
#include "vislib/scene/write_gltf.h"

using namespace vislib;

namespace {

// Every other triangle: a visible set that cuts through objects and material runs.
std::vector<uint32_t> every_other(const Scene& s) {
  std::vector<uint32_t> ids;
  for (uint32_t t = 0; t < s.triangle_count(); t += 2) ids.push_back(t);
  return ids;
}

tinygltf::Model parse_glb(const std::string& bytes) {
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int,
                           const unsigned char*, int, void*) { return true; },
                        nullptr);
  tinygltf::Model m;
  std::string err, warn;
  EXPECT_TRUE(loader.LoadBinaryFromMemory(&m, &err, &warn,
                                          reinterpret_cast<const unsigned char*>(bytes.data()),
                                          unsigned(bytes.size())))
      << err;
  return m;
}

// The shared scene files, or empty.
std::vector<std::string> shared_scene_files(const std::string& shared) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(shared + "/scenes")) {
    std::string ext = file_extension(e.path().string());
    if (ext == ".glb" || ext == ".gltf" || ext == ".obj") out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Runs scripts/gltf-validate.js; returns its exit code (3: validator absent, 127: no node).
int validate(const std::string& file, std::string* report) {
  std::string cmd = "NODE_PATH=\"$(npm root -g 2>/dev/null)\" node " + vislib_test::source_dir() +
                    "/scripts/gltf-validate.js '" + file + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return 127;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) report->append(buf, n);
  int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 2;
}

}  // namespace

TEST(GltfExport, FoxKeepsCopyrightMaterialTextureAndUvs) {
  VISLIB_REQUIRE_SHARED(shared);
  const std::string fox = shared + "/scenes/khronos_fox/Fox.glb";
  Scene scene = load_scene(fox);
  SceneAppearance app = load_appearance(fox);
  EXPECT_NE(app.copyright.find("CC-BY 4.0"), std::string::npos) << app.copyright;
  ASSERT_EQ(app.normals.size(), scene.vertex_count());
  ASSERT_EQ(app.triangle_material.size(), scene.triangle_count());
  ASSERT_FALSE(app.materials.empty());
  ASSERT_GE(app.materials[0].base_color_image, 0);
  EXPECT_FALSE(app.images[size_t(app.materials[0].base_color_image)].bytes.empty());
  // Fox.glb has no NORMAL attribute: every normal is NaN (absent), so none is exported.
  for (const Vec3& n : app.normals)
    ASSERT_TRUE(std::isnan(n.x) && std::isnan(n.y) && std::isnan(n.z));

  std::vector<uint32_t> ids = every_other(scene);
  Scene sub = scene_subset(scene, ids, Granularity::Triangle);
  SceneAppearance sub_app = appearance_subset(scene, app, ids, Granularity::Triangle);
  std::string glb = scene_to_glb(sub, &sub_app);
  EXPECT_EQ(glb, scene_to_glb(sub, &sub_app));  // deterministic
  tinygltf::Model m = parse_glb(glb);
  EXPECT_EQ(m.asset.copyright, app.copyright);
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].pbrMetallicRoughness.baseColorTexture.index, 0);
  ASSERT_EQ(m.images.size(), 1u);
  EXPECT_GE(m.images[0].bufferView, 0);
  EXPECT_EQ(m.images[0].mimeType, app.images[size_t(app.materials[0].base_color_image)].mime_type);
  ASSERT_EQ(m.meshes.size(), 1u);
  for (const auto& p : m.meshes[0].primitives) {
    EXPECT_FALSE(p.attributes.count("NORMAL"));
    EXPECT_TRUE(p.attributes.count("TEXCOORD_0"));
    EXPECT_EQ(p.material, 0);
  }
  // The kept triangles come back in order (positions rounded to float).
  std::string path = vislib_test::temp_dir("gltf_export") + "/fox_half.glb";
  write_file_atomic(path, glb);
  Scene back = load_scene(path);
  ASSERT_EQ(back.triangle_count(), ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    auto a = scene.corners(ids[i]), b = back.corners(uint32_t(i));
    for (int c = 0; c < 3; ++c)
      ASSERT_LE(length(a[c] - b[c]), 1e-4 * (1 + length(a[c]))) << "triangle " << i;
  }
}

TEST(GltfExport, NormalsAreUnitInWorldSpaceAndExported) {
  VISLIB_REQUIRE_SHARED(shared);
  const std::string box = shared + "/scenes/khronos_boxanimated/BoxAnimated.gltf";
  Scene scene = load_scene(box);
  SceneAppearance app = load_appearance(box);
  ASSERT_EQ(app.normals.size(), scene.vertex_count());
  size_t with = 0;
  for (const Vec3& n : app.normals)
    if (!std::isnan(n.x)) {
      ++with;
      ASSERT_NEAR(length(n), 1.0, 1e-9);
    }
  ASSERT_GT(with, 0u);
  // Each triangle's normals point to the side its winding faces (flat boxes: within 60 degrees).
  size_t agree = 0, checked = 0;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    auto c = scene.corners(t);
    Vec3 f = cross(c[1] - c[0], c[2] - c[0]);
    const Vec3& n = app.normals[scene.triangles[t][0]];
    if (std::isnan(n.x) || !(length(f) > 0)) continue;
    ++checked;
    agree += dot(f, n) > 0.5 * length(f);
  }
  EXPECT_GT(checked, 0u);
  EXPECT_EQ(agree, checked);
  std::vector<uint32_t> ids = every_other(scene);
  Scene sub = scene_subset(scene, ids, Granularity::Triangle);
  SceneAppearance sub_app = appearance_subset(scene, app, ids, Granularity::Triangle);
  tinygltf::Model m = parse_glb(scene_to_glb(sub, &sub_app));
  size_t with_normals = 0;
  for (const auto& mesh : m.meshes)
    for (const auto& p : mesh.primitives) with_normals += p.attributes.count("NORMAL");
  EXPECT_GT(with_normals, 0u);
}

TEST(GltfExport, MaterialRunsBecomePrimitivesAndOrderIsKept) {
  // One object, materials 0 0 1 0 by triangle: three primitives (runs), triangles in id order.
  Scene s;
  for (int i = 0; i < 4; ++i)
    vislib_test::add_quad(s, {double(i), 0, 0}, {double(i) + 1, 0, 0}, {double(i) + 1, 1, 0},
                          {double(i), 1, 0});
  for (auto& o : s.triangle_object) o = 0;
  s.objects.resize(1);
  SceneAppearance app;
  app.materials.resize(2);
  app.materials[1].base_color = {1, 0, 0, 1};
  app.triangle_material = {0, 0, 0, 0, 1, 1, 0, 0};
  app.copyright = "test copyright";
  std::string glb = scene_to_glb(s, &app);
  tinygltf::Model m = parse_glb(glb);
  ASSERT_EQ(m.meshes.size(), 1u);
  ASSERT_EQ(m.meshes[0].primitives.size(), 3u);
  EXPECT_EQ(m.meshes[0].primitives[0].material, 0);
  EXPECT_EQ(m.meshes[0].primitives[1].material, 1);
  EXPECT_EQ(m.meshes[0].primitives[2].material, 0);
  EXPECT_EQ(m.materials[1].pbrMetallicRoughness.baseColorFactor, (std::vector<double>{1, 0, 0, 1}));
  EXPECT_EQ(m.asset.copyright, "test copyright");
  std::string path = vislib_test::temp_dir("gltf_export") + "/runs.glb";
  write_file_atomic(path, glb);
  Scene back = load_scene(path);
  ASSERT_EQ(back.triangle_count(), s.triangle_count());
  for (uint32_t t = 0; t < s.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(back.corners(t)[c], s.corners(t)[c]);
}

TEST(GltfExport, DataUriImageIsEmbedded) {
  // A .gltf whose base colour image is a data: URI (here the 8 bytes of the PNG signature: the
  // export carries bytes, it does not decode them). tinygltf keeps no URI for it, so the bytes
  // must come from the document.
  const std::string gltf = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "tri", "mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
    "materials": [{"name": "m", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}],
    "images": [{"uri": "data:image/png;base64,iVBORw0KGgo="}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}]})";
  const std::string path = vislib_test::temp_dir("gltf_export") + "/data_uri.gltf";
  write_file_atomic(path, gltf);
  const Scene s = load_scene(path);
  const SceneAppearance app = load_appearance(path);
  ASSERT_EQ(app.images.size(), 1u);
  EXPECT_EQ(app.images[0].bytes, std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(app.images[0].mime_type, "image/png");
  ASSERT_EQ(app.materials.size(), 1u);
  EXPECT_EQ(app.materials[0].base_color_image, 0);
  const tinygltf::Model m = parse_glb(scene_to_glb(s, &app));
  ASSERT_EQ(m.images.size(), 1u);
  EXPECT_GE(m.images[0].bufferView, 0);
  EXPECT_EQ(m.images[0].mimeType, "image/png");
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].pbrMetallicRoughness.baseColorTexture.index, 0);
}

TEST(GltfExport, KhronosValidatorFindsNoErrorOnEverySharedScene) {
  VISLIB_REQUIRE_SHARED(shared);
  if (std::system("command -v node > /dev/null 2>&1") != 0) GTEST_SKIP() << "node is not installed";
  const std::string dir = vislib_test::temp_dir("gltf_validate");
  auto files = shared_scene_files(shared);
  ASSERT_FALSE(files.empty());
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    Scene scene = load_scene(f);
    SceneAppearance app = load_appearance(f);
    std::vector<uint32_t> ids = every_other(scene);
    Scene sub = scene_subset(scene, ids, Granularity::Triangle);
    SceneAppearance sub_app = appearance_subset(scene, app, ids, Granularity::Triangle);
    std::string out = dir + "/" + std::filesystem::path(f).stem().string() + ".glb";
    write_file_atomic(out, scene_to_glb(sub, &sub_app));
    std::string report;
    int rc = validate(out, &report);
    if (rc == 3 || rc == 127) GTEST_SKIP() << "the glTF validator is not installed: " << report;
    EXPECT_EQ(rc, 0) << report;
  }
}
