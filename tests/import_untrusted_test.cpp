// Tests of the project's own PLY, OFF and STL readers (vislib/scene/import_{ply,off,stl}.cpp):
// well-formed files in every encoding, the hand-made malformed files in tests/data/malformed, and
// the crash/hang/out-of-memory repros in ../shared/repros (skipped when absent).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "tests/import_test_files.h"
#include "tests/test_support.h"
#include "vislib/base/error.h"
#include "vislib/scene/import.h"

using namespace vislib;
using namespace vislib_test;

namespace {

std::string le32(uint32_t v) {
  return std::string(reinterpret_cast<const char*>(&v), 4);
}
std::string lef(float v) {
  return std::string(reinterpret_cast<const char*>(&v), 4);
}
std::string be(std::string s) {
  return std::string(s.rbegin(), s.rend());
}

std::string ply_header(const char* format, int nv, int nf) {
  return std::string("ply\nformat ") + format + " 1.0\ncomment made by hand\nelement vertex " +
         std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty uchar red\nproperty float z\nelement "
         "face " +
         std::to_string(nf) +
         "\nproperty list uchar int vertex_indices\nproperty int flags\nend_header\n";
}

// The quad (0,1,2,3) and the triangle (1,4,2) as in the OFF test: 3 triangles, 5 vertices.
const float kPts[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, 0}, {2, 2, -1}};

void expect_quad_and_triangle(const Scene& s) {
  ASSERT_EQ(s.vertex_count(), 5u);
  ASSERT_EQ(s.triangle_count(), 3u);
  EXPECT_EQ(s.triangles[0], (std::array<uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(s.triangles[1], (std::array<uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(s.triangles[2], (std::array<uint32_t, 3>{1, 4, 2}));
  for (int v = 0; v < 5; ++v)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.positions[0][size_t(v)][k], double(kPts[v][k]));
  ASSERT_EQ(s.objects.size(), 1u);
}

std::string binary_ply(bool big) {
  auto f = [&](float x) { return big ? be(lef(x)) : lef(x); };
  auto i = [&](uint32_t x) { return big ? be(le32(x)) : le32(x); };
  std::string s = ply_header(big ? "binary_big_endian" : "binary_little_endian", 5, 2);
  for (auto& p : kPts) s += f(p[0]) + f(p[1]) + std::string(1, char(200)) + f(p[2]);
  s += std::string(1, char(4)) + i(0) + i(1) + i(2) + i(3) + i(77);
  s += std::string(1, char(3)) + i(1) + i(4) + i(2) + i(0);
  return s;
}

void expect_input_error(const std::string& path, const std::string& fragment) {
  try {
    load_scene(path);
    FAIL() << path << ": no error";
  } catch (const InputError& e) {
    std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos)
        << "expected '" << fragment << "' in: " << what;
  }
}

}  // namespace

TEST(ImportPly, AsciiSkipsExtraPropertiesAndFanTriangulates) {
  std::string dir = temp_dir("ply_ascii");
  std::string text = ply_header("ascii", 5, 2);
  for (auto& p : kPts)
    text +=
        std::to_string(p[0]) + " " + std::to_string(p[1]) + " 255 " + std::to_string(p[2]) + "\n";
  text += "4 0 1 2 3 9\n3 1 4 2 0\n";
  Scene s = load_scene(write_text(dir + "/m.ply", text));
  expect_quad_and_triangle(s);
  EXPECT_EQ(s.objects[0].name, "m");
}

TEST(ImportPly, BinaryLittleAndBigEndianReadTheSameScene) {
  std::string dir = temp_dir("ply_binary");
  expect_quad_and_triangle(load_scene(write_text(dir + "/le.ply", binary_ply(false))));
  expect_quad_and_triangle(load_scene(write_text(dir + "/be.ply", binary_ply(true))));
}

TEST(ImportPly, OtherElementsAreSkippedInAnyOrder) {
  std::string dir = temp_dir("ply_other");
  std::string text =
      "ply\nformat ascii 1.0\nelement material 2\nproperty list uchar float rgb\nproperty uchar "
      "id\n"
      "element vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
      "element face 1\nproperty list uchar uint vertex_index\nelement edge 1\nproperty int "
      "a\nproperty int b\n"
      "end_header\n3 0.1 0.2 0.3 7\n0 8\n0 0 0\n1 0 0\n0 1 0.25\n3 2 1 0\n0 1\n";
  Scene s = load_scene(write_text(dir + "/o.ply", text));
  ASSERT_EQ(s.triangle_count(), 1u);
  EXPECT_EQ(s.triangles[0], (std::array<uint32_t, 3>{2, 1, 0}));
  EXPECT_EQ(s.positions[0][2].z, 0.25);
}

TEST(ImportPly, CountBeyondTheFileIsRejectedBeforeAllocating) {
  std::string dir = temp_dir("ply_count");
  // 2^31 vertices of 3 floats each in a 200-byte binary file: the check happens on the header.
  std::string text = ply_header("binary_little_endian", 2000000000, 1);
  expect_input_error(write_text(dir + "/big.ply", text), "can hold at most");
}

TEST(ImportPly, HandMadeMalformedFilesGiveInputErrors) {
  const std::string d = source_dir() + "/tests/data/malformed/";
  expect_input_error(d + "ply-count-beyond-file.ply", "element 'vertex' count");
  expect_input_error(d + "ply-binary-truncated.ply", "truncated");
  expect_input_error(d + "ply-misspelt-keyword.ply", "unknown header keyword 'elemnt'");
  expect_input_error(d + "ply-index-out-of-range.ply", "vertex index 7 out of range");
  expect_input_error(d + "ply-unknown-type.ply", "unknown property type 'fl0at'");
  expect_input_error(d + "ply-nan-vertex.ply", "non-finite");
}

TEST(ImportOff, HandMadeMalformedFilesGiveInputErrors) {
  const std::string d = source_dir() + "/tests/data/malformed/";
  expect_input_error(d + "off-count-beyond-file.off", "vertex count");
  expect_input_error(d + "off-index-out-of-range.off", "vertex index 3 out of range");
  expect_input_error(d + "off-truncated.off", "truncated");
}

TEST(ImportOff, CountsOnTheHeaderLineAndCommentsAndColours) {
  std::string dir = temp_dir("off_variants");
  std::string body;
  for (auto& p : kPts)
    body += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) +
            " 0.5 0.5 0.5\n";
  body += "# a comment\n\n4 0 1 2 3 255 0 0\n3 1 4 2\n";
  expect_quad_and_triangle(load_scene(write_text(dir + "/a.off", "COFF 5 2 0\n" + body)));
  expect_quad_and_triangle(
      load_scene(write_text(dir + "/b.off", "OFF\n# counts next\n5 2 0\n" + body)));
}

