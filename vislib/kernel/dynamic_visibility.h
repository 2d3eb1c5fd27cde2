// dynamic_visibility.h: continuous from-segment visibility of moving triangles and spheres
// (docs/visibility-math.md §3-5): the eye translates along the segment while the scene's key states
// are interpolated linearly in time; events are quadratic (moving triangles) or come from the
// sphere equations, found as polynomial roots (polynomial.h). segment_visibility() calls it for
// dynamic scenes; the header is for callers that want the dynamic path on any scene.
#pragma once

#include "vislib/kernel/segment_visibility.h"

namespace vislib {

// The dynamic kernel alone (also for static scenes, e.g. to compare both paths in tests).
SegmentResult dynamic_segment_visibility(const Scene& scene, Vec3 v0, Vec3 v1,
                                         const SegmentOptions& options);

}  // namespace vislib
