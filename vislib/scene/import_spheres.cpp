// import_spheres.cpp: the sphere text format (docs/sphere-format.md).
//   vislib-spheres 1
//   states K
//   mesh PATH                                                 (any number, after 'states')
//   radius x0 y0 z0 [x1 y1 z1 ... x(K-1) y(K-1) z(K-1)]      (one line per sphere)
// '#' starts a comment (to end of line); blank lines are ignored. Sphere i is Object "sphere<i>".
// A `mesh` line adds a static mesh file (any other format, PATH relative to this file's folder):
// its triangles and objects come first, in line order, then the spheres (the paper's bouncing
// spheres over a ground).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/import.h"
#include "vislib/scene/import_formats.h"

namespace vislib {

namespace {

// Splits a line (comment removed) into whitespace-separated tokens.
std::vector<std::string> tokens_of(std::string line) {
  auto hash = line.find('#');
  if (hash != std::string::npos) line.resize(hash);
  std::istringstream ss(line);
  std::vector<std::string> out;
  std::string t;
  while (ss >> t) out.push_back(t);
  return out;
}

bool parse_double(const std::string& s, double& v) {
  errno = 0;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && !s.empty() && errno != ERANGE && std::isfinite(v);
}

}  // namespace

Scene load_spheres(const std::string& path, std::vector<std::string>& warnings) {
  std::istringstream in(read_file(path));
  Scene scene;
  std::string line;
  size_t line_no = 0;
  int stage = 0;  // 0: expect magic, 1: expect states, 2: spheres
  size_t K = 0;
  std::vector<Scene> meshes;
  auto fail = [&](const std::string& what) {
    throw InputError(path, "line " + std::to_string(line_no) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    auto tok = tokens_of(line);
    if (tok.empty()) continue;
    if (stage == 0) {
      if (tok.size() != 2 || tok[0] != "vislib-spheres")
        fail("expected the header 'vislib-spheres 1'");
      if (tok[1] != "1") fail("unsupported sphere format version '" + tok[1] + "' (this reader knows 1)");
      stage = 1;
    } else if (stage == 1) {
      char* end = nullptr;
      long k = tok.size() == 2 && tok[0] == "states" ? std::strtol(tok[1].c_str(), &end, 10) : 0;
      if (k < 1 || k > 1000000 || !end || *end) fail("expected 'states K' with K >= 1");
      K = size_t(k);
      scene.sphere_centers.resize(K);
      stage = 2;
    } else if (tok[0] == "mesh") {
      if (tok.size() != 2) fail("expected 'mesh PATH' (one path without spaces)");
      std::filesystem::path mp(tok[1]);
      if (mp.is_relative()) mp = std::filesystem::path(path).parent_path() / mp;
      if (mp.extension() == ".spheres")
        fail("a mesh line cannot name a sphere file ('" + tok[1] + "')");
      try {
        meshes.push_back(load_scene(mp.string(), LoadOptions{}, &warnings));
      } catch (const InputError& e) {
        fail("mesh '" + tok[1] + "': " + e.what());
      }
      if (meshes.back().is_dynamic())
        fail("mesh '" + tok[1] + "' is animated; only static meshes can be added");
    } else {
      if (tok.size() != 1 + 3 * K)
        fail("expected " + std::to_string(1 + 3 * K) + " numbers (radius and " + std::to_string(K) +
             " centres), got " + std::to_string(tok.size()));
      std::vector<double> v(tok.size());
      for (size_t i = 0; i < tok.size(); ++i)
        if (!parse_double(tok[i], v[i])) fail("'" + tok[i] + "' is not a finite number");
      if (!(v[0] > 0)) fail("radius must be > 0, got " + tok[0]);
      size_t id = scene.sphere_radius.size();
      if (id >= UINT32_MAX) fail("too many spheres");
      scene.sphere_radius.push_back(v[0]);
      for (size_t k = 0; k < K; ++k)
        scene.sphere_centers[k].push_back({v[1 + 3 * k], v[2 + 3 * k], v[3 + 3 * k]});
      scene.sphere_object.push_back(uint32_t(scene.objects.size()));
      scene.objects.push_back({"sphere" + std::to_string(id)});
    }
  }
  if (stage == 0) throw InputError(path, "empty file: expected the header 'vislib-spheres 1'");
  if (stage == 1) throw InputError(path, "missing the 'states K' line after the header");
  if (scene.sphere_radius.empty()) warnings.push_back(path + ": no spheres");
  if (meshes.empty()) return scene;
  Scene out = std::move(meshes[0]);
  for (size_t m = 1; m < meshes.size(); ++m) append_scene(out, meshes[m]);
  append_scene(out,
               scene);  // triangles first, then the spheres: the one id rule (bake/id_universe.h)
  return out;
}

}  // namespace vislib
