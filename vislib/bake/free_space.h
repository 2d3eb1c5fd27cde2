// free_space.h: points of a view cell that lie inside the geometry.
#pragma once

#include <cstddef>
#include <optional>

#include "vislib/base/vec.h"
#include "vislib/scene/scene.h"

namespace vislib {

// --- Free space ----------------------------------------------------------------------------------
// Walkable cells are columns over floor: a column that straddles a building holds points inside
// it. These functions find such points without Embree (brute force over the triangles, so cost is
// O(triangles) per ray: meant for a few points per cell, not for whole bakes).

// True when `p` is enclosed by the geometry of state `state`: every one of kEnclosureRays fixed
// directions (the 6 axes and 8 diagonals, tilted by fixed small rotations so that no ray runs
// along an edge of an axis-aligned model) hits a triangle, and more than half of the nearest hits
// are back faces (the ray meets the triangle from the side its normal (b-a)x(c-a) points to, the
// inside of a closed, outward-facing solid). A point in a street sees the sky (some ray escapes);
// a point under a bridge or in a tunnel sees front faces. Open or inward-facing models may be
// misjudged either way; degenerate triangles are ignored. Deterministic, thread-safe.
constexpr int kEnclosureRays = 14;
bool point_enclosed(const Scene& scene, Vec3 p, size_t state = 0);

// Enclosure of the samples of a view region: its centre, then a 4 x 4 grid (cell centres of a
// 4 x 4 split in x and z) at the mid height of the region, in z-major order.
struct CellFreeSpace {
  int samples = 0;
  int enclosed = 0;                // samples enclosed (point_enclosed)
  bool centre_enclosed = false;    // the first sample
  std::optional<Vec3> free_point;  // the free sample nearest the centre (the centre when free);
                                   // none when every sample is enclosed
};
CellFreeSpace cell_free_space(const Scene& scene, const Box3& view_region, size_t state = 0);

}  // namespace vislib
