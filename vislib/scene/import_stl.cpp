// import_stl.cpp: the project's own STL reader, binary and ASCII, replacing OpenMesh's.
//
// Binary: an 80-byte header, u32 triangle count n (little-endian), n records of 50 bytes (normal,
// 3 vertices as float32 x,y,z, u16 attribute); the file must be exactly 84 + 50 n bytes (a count
// that does not match the size is an error, never an allocation). ASCII: a file starting with
// `solid` that is not a valid binary file: `facet normal ...`, `outer loop`, `vertex x y z`...,
// `endloop`, `endfacet`, ..., `endsolid`; a facet with more than 3 vertices is fan-triangulated.
// Coordinates are float32 (as the format stores them) widened to double. Vertices with identical
// coordinates are merged into one, numbered in order of first appearance (what OpenMesh did, so
// vertex counts match); every facet is kept in file order, degenerate ones included (OpenMesh
// dropped facets it could not add to a half-edge mesh). One object named after the file stem.
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <tuple>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"
#include "vislib/scene/mesh_reader_support.h"

namespace vislib {

namespace {

class VertexMerger {
 public:
  explicit VertexMerger(Scene& scene) : pos_(scene.positions[0]) {}
  uint32_t add(const float p[3]) {
    auto [it, added] = index_.emplace(std::make_tuple(p[0], p[1], p[2]), uint32_t(pos_.size()));
    if (added) pos_.push_back({double(p[0]), double(p[1]), double(p[2])});
    return it->second;
  }

 private:
  std::vector<Vec3>& pos_;
  std::map<std::tuple<float, float, float>, uint32_t> index_;
};

float le_float(const char* p) {
  uint32_t u = uint32_t(uint8_t(p[0])) | uint32_t(uint8_t(p[1])) << 8 |
               uint32_t(uint8_t(p[2])) << 16 | uint32_t(uint8_t(p[3])) << 24;
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

Scene load_binary(const std::string& path, const std::string& b) {
  uint32_t n = uint32_t(uint8_t(b[80])) | uint32_t(uint8_t(b[81])) << 8 |
               uint32_t(uint8_t(b[82])) << 16 | uint32_t(uint8_t(b[83])) << 24;
  if (uint64_t(b.size()) != 84 + 50 * uint64_t(n))
    throw InputError(path, "binary STL: the header declares " + std::to_string(n) + " triangles (" +
                               std::to_string(84 + 50 * uint64_t(n)) +
                               " bytes), but the file has " + std::to_string(b.size()) + " bytes");
  Scene scene = mesh_reader::one_object_scene(path);
  scene.triangles.reserve(n);
  scene.triangle_object.reserve(n);
  VertexMerger merge(scene);
  for (uint32_t t = 0; t < n; ++t) {
    const char* rec = b.data() + 84 + 50 * size_t(t);
    std::array<uint32_t, 3> tri;
    for (int v = 0; v < 3; ++v) {
      float p[3];
      for (int k = 0; k < 3; ++k) p[k] = le_float(rec + 12 + 12 * v + 4 * k);
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        throw InputError(path, "byte " + std::to_string(84 + 50 * size_t(t) + 12 + 12 * v) +
                                   ": triangle " + std::to_string(t) + " has a non-finite vertex");
      tri[size_t(v)] = merge.add(p);
    }
    scene.triangles.push_back(tri);
    scene.triangle_object.push_back(0);
  }
  return scene;
}

Scene load_ascii(const std::string& path, const std::string& t,
                 std::vector<std::string>& warnings) {
  Scene scene = mesh_reader::one_object_scene(path);
  VertexMerger merge(scene);
  size_t at = 0, line = 1;
  std::string tok;
  auto next = [&]() -> bool {
    while (at < t.size() && std::isspace(static_cast<unsigned char>(t[at]))) {
      if (t[at] == '\n') ++line;
      ++at;
    }
    if (at >= t.size()) return false;
    size_t end = at;
    while (end < t.size() && !std::isspace(static_cast<unsigned char>(t[end]))) ++end;
    tok.assign(t, at, std::min<size_t>(end - at, 64));
    at = end;
    return true;
  };
  auto fail = [&](const std::string& what) {
    throw InputError(path, "line " + std::to_string(line) + ": " + what);
  };
  auto skip_line = [&] {
    while (at < t.size() && t[at] != '\n') ++at;
  };
  auto expect = [&](const char* word) {
    if (!next() || tok != word) fail(std::string("expected '") + word + "'");
  };
  if (!next() || tok != "solid") fail("expected 'solid'");
  skip_line();  // the solid's name
  std::vector<uint32_t> face;
  size_t facets = 0, short_facets = 0;
  bool ended = false;
  while (next()) {
    if (tok == "endsolid") {
      ended = true;
      skip_line();
      // Several solids in one file: keep reading.
      continue;
    }
    if (tok == "solid") {
      skip_line();
      continue;
    }
    if (tok != "facet") fail("expected 'facet' or 'endsolid', got '" + tok + "'");
    ended = false;
    skip_line();  // normal nx ny nz
    expect("outer");
    expect("loop");
    face.clear();
    while (true) {
      if (!next()) fail("truncated: the facet has no 'endloop'");
      if (tok == "endloop") break;
      if (tok != "vertex") fail("expected 'vertex' or 'endloop', got '" + tok + "'");
      float p[3];
      for (int k = 0; k < 3; ++k) {
        if (!next()) fail("truncated vertex");
        char* end = nullptr;
        errno = 0;
        p[k] = std::strtof(tok.c_str(), &end);
        if (end != tok.c_str() + tok.size()) fail("'" + tok + "' is not a number");
        if (!std::isfinite(p[k])) fail("non-finite vertex coordinate '" + tok + "'");
      }
      if (face.size() >= 1000000) fail("a facet with more than 10^6 vertices");
      face.push_back(merge.add(p));
    }
    expect("endfacet");
    ++facets;
    if (face.size() < 3)
      ++short_facets;
    else
      mesh_reader::add_fan(scene, face);
  }
  if (!ended && facets > 0) warnings.push_back(path + ": no 'endsolid' at the end of the file");
  if (short_facets)
    warnings.push_back(path + ": " + std::to_string(short_facets) +
                       " facet(s) with fewer than 3 vertices skipped");
  return scene;
}

}  // namespace

Scene load_stl(const std::string& path, std::vector<std::string>& warnings) {
  const std::string bytes = read_file(path);
  Scene scene;
  bool exact_binary = bytes.size() >= 84 && [&] {
    uint32_t n = uint32_t(uint8_t(bytes[80])) | uint32_t(uint8_t(bytes[81])) << 8 |
                 uint32_t(uint8_t(bytes[82])) << 16 | uint32_t(uint8_t(bytes[83])) << 24;
    return uint64_t(bytes.size()) == 84 + 50 * uint64_t(n);
  }();
  // Binary files may start with "solid" too (some exporters write it): a size that matches the
  // triangle count decides.
  if (!exact_binary && bytes.compare(0, 5, "solid") == 0)
    scene = load_ascii(path, bytes, warnings);
  else if (bytes.size() < 84)
    throw InputError(path, "not an STL file: " + std::to_string(bytes.size()) +
                               " bytes, less than a binary STL header, and no 'solid' keyword");
  else
    scene = load_binary(path, bytes);
  if (scene.triangles.empty()) warnings.push_back(path + ": no faces");
  return scene;
}

}  // namespace vislib