TEST(ImportStl, BinaryAndAsciiMergeIdenticalVertices) {
  std::string dir = temp_dir("stl");
  // Two triangles sharing the edge (1,0,0)-(0,1,0).
  const float tri[2][3][3] = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  std::string bin = "solid but binary" + std::string(64, ' ') + le32(2);
  std::string ascii = "solid x\n";
  for (auto& t : tri) {
    bin += lef(0) + lef(0) + lef(1);
    ascii += " facet normal 0 0 1\n  outer loop\n";
    for (auto& v : t) {
      bin += lef(v[0]) + lef(v[1]) + lef(v[2]);
      ascii += "   vertex " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " " +
               std::to_string(v[2]) + "\n";
    }
    bin += std::string(2, '\0');
    ascii += "  endloop\n endfacet\n";
  }
  ascii += "endsolid x\n";
  for (const std::string& path :
       {write_text(dir + "/b.stl", bin), write_text(dir + "/a.stl", ascii)}) {
    Scene s = load_scene(path);
    ASSERT_EQ(s.vertex_count(), 4u) << path;
    ASSERT_EQ(s.triangle_count(), 2u) << path;
    EXPECT_EQ(s.triangles[0], (std::array<uint32_t, 3>{0, 1, 2})) << path;
    EXPECT_EQ(s.triangles[1], (std::array<uint32_t, 3>{1, 3, 2})) << path;
  }
}

TEST(ImportStl, HandMadeMalformedFilesGiveInputErrors) {
  const std::string d = source_dir() + "/tests/data/malformed/";
  expect_input_error(d + "stl-count-beyond-file.stl", "declares 100000000 triangles");
  expect_input_error(d + "stl-ascii-short-vertex.stl", "'endloop' is not a number");
}

