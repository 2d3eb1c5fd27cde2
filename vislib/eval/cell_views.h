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

// Which views render_cell_views renders: `forwards` the view directions (each with a nonzero
// horizontal part, the camera's up being +y; empty: +x, +z, -x, -z in that order), at a vertical
// field of view of `vfov_degrees` in (0, 180).
struct CellViewOptions {
  std::vector<Vec3> forwards;
  double vfov_degrees = 90;
};

// Renders from `eye`, along each direction of options, the full scene and the scene reduced to
// `triangles` (ids < triangle_count()), width x height pixels, and writes dir/view<k>_full.png,
// _pvs.png and _heat.png (dir is created). Deterministic.
std::vector<CellView> render_cell_views(const Scene& scene, const std::vector<uint32_t>& triangles,
                                        Vec3 eye, const std::string& dir, int width, int height,
                                        const CellViewOptions& options = {});

}  // namespace vislib
