// import.h: loading scenes from files. The I/O boundary: bad files throw vislib::InputError with
// the path and what is wrong (accessor index, line number, byte offset); nothing else is thrown
// for bad data, and no input makes it crash.
//
// Formats, chosen by extension (case-insensitive):
//   .gltf .glb        glTF 2.0 (import_gltf.cpp)
//   .obj .ply .off .stl  our own readers (import_mesh.cpp, scene/import_{ply,off,stl}.cpp); every
//                     count in a header is checked against the file size before allocating
//   .spheres          the sphere text format of docs/sphere-format.md (import_spheres.cpp)
//   .bsp              compiled Quake maps, BSP29, BSP2 and 2PSB (import_bsp.cpp, quake_bsp.h)
#pragma once

#include <string>

#include "vislib/scene/scene.h"

namespace vislib {

// Quake maps: which brush models become triangles.
enum class BspModels {
  world,  // model 0 only (the world; what the compiler's vis treats as occluding)
  all,    // every model in model order (doors, lifts, triggers too)
};
// Quake maps: what becomes of faces with a '*' texture (water, slime, lava, teleporters).
enum class BspLiquids {
  opaque,       // ordinary triangles: they occlude
  omit,         // left out of the scene
  see_through,  // kept, on see-through objects (Object::see_through): seen but not occluding
};

struct LoadOptions {
  // Key states to sample node animations into (glTF). 1 = the rest pose only. Must be >= 1.
  int states = 1;
  // glTF: index of the animation to sample (-1 = all animations together, on a common clock).
  int animation = -1;
  // .bsp: brush models and liquid faces (docs/scene-model.md).
  BspModels bsp_models = BspModels::world;
  BspLiquids bsp_liquids = BspLiquids::opaque;
};

// Loads any supported format. Throws InputError on a missing, unreadable, malformed or
// unsupported file. Warnings (skipped primitives etc.) are appended to `warnings` if given.
Scene load_scene(const std::string& path, const LoadOptions& options = {},
                 std::vector<std::string>* warnings = nullptr);

}  // namespace vislib
