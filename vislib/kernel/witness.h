// witness.h: where a from-segment kernel saw a primitive (a pixel and a time), shared by the
// static and the dynamic kernels and their results (segment_visibility.h).
#pragma once

#include <cstdint>

namespace vislib {

// A pixel and a t at which `tri` is the first hit, or (CoplanarRule::Both) lies within eps_z of the
// first hit's depth: the middle of its longest final or tied stretch (ties: lowest face, then row,
// then column).
struct Witness {
  uint32_t tri = 0;  // triangle id, or sphere index when is_sphere
  bool is_sphere = false;
  int face = 0, x = 0, y = 0;
  double t = 0;    // eye at v0 + t (v1 - v0)
  double tau = 0;  // animation time in [0,1] (static scenes: 0)
};

}  // namespace vislib
