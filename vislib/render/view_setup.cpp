// view_setup.cpp: the camera, centre and radii of a near-far view of a cell.
#include "vislib/render/view_setup.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cassert>
#include <cmath>

#include "vislib/bake/cell_set.h"
#include "vislib/bake/free_space.h"
#include "vislib/bake/view_cells.h"

namespace vislib {

Camera look_at_camera(Vec3 eye, Vec3 target, int width, int height) {
  assert(length(target - eye) > 0);
  Camera cam;
  cam.eye = eye;
  cam.forward = target - eye;
  if (length(cross(cam.forward, cam.up)) == 0) cam.up = {0, 0, -1};
  cam.width = width;
  cam.height = height;
  return cam;
}

std::optional<ViewCentre> default_view_centre(const Scene& scene, const Box3& view_region,
                                              Vec3 region_centre) {
  const CellFreeSpace fs = cell_free_space(scene, view_region);
  if (!fs.centre_enclosed) return ViewCentre{region_centre, false};
  if (!fs.free_point) return std::nullopt;
  return ViewCentre{*fs.free_point, true};
}

std::vector<std::optional<ViewCentre>> default_view_centres(const Scene& scene,
                                                            const pvs::CellLayout& layout) {
  // Cells are independent and each writes its own slot: the same result for any thread count.
  std::vector<std::optional<ViewCentre>> out(layout.cell_count());
  tbb::parallel_for(uint32_t(0), layout.cell_count(), [&](uint32_t c) {
    out[c] =
        default_view_centre(scene, to_box3(layout.view_region(c)), view_region_centre(layout, c));
  });
  return out;
}

NearFarRadii default_near_far_radii(const pvs::Box& cell_box, double eye_axis) {
  const double half_diagonal =
      0.5 * std::hypot(cell_box.max[0] - cell_box.min[0], cell_box.max[2] - cell_box.min[2]);
  const double r1 = 1.25 * std::max({half_diagonal, eye_axis, 1e-6});
  return {r1, 2 * r1};
}

}  // namespace vislib
