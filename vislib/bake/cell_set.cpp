// cell_set.cpp: a cell's visible set read back for its scene.
#include "vislib/bake/cell_set.h"

#include "vislib/bake/id_universe.h"

namespace vislib {

Granularity granularity_of(const pvs::FileInfo& info) {
  return info.granularity == pvs::Granularity::Object ? Granularity::Object : Granularity::Triangle;
}

void check_universe(const std::string& path, const pvs::FileInfo& info, const Scene& scene) {
  const uint32_t expect = id_universe(scene, granularity_of(info));  // the bake's one id rule
  if (expect != info.universe)
    throw InputError(path, "universe " + std::to_string(info.universe) +
                               " differs from the scene's " + std::to_string(expect));
}

std::vector<uint32_t> visible_triangles(const Scene& scene, const std::vector<uint32_t>& ids,
                                        Granularity granularity) {
  return primitives_of(scene, granularity, ids).triangles;
}

Vec3 view_region_centre(const pvs::CellLayout& layout, uint32_t cell) {
  const pvs::Box region = layout.view_region(cell);
  return {(region.min[0] + region.max[0]) / 2, (region.min[1] + region.max[1]) / 2,
          (region.min[2] + region.max[2]) / 2};
}

}  // namespace vislib
