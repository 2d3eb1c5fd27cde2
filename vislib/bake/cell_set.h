// cell_set.h: one cell's visible set read back from a PVS file, for the scene it was baked for
// (pvs inspect, pvs view): the file's universe checked against the scene, object ids expanded to
// the objects' triangles, PVS format errors turned into InputError naming the file.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "vislib/base/error.h"
#include "vislib/base/vec.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The granularity of a PVS file's ids.
Granularity granularity_of(const pvs::FileInfo& info);

// Throws InputError(path, ...) when the file's universe is not the scene's id_universe at the
// file's granularity (bake/id_universe.h: triangles then spheres, or objects).
void check_universe(const std::string& path, const pvs::FileInfo& info, const Scene& scene);

// The triangles of a visible set (primitives_of(...).triangles, bake/id_universe.h): Triangle
// granularity: the triangle ids among `ids` (sphere ids are left out); Object: every triangle of
// those objects, ascending. Ids must be < id_universe(scene, granularity).
std::vector<uint32_t> visible_triangles(const Scene& scene, const std::vector<uint32_t>& ids,
                                        Granularity granularity);

// The triangles of the union of visible sets (each as for visible_triangles; any order,
// duplicates allowed), ascending: the triangles drawn for a view that needs several cells (a
// stereo pair, an ODS viewing disc). Ids must be < id_universe(scene, granularity).
std::vector<uint32_t> visible_triangles_union(const Scene& scene,
                                              const std::vector<std::vector<uint32_t>>& sets,
                                              Granularity granularity);

// Where the visible set of a point lies in a PVS file.
struct PointCell {
  enum Status {
    Found,   // `cell` contains the point and its block is in the file
    NoCell,  // no cell of the layout contains the point
    Absent,  // `cell` contains it but is absent from this file (another shard's)
  };
  Status status = NoCell;
  uint32_t cell = 0;  // unless NoCell
};
// Reads (and checks) only the block of the cell found; throws pvs::FormatError on a corrupt one.
PointCell find_point_cell(pvs::Reader& reader, Vec3 p);

// One cell's visible set for a view from a point (pvs view), read back for its scene.
struct CellViewSet {
  PointCell where;
  std::vector<uint32_t> triangles;  // visible_triangles of the cell's set
  Vec3 centre;                      // of the cell's view region
  Box3 view_region;
  pvs::Box box;  // the cell's lookup box
};
// Opens the PVS file at `path`, requires it to have been baked for `scene` (fingerprint and
// universe, else InputError naming `path`; format errors become InputError too) and reads the set
// of the cell containing `p`. When where.status is not Found, nothing else is filled in.
CellViewSet read_cell_view_set(const std::string& path, const Scene& scene, Vec3 p);

// The centre of a cell's view region (scene units).
Vec3 view_region_centre(const pvs::CellLayout& layout, uint32_t cell);

// Runs f() and returns its result; a pvs::FormatError thrown inside becomes InputError(path, its
// message): the I/O boundary of code that reads the PVS file at `path`.
template <class F>
auto reading_pvs(const std::string& path, F&& f) -> decltype(f()) {
  try {
    return std::forward<F>(f)();
  } catch (const pvs::FormatError& e) {
    throw InputError(path, e.what());
  }
}

}  // namespace vislib
