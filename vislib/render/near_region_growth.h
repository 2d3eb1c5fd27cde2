// near_region_growth.h: CloVR's progressive near region (CloVR §3.2, Alg. 1) grown ring by ring up
// to r2, and the continuity it keeps: the frames of each growth step and the SSIM between
// consecutive frames. The rings are equal-area, or merged so that each brings at least a given
// number of visible triangles into the near region (runtime/near_far.h, merge_rings).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene.h"

namespace vislib {

// The ring radii of a growth up to r2 (scene units): `rings` equal-area rings, each ring's count
// of visible triangles entering the near region, and the merged rings.
struct GrowthPlan {
  double ring_area = 0;               // pi r2^2 / rings (scene units squared)
  std::vector<double> equal;          // equal-area ring radii, ascending, last = r2
  std::vector<double> contribution;   // per equal-area ring: visible triangles entering it
  double merge_min_contribution = 0;  // what each merged ring brings at least
  std::vector<double> merged;         // merged ring radii, ascending, last = r2
};

// `rings` must be >= 1 and r2 > 0. merge_min < 0 takes the mean contribution of the equal-area
// rings. Deterministic.
GrowthPlan plan_growth(const Scene& scene, const std::vector<uint32_t>& visible, Vec3 centre,
                       double r2, int rings, double merge_min);

// One frame of a growth: the near region R, of ring `ring` (outer radius ring_radius).
struct GrowthStep {
  size_t ring = 0;
  double ring_radius = 0, radius = 0;  // scene units
  double ssim_to_truth = 0;
  std::optional<double> ssim_to_previous;  // windowed (11 x 11) SSIM; none for the first frame
  std::optional<double>
      whole_ssim_to_previous;  // whole-image SSIM (CloVR's VC); none for the first
};

struct GrowthRun {
  std::vector<double> radii;
  std::vector<GrowthStep> steps;
  std::optional<double> min_consecutive_ssim;        // none with fewer than two frames
  std::optional<double> min_consecutive_whole_ssim;  // the same with whole-image SSIM
};

// What the frames of a growth need besides the radii.
struct GrowthSettings {
  Vec3 centre;                 // O of the cylinders
  double near_fraction = 0.7;  // R_n / R of Alg. 1, in (0, 1)
  int env_size = 0;            // environment map face side (pixels), >= 1
  int frames_per_ring = 4;     // >= 1
  // If set, called with each frame of the growth in order (index from 0), e.g. to write it.
  std::function<void(size_t index, const GrowthStep& step, const Frame& frame)> on_frame;
};

// Grows the near region through `radii`: ring i is injected over frames_per_ring frames with
// R = R_{i-1} + (R_i - R_{i-1}) j / F, j = 1..F (the first ring appears at once); a frame whose
// eye is not inside R_n (near_fraction * R from the axis) is skipped, as Alg. 1 needs. Each frame
// is render_progressive's, compared with `truth` (same camera) and with the previous frame.
GrowthRun grow_near_region(const Scene& scene, const EmbreeScene& rt,
                           const std::vector<uint32_t>& visible, const Camera& camera,
                           const Frame& truth, const std::vector<double>& radii,
                           const GrowthSettings& settings);

// Both growths of a plan, the merged rings then the equal-area rings (pvs view --grow), with the
// same settings; `on_frame`, when set, gets each frame with its schedule ("merged" or
// "equal_area") and its index within that growth (settings.on_frame is not used).
struct GrowthComparison {
  GrowthRun merged, equal_area;
};
using ScheduleFrameFn = std::function<void(const std::string& schedule, size_t index,
                                           const GrowthStep& step, const Frame& frame)>;
GrowthComparison grow_near_region_both(const Scene& scene, const EmbreeScene& rt,
                                       const std::vector<uint32_t>& visible, const Camera& camera,
                                       const Frame& truth, const GrowthPlan& plan,
                                       GrowthSettings settings,
                                       const ScheduleFrameFn& on_frame = {});

}  // namespace vislib
