// mesh_reader_support.h: small helpers shared by the project's own PLY, OFF and STL readers
// (import_ply.cpp, import_off.cpp, import_stl.cpp). Internal to vislib.
//
// The readers never trust a count in a header: before anything is allocated for `count` items
// they check that the bytes left in the file can hold `count` items of the smallest size the
// format allows (bounded_count), so a 75-byte file cannot ask for gigabytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "vislib/base/error.h"
#include "vislib/scene/scene.h"

namespace vislib {
namespace mesh_reader {

// Throws InputError(path, what_desc) unless count * min_bytes <= available (overflow-safe).
// `min_bytes` must be >= 1.
inline void check_count_fits(const std::string& path, const std::string& what, uint64_t count,
                             uint64_t min_bytes, uint64_t available) {
  if (min_bytes == 0) min_bytes = 1;
  if (count > available / min_bytes)
    throw InputError(path, what + ": the header declares " + std::to_string(count) + ", but the " +
                               std::to_string(available) + " bytes after it can hold at most " +
                               std::to_string(available / min_bytes));
}

// A scene with one object named after the file stem, vertices in state 0.
inline Scene one_object_scene(const std::string& path) {
  Scene scene;
  scene.positions.resize(1);
  scene.objects.push_back({std::filesystem::path(path).stem().string()});
  return scene;
}

// Fan-triangulates `face` ((v0,v1,v2), (v0,v2,v3), ...) into object 0.
inline void add_fan(Scene& scene, const std::vector<uint32_t>& face) {
  for (size_t i = 1; i + 1 < face.size(); ++i) {
    scene.triangles.push_back({face[0], face[i], face[i + 1]});
    scene.triangle_object.push_back(0);
  }
}

// The warnings of a PLY or OFF reader at the end: `short_faces` faces of fewer than 3 vertices
// skipped, and a scene without a face.
inline void warn_faces(const std::string& path, size_t short_faces, const Scene& scene,
                       std::vector<std::string>& warnings) {
  if (short_faces)
    warnings.push_back(path + ": " + std::to_string(short_faces) +
                       " face(s) with fewer than 3 vertices skipped");
  if (scene.triangles.empty()) warnings.push_back(path + ": no faces");
}

}  // namespace mesh_reader
}  // namespace vislib
