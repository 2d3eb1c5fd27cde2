// scene_subset.h: a scene reduced to a visible set, e.g. to look at one cell's PVS in a glTF
// viewer (pvs inspect --export-gltf).
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/appearance.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The scene reduced to `ids`, read with the one id rule of bake/id_universe.h (sorted or not;
// each < id_universe(scene, granularity): triangle ids, then sphere s as triangle_count() + s, or
// object ids): Triangle keeps exactly those triangles and spheres, Object keeps every triangle and
// sphere of those objects. Objects left without primitives are dropped; the others keep their
// names and their order, and triangles and spheres keep their relative order. Every state's
// positions are kept (unused vertices too: writers such as scene_to_glb write only the vertices an
// object uses).
Scene scene_subset(const Scene& scene, const std::vector<uint32_t>& ids, Granularity granularity);

// The appearance of scene_subset(scene, ids, granularity): `appearance` (aligned with `scene`)
// with the per-triangle materials of the kept triangles; per-vertex data, materials, images and
// copyright are kept whole (vertex ids do not change).
SceneAppearance appearance_subset(const Scene& scene, const SceneAppearance& appearance,
                                  const std::vector<uint32_t>& ids, Granularity granularity);

}  // namespace vislib
