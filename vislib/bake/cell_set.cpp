// cell_set.cpp: a cell's visible set read back for its scene.
#include "vislib/bake/cell_set.h"

namespace vislib {

Granularity granularity_of(const pvs::FileInfo& info) {
  return info.granularity == pvs::Granularity::Object ? Granularity::Object : Granularity::Triangle;
}

void check_universe(const std::string& path, const pvs::FileInfo& info, const Scene& scene) {
  const size_t expect =
      granularity_of(info) == Granularity::Object ? scene.objects.size() : scene.triangle_count();
  if (expect != info.universe)
    throw InputError(path, "universe " + std::to_string(info.universe) +
                               " differs from the scene's " + std::to_string(expect));
}

std::vector<uint32_t> visible_triangles(const Scene& scene, const std::vector<uint32_t>& ids,
                                        Granularity granularity) {
  if (granularity == Granularity::Triangle) return ids;
  std::vector<uint8_t> keep(scene.objects.size(), 0);
  for (uint32_t o : ids) keep[o] = 1;
  std::vector<uint32_t> tris;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[scene.triangle_object[t]]) tris.push_back(t);
  return tris;
}

Vec3 view_region_centre(const pvs::CellLayout& layout, uint32_t cell) {
  const pvs::Box region = layout.view_region(cell);
  return {(region.min[0] + region.max[0]) / 2, (region.min[1] + region.max[1]) / 2,
          (region.min[2] + region.max[2]) / 2};
}

}  // namespace vislib
