// seeing_rule.cpp: the seeing rule of the sampled checks (seeing_rule.h).
#include "vislib/eval/seeing_rule.h"

#include <cmath>

namespace vislib {
namespace {

// The crossing of `tri` among `cr`, if any.
const RayCrossing* crossing_of(const std::vector<RayCrossing>& cr, uint32_t tri) {
  for (const RayCrossing& c : cr)
    if (c.tri == tri) return &c;
  return nullptr;
}

// No opaque crossing other than `t`'s lies in front of it by more than eps_z.
bool nothing_in_front(const SeeingRule& r, const std::vector<RayCrossing>& cr,
                      const RayCrossing& t) {
  const double front = t.lambda * (1.0 - r.eps_z);
  for (const RayCrossing& c : cr)
    if (c.tri != t.tri && !r.scene.triangle_see_through(c.tri) &&
        c.lambda > r.z_near - kReferenceNear && c.lambda < front)
      return false;
  return true;
}

}  // namespace

double SeeingRule::seen_depth(const std::vector<RayCrossing>& cr, uint32_t tri) const {
  const RayCrossing* t = crossing_of(cr, tri);
  if (!t || t->min_bary <= kReferenceBarycentric || t->lambda <= z_near + kReferenceNear) return -1;
  return nothing_in_front(*this, cr, *t) ? t->lambda : -1;
}

bool SeeingRule::seen_at_tie(const std::vector<RayCrossing>& cr, uint32_t tri) const {
  const RayCrossing* t = crossing_of(cr, tri);
  if (!t || t->lambda <= z_near + kReferenceNear) return false;
  return nothing_in_front(*this, cr, *t);
}

bool SeeingRule::set_at_depth(const std::vector<RayCrossing>& cr, double lambda,
                              const std::vector<uint8_t>& in_set) const {
  for (const RayCrossing& c : cr)
    if (in_set[c.tri] && std::fabs(c.lambda - lambda) <= eps_z * lambda) return true;
  return false;
}

}  // namespace vislib
