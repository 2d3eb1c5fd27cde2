// view_setup.h: how a near-far view of a cell is set up (pvs view; near-far paper §3, CloVR §3):
// the camera, the default centre O of the cylinders and environment map, and the default radii
// r1, r2 derived from the cell as the runtime's pvs_rt_cell_near_far does (docs/runtime.md).
#pragma once

#include <optional>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/base/vec.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene.h"

namespace vislib {

// A camera at `eye` looking at `target` (which must differ from eye), frame width x height
// pixels; the default up vector unless the view is along it, then up = -z.
Camera look_at_camera(Vec3 eye, Vec3 target, int width, int height);

// The default centre of a cell's view: the centre of its view region (`region_centre`), or, when
// that point is enclosed by the scene (inside a building; cell_free_space), the free sample of
// the region nearest it (`moved` set). None when every sample of the region is enclosed.
struct ViewCentre {
  Vec3 point;
  bool moved = false;
};
std::optional<ViewCentre> default_view_centre(const Scene& scene, const Box3& view_region,
                                              Vec3 region_centre);

// default_view_centre of every cell of `layout` (its view region and that region's centre), in
// cell order: the centres `pvs view` uses, for a client that cannot compute them (the web page
// reads them from `pvs export --centres`). Cost: cells x 17 samples x 14 rays x triangles (the
// brute force of cell_free_space, cells in parallel), so seconds for the city, more for large
// scenes.
std::vector<std::optional<ViewCentre>> default_view_centres(const Scene& scene,
                                                            const pvs::CellLayout& layout);

// Radii of the near and far cylinders about the centre's vertical axis (scene units).
struct NearFarRadii {
  double r1 = 0, r2 = 0;
};
// The default for a cell: r1 = 1.25 max(half the x-z diagonal of `cell_box`, `eye_axis`, 1e-6)
// (eye_axis: the eye's distance from the centre's axis, so that the eye is inside r1), r2 = 2 r1.
NearFarRadii default_near_far_radii(const pvs::Box& cell_box, double eye_axis);

}  // namespace vislib