// The repros crashed (signal 11), hung with memory growing to 3.5 GB, or threw std::bad_alloc
// through OpenMesh's readers. Through `pvs info` each must exit 2 naming the file.
TEST(ImportRepros, SharedReprosExitTwoWithAMessage) {
  VISLIB_REQUIRE_SHARED(shared);
  const std::string dir = shared + "/repros";
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << dir << " is absent";
  int seen = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    std::string name = e.path().filename().string();
    if (!(name.rfind("ply-", 0) == 0 || name == "off-oom.off")) continue;
    ++seen;
    std::string out;
    EXPECT_EQ(run_pvs("info " + e.path().string(), &out), 2) << name << ": " << out;
    EXPECT_NE(out.find(name), std::string::npos) << out;
    EXPECT_THROW(load_scene(e.path().string()), InputError) << name;
  }
  EXPECT_GE(seen, 5);
}

namespace {

// A one-triangle .gltf in `dir` whose buffer is the external file named by `uri`; the buffer's
// bytes are written to `dir/tri.bin`.
std::string gltf_with_uri(const std::string& dir, const std::string& uri) {
  GltfSpec g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string path = write_gltf(dir + "/a.gltf", g);
  nlohmann::json doc = nlohmann::json::parse(read_bytes(path));
  write_text(dir + "/tri.bin", std::string(reinterpret_cast<const char*>(g.positions.data()), 36));
  doc["buffers"][0]["uri"] = uri;
  return write_text(path, doc.dump());
}

void expect_uri_rejected(const std::string& path, const std::string& uri) {
  try {
    load_scene(path);
    FAIL() << uri << ": loaded";
  } catch (const InputError& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("uri '" + uri + "'"), std::string::npos) << what;
    // Nothing about the outside file (its size, its contents) is echoed.
    EXPECT_EQ(what.find("bytes"), std::string::npos) << what;
    EXPECT_EQ(what.find("SECRET"), std::string::npos) << what;
  }
}

}  // namespace

TEST(ImportGltfUris, ExternalBufferInsideTheFolderLoads) {
  std::string dir = temp_dir("gltf_uri_ok");
  std::filesystem::create_directories(dir + "/sub");
  EXPECT_EQ(load_scene(gltf_with_uri(dir, "tri.bin")).triangle_count(), 1u);
  std::filesystem::rename(dir + "/tri.bin", dir + "/sub/t r.bin");
  EXPECT_EQ(load_scene(gltf_with_uri(dir, "sub/t%20r.bin")).triangle_count(), 1u);
}

TEST(ImportGltfUris, UrisLeavingTheAssetFolderAreRejectedWithoutTouchingTheFile) {
  std::string top = temp_dir("gltf_uri_escape");
  std::string dir = top + "/asset";
  std::filesystem::create_directories(dir);
  write_text(top + "/secret.bin", std::string(36, 'S') + "SECRET");
  for (std::string uri :
       std::vector<std::string>{"../secret.bin", "%2e%2e/secret.bin", "sub/../../secret.bin",
                                top + "/secret.bin", "../../../../../../../../etc/hostname"})
    expect_uri_rejected(gltf_with_uri(dir, uri), uri);
  // A symbolic link inside the folder that points outside it.
  std::filesystem::create_symlink(top + "/secret.bin", dir + "/link.bin");
  expect_uri_rejected(gltf_with_uri(dir, "link.bin"), "link.bin");
  // A symbolic link to a file inside the folder is fine.
  std::filesystem::create_symlink(dir + "/tri.bin", dir + "/inside.bin");
  EXPECT_EQ(load_scene(gltf_with_uri(dir, "inside.bin")).triangle_count(), 1u);
}

TEST(ImportGltfUris, ImageUrisAreCheckedToo) {
  std::string top = temp_dir("gltf_uri_image");
  std::string dir = top + "/asset";
  std::filesystem::create_directories(dir);
  std::string path = gltf_with_uri(dir, "tri.bin");
  nlohmann::json doc = nlohmann::json::parse(read_bytes(path));
  doc["images"] = nlohmann::json::array({{{"uri", "../../etc/passwd"}}});
  write_text(path, doc.dump());
  expect_uri_rejected(path, "../../etc/passwd");
}
