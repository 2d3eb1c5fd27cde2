// scene_transform.h: a similarity transform of a scene (scale, rotation, translation), for moving a
// scene to another place, orientation and unit and checking that its visible sets do not change
// (docs/visibility-math.md §6 "Invariance under transformation").
#pragma once

#include "vislib/base/vec.h"
#include "vislib/scene/scene.h"

namespace vislib {

// x' = scale * (rotation * x) + translation. `scale` > 0 and finite, `rotation` a rotation
// (is_rotation), `translation` finite: transform_scene refuses anything else.
struct Similarity {
  double scale = 1;
  Mat3 rotation;
  Vec3 translation{0, 0, 0};
};

// The rotation by `degrees` about `axis` (any non-zero finite length; normalised here),
// right-handed (Rodrigues). Throws std::invalid_argument for a zero or non-finite axis or angle.
Mat3 axis_angle_rotation(Vec3 axis, double degrees);

// Matrix product a * b (apply b first).
Mat3 multiply(const Mat3& a, const Mat3& b);

// The image of the point p, each coordinate rounded once per operation in double
// (scale * (R p) + t, no fused multiply-add).
Vec3 apply(const Similarity& s, Vec3 p);

// Every vertex of every key state and every sphere centre mapped by `s`, sphere radii multiplied
// by s.scale; triangles, ids and objects unchanged. Throws std::invalid_argument when `s` is not a
// similarity as stated above.
void transform_scene(Scene& scene, const Similarity& s);

}  // namespace vislib
