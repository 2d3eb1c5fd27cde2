// import_mesh.cpp: polygon-soup formats, all read by the project's own readers: OBJ below, PLY,
// OFF and STL in vislib/scene/import_{ply,off,stl}.cpp. (OpenMesh's PLY and OFF readers crashed,
// hung or allocated gigabytes on small malformed files.)
//
// Why our own OBJ reader: OpenMesh's OBJ reader drops `g`/`o` statements, so the groups that name
// the objects of a level (Sauerbraten exports one group per material slot) would be lost, and it
// may also drop or split faces that do not fit a manifold half-edge mesh, which changes triangle
// ids and counts. The reader here keeps every face in file order (degenerate faces included, so
// counts match the file), fan-triangulates polygons (v0,v1,v2), (v0,v2,v3), ..., resolves
// negative (relative) indices, accepts `f v`, `f v/vt`, `f v//vn`, `f v/vt/vn`, `v x y z [w or
// r g b]`, and `\` line continuations. Each distinct `g`/`o` name becomes one Object (the latest
// statement names the current object; repeating a name returns to that object); faces before any
// statement go to "default". Vertices keep their file order (vertex i = the i-th `v` line).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <unordered_map>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import_formats.h"

namespace vislib {

namespace {

Scene load_obj(const std::string& path, std::vector<std::string>& warnings) {
  const std::string text = read_file(path);
  Scene scene;
  scene.positions.resize(1);
  auto& pos = scene.positions[0];
  std::unordered_map<std::string, uint32_t> object_of_name;
  std::string current = "default";
  bool has_current = false;
  uint32_t current_obj = 0;
  std::vector<uint32_t> face;
  size_t line_no = 0, skipped = 0;
  auto fail = [&](const std::string& what) {
    throw InputError(path, "line " + std::to_string(line_no) + ": " + what);
  };
  size_t at = 0;
  std::string line;
  while (at < text.size()) {
    // Gather one logical line (joining `\` continuations).
    line.clear();
    while (at < text.size()) {
      size_t end = text.find('\n', at);
      if (end == std::string::npos) end = text.size();
      ++line_no;
      std::string part = text.substr(at, end - at);
      at = end + 1;
      if (!part.empty() && part.back() == '\r') part.pop_back();
      if (!part.empty() && part.back() == '\\') {
        part.back() = ' ';
        line += part;
        continue;
      }
      line += part;
      break;
    }
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const char* p = line.c_str();
    while (*p == ' ' || *p == '\t') ++p;
    const char* kw = p;
    while (*p && *p != ' ' && *p != '\t') ++p;
    std::string key(kw, p);
    if (key == "v") {
      Vec3 v;
      for (int i = 0; i < 3; ++i) {
        char* end = nullptr;
        errno = 0;
        v[i] = std::strtod(p, &end);
        if (end == p) fail("vertex needs 3 numbers");
        p = end;
      }
      if (!is_finite(v))
        fail("vertex " + std::to_string(pos.size()) + " has a non-finite coordinate");
      if (pos.size() >= UINT32_MAX) fail("too many vertices");
      pos.push_back(v);
    } else if (key == "f") {
      face.clear();
      while (true) {
        while (*p == ' ' || *p == '\t') ++p;
        if (!*p) break;
        char* end = nullptr;
        errno = 0;
        long long idx = std::strtoll(p, &end, 10);
        if (end == p || errno == ERANGE) fail("bad face vertex '" + std::string(p) + "'");
        p = end;
        while (*p && *p != ' ' && *p != '\t') {  // skip /vt/vn
          if (*p != '/' && *p != '-' && (*p < '0' || *p > '9')) fail("bad face vertex syntax");
          ++p;
        }
        long long n = (long long)pos.size();
        long long resolved = idx > 0 ? idx - 1 : n + idx;
        if (idx == 0 || resolved < 0 || resolved >= n)
          fail("face index " + std::to_string(idx) + " out of range (" + std::to_string(n) +
               " vertices so far)");
        face.push_back(uint32_t(resolved));
      }
      if (face.size() < 3) {
        ++skipped;
        continue;
      }
      if (!has_current) {
        auto [it, added] = object_of_name.emplace(current, uint32_t(scene.objects.size()));
        if (added) scene.objects.push_back({current});
        current_obj = it->second;
        has_current = true;
      }
      for (size_t i = 1; i + 1 < face.size(); ++i) {
        scene.triangles.push_back({face[0], face[i], face[i + 1]});
        scene.triangle_object.push_back(current_obj);
      }
    } else if (key == "g" || key == "o") {
      while (*p == ' ' || *p == '\t') ++p;
      std::string name(p);
      while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
      current = name.empty() ? "default" : name;
      has_current = false;  // the object is created with its first face
    }
  }
  if (skipped)
    warnings.push_back(path + ": " + std::to_string(skipped) +
                       " face(s) with fewer than 3 vertices skipped");
  return scene;
}

}  // namespace

Scene load_mesh(const std::string& path, std::vector<std::string>& warnings) {
  std::string ext = file_extension(path);
  if (ext == ".obj") return load_obj(path, warnings);
  if (ext == ".ply") return load_ply(path, warnings);
  if (ext == ".off") return load_off(path, warnings);
  if (ext == ".stl") return load_stl(path, warnings);
  throw InputError(path, "not a polygon-soup format (.obj .ply .off .stl)");
}

}  // namespace vislib
