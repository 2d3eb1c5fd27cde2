// cell_set.cpp: a cell's visible set read back for its scene.
#include "vislib/bake/cell_set.h"

#include <cassert>
#include <optional>

#include "vislib/bake/id_universe.h"
#include "vislib/bake/view_cells.h"
#include "vislib/scene/scene_fingerprint.h"

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

std::vector<uint32_t> visible_triangles_union(const Scene& scene,
                                              const std::vector<std::vector<uint32_t>>& sets,
                                              Granularity granularity) {
  std::vector<uint8_t> keep(id_universe(scene, granularity), 0);
  for (const std::vector<uint32_t>& set : sets)
    for (uint32_t id : set) {
      assert(id < keep.size());
      keep[id] = 1;
    }
  const bool object = granularity == Granularity::Object;
  std::vector<uint32_t> tris;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t)
    if (keep[object ? scene.triangle_object[t] : t]) tris.push_back(t);
  return tris;
}

PointCell find_point_cell(pvs::Reader& reader, Vec3 p) {
  const double q[3] = {p.x, p.y, p.z};
  const std::optional<uint32_t> c = reader.info().layout.find_cell(q);
  if (!c) return {};
  const bool absent = reader.block_info(*c).encoding == pvs::Encoding::Absent;
  return {absent ? PointCell::Absent : PointCell::Found, *c};
}

CellViewSet read_cell_view_set(const std::string& path, const Scene& scene, Vec3 p) {
  pvs::ReadOptions opt;
  opt.expected_fingerprint = scene_fingerprint(scene);
  return reading_pvs(path, [&] {
    pvs::Reader r = pvs::Reader::from_file(path, opt);
    const pvs::FileInfo& info = r.info();
    check_universe(path, info, scene);
    CellViewSet v;
    v.where = find_point_cell(r, p);
    if (v.where.status != PointCell::Found) return v;
    const uint32_t cell = v.where.cell;
    v.triangles = visible_triangles(scene, r.read_cell(cell), granularity_of(info));
    v.centre = view_region_centre(info.layout, cell);
    v.view_region = to_box3(info.layout.view_region(cell));
    v.box = info.layout.cell_box(cell);
    return v;
  });
}

}  // namespace vislib
