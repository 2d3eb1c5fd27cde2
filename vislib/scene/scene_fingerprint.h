// scene_fingerprint.h: the 64-bit fingerprint a PVS file stores, so that a PVS is never applied
// to another scene (docs/pvs-format.md, "The scene fingerprint", specifies the byte stream).
#pragma once

#include <cstdint>

#include "vislib/scene/scene.h"

namespace vislib {

// FNV-1a 64 over: "vislib-scene-fingerprint-1", the state, vertex, triangle and object counts
// (u64), every vertex position of every state (f64 x, y, z, little-endian) and every triangle's
// three indices and object id (u32). Spheres and names are not included. Deterministic and
// platform-independent; O(size of the scene). Thread-safe.
uint64_t scene_fingerprint(const Scene& scene);

}  // namespace vislib
