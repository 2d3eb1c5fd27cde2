// cell_views.h: how a visible set looks against the full scene from one eye (pvs inspect
// --render): frames in the four horizontal directions, their quality and error heat maps.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/metrics.h"
#include "vislib/scene/scene.h"

namespace vislib {

struct CellView {
  Vec3 eye, forward;
  FrameQuality quality;             // the visible set's frame against the full scene's
  std::string full, pvs, heat_map;  // the PNG files written
};

// Renders from `eye`, looking along +x, +z, -x, -z (in that order), the full scene and the scene
// reduced to `triangles` (ids < triangle_count()), width x height pixels, and writes
// dir/view<k>_full.png, _pvs.png and _heat.png (dir is created). Deterministic.
std::vector<CellView> render_cell_views(const Scene& scene, const std::vector<uint32_t>& triangles,
                                        Vec3 eye, const std::string& dir, int width, int height);

}  // namespace vislib
