// write_gltf.h: writing a Scene as binary glTF 2.0 (.glb), no extensions, through tinygltf.
#pragma once

#include <string>

#include "vislib/scene/appearance.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Returns the bytes of a GLB file holding the triangles of `scene`:
//  - one root node + mesh per Object, in object order, both named after the object; the mesh has
//    one TRIANGLES primitive per run of consecutive triangles (in id order) of one material (one
//    primitive without `appearance`), uint32 indices and float POSITION (with min/max) over the
//    vertices the primitive uses, numbered by first use. An object without triangles becomes a
//    node without mesh. So importing the file back gives the same triangles in the same order
//    whenever each object's triangles are contiguous in `scene`.
//  - With `appearance` (aligned with `scene`: see appearance.h): NORMAL and TEXCOORD_0 on each
//    primitive whose vertices all have them (finite), the materials the kept triangles use (base
//    colour factor and texture, metallic/roughness, emissive, alpha mode, double-sidedness) with
//    their base colour images embedded in the BIN chunk (PNG/JPEG bytes) or, when the bytes were
//    not read, referenced by the source's URI; and asset.copyright.
//  - K > 1 states: the mesh of every object whose vertices move gets K-1 morph targets (target
//    k-1 = state k minus state 0, as float) and default weights 0, and one animation "states"
//    animates their weights with LINEAR keyframes at t = 0, 1, ..., K-1 seconds, state k at time k
//    (weights: one-hot k-1, all zero at t = 0). Scene time tau in [0,1] is glTF time tau*(K-1).
//    Static objects get no targets.
//  - Spheres are not written (see write_spheres.h).
// Positions are rounded to float: keep coordinates near the origin. Deterministic: same scene,
// same bytes. Throws std::runtime_error if the file would come near the 4 GiB limit of GLB.
// Preconditions: triangle indices < vertex_count(), triangle_object[i] < objects.size().
std::string scene_to_glb(const Scene& scene, const SceneAppearance* appearance = nullptr);

}  // namespace vislib
