// seeing_rule.h: the seeing rule of the sampled checks (vis_compare.h, pvs_check.h) on the
// crossings of one double-precision ray (ray_crossings, ray_reference.h).
#pragma once

#include <cstdint>
#include <vector>

#include "vislib/eval/ray_reference.h"
#include "vislib/scene/scene.h"

namespace vislib {

// Along a ray, triangle T is seen when the ray crosses T at lambda > z_near, farther than
// kReferenceBarycentric inside its edges, and no opaque triangle is crossed (its edges widened by
// kReferenceBarycentric) in front of T by more than eps_z * lambda_T (the kernel's
// CoplanarRule::Both, tolerances.h); see-through triangles hide nothing.
struct SeeingRule {
  const Scene& scene;
  double z_near;  // scene units, > 0
  double eps_z;   // relative

  // T's depth when seen, else a negative value.
  double seen_depth(const std::vector<RayCrossing>& cr, uint32_t tri) const;
  // T is crossed beyond z_near but not farther than kReferenceBarycentric inside its edges (so
  // seen_depth refuses it), and nothing opaque lies in front of it by more than eps_z: only the
  // kernel's tie rules decide such a ray.
  bool seen_at_tie(const std::vector<RayCrossing>& cr, uint32_t tri) const;
  // Whether a triangle with in_set != 0 is crossed within eps_z * lambda of depth `lambda`.
  bool set_at_depth(const std::vector<RayCrossing>& cr, double lambda,
                    const std::vector<uint8_t>& in_set) const;
};

}  // namespace vislib
