// import_formats.h: the per-format loaders behind load_scene (import.h). Internal to vislib.
// Each one takes the path (for messages and relative resources) and throws InputError(path, ...)
// on bad data; warnings are appended to `warnings` (never null here).
#pragma once

#include <string>
#include <vector>

#include "vislib/scene/import.h"

namespace vislib {

// glTF 2.0, .gltf or .glb (import_gltf.cpp).
struct SceneAppearance;
// With `appearance`, also fills it (appearance.h).
Scene load_gltf(const std::string& path, const LoadOptions& options,
                std::vector<std::string>& warnings, SceneAppearance* appearance = nullptr);
// OBJ (groups become objects), PLY, OFF, STL by extension (import_mesh.cpp).
Scene load_mesh(const std::string& path, std::vector<std::string>& warnings);
// PLY ascii / binary little and big endian (vislib/scene/import_ply.cpp).
Scene load_ply(const std::string& path, std::vector<std::string>& warnings);
// OFF, ASCII (vislib/scene/import_off.cpp).
Scene load_off(const std::string& path, std::vector<std::string>& warnings);
// STL, binary and ASCII (vislib/scene/import_stl.cpp).
Scene load_stl(const std::string& path, std::vector<std::string>& warnings);
// The sphere text format of docs/sphere-format.md (import_spheres.cpp).
Scene load_spheres(const std::string& path, std::vector<std::string>& warnings);

// Compiled Quake maps, .bsp (import_bsp.cpp): the scene of `bsp`, the map read from `path`.
struct QuakeBsp;
Scene load_bsp(const QuakeBsp& bsp, const std::string& path, const LoadOptions& options,
               std::vector<std::string>& warnings);

}  // namespace vislib
