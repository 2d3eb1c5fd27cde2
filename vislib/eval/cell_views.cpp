// cell_views.cpp: a visible set's frames against the full scene in four horizontal directions.
#include "vislib/eval/cell_views.h"

#include <filesystem>

#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/render.h"

namespace vislib {

std::vector<CellView> render_cell_views(const Scene& scene, const std::vector<uint32_t>& triangles,
                                        Vec3 eye, const std::string& dir, int width, int height,
                                        const CellViewOptions& options) {
  std::filesystem::create_directories(dir);
  const std::vector<uint8_t> mask = triangle_mask(scene.triangle_count(), triangles);
  EmbreeScene rt(scene, 0.0, eye);
  std::vector<CellView> views;
  std::vector<Vec3> dirs = options.forwards;
  if (dirs.empty()) dirs = {{1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}};
  for (size_t k = 0; k < dirs.size(); ++k) {
    Camera cam;
    cam.eye = eye;
    cam.forward = dirs[k];
    cam.vfov_degrees = options.vfov_degrees;
    cam.width = width;
    cam.height = height;
    const Frame truth = render_frame(scene, rt, cam);
    const Frame test = render_frame(scene, rt, cam, mask.data());
    CellView v;
    v.eye = eye;
    v.forward = dirs[k];
    v.quality = frame_quality(truth, test);
    const std::string base = dir + "/view" + std::to_string(k);
    v.full = base + "_full.png";
    v.pvs = base + "_pvs.png";
    v.heat_map = base + "_heat.png";
    write_rgb8_image(v.full, width, height, truth.rgb);
    write_rgb8_image(v.pvs, width, height, test.rgb);
    write_rgb8_image(v.heat_map, width, height, error_heat_map(test, missed_pixels(truth, test)));
    views.push_back(v);
  }
  return views;
}

}  // namespace vislib
