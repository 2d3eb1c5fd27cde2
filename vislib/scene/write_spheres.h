// write_spheres.h: writing the spheres of a Scene in the vislib sphere text format, version 1:
//
//   vislib-spheres 1
//   # comment lines start with '#'
//   states K
//   radius x0 y0 z0 x1 y1 z1 ...        (one line per sphere: its centre in each of the K states)
//
// Numbers are printed with %.17g, so reading them back as double gives the same values.
#pragma once

#include <string>

#include "vislib/scene/scene.h"

namespace vislib {

// Returns the text above for the spheres of `scene` (triangles are ignored), K =
// sphere_centers.size() (1 if the scene has no sphere states). Deterministic.
// Preconditions: every sphere_centers[k] has sphere_count() entries.
std::string spheres_to_text(const Scene& scene);

}  // namespace vislib
