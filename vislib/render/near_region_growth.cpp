// near_region_growth.cpp: CloVR's ring-by-ring growth of the near region (CloVR §3.2, Alg. 1) and
// its continuity (minimum SSIM between consecutive frames).
#include "vislib/render/near_region_growth.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "runtime/near_far.h"
#include "vislib/eval/metrics.h"
#include "vislib/render/near_far_render.h"

namespace vislib {

GrowthPlan plan_growth(const Scene& scene, const std::vector<uint32_t>& visible, Vec3 centre,
                       double r2, int rings, double merge_min) {
  GrowthPlan p;
  p.ring_area = M_PI * r2 * r2 / rings;
  p.equal = pvs_runtime::equal_area_ring_radii(p.ring_area, r2);
  p.contribution = ring_visible_triangle_contribution(scene, visible, centre, p.equal);
  double total = 0;
  for (double c : p.contribution) total += c;
  p.merge_min_contribution = merge_min >= 0 ? merge_min : total / double(p.equal.size());
  p.merged = pvs_runtime::merge_rings(p.equal, p.contribution, p.merge_min_contribution);
  return p;
}

GrowthRun grow_near_region(const Scene& scene, const EmbreeScene& rt,
                           const std::vector<uint32_t>& visible, const Camera& camera,
                           const Frame& truth, const std::vector<double>& radii,
                           const GrowthSettings& settings) {
  GrowthRun run;
  run.radii = radii;
  const double eye_axis =
      pvs_runtime::axis_distance({camera.eye.x, camera.eye.y, camera.eye.z},
                                 {settings.centre.x, settings.centre.y, settings.centre.z});
  double min_ssim = 1, min_whole = 1;
  std::optional<Frame> prev;
  for (size_t i = 0; i < radii.size(); ++i) {
    const int frames = i == 0 ? 1 : settings.frames_per_ring;
    for (int k = 1; k <= frames; ++k) {
      const double big_r =
          i == 0 ? radii[0] : radii[i - 1] + (radii[i] - radii[i - 1]) * k / frames;
      if (!(eye_axis < settings.near_fraction * big_r))
        continue;  // Alg. 1 needs the eye inside R_n
      Frame f = render_progressive(scene, rt, visible, camera, settings.centre, big_r,
                                   settings.near_fraction, settings.env_size, radii[i]);
      GrowthStep step;
      step.ring = i;
      step.ring_radius = radii[i];
      step.radius = big_r;
      step.ssim_to_truth = frame_quality(truth, f).ssim;
      if (prev) {
        const double ss = ssim_luminance(camera.width, camera.height, prev->rgb, f.rgb);
        step.ssim_to_previous = ss;
        min_ssim = std::min(min_ssim, ss);
        const double whole = ssim_whole_image(camera.width, camera.height, prev->rgb, f.rgb);
        step.whole_ssim_to_previous = whole;
        min_whole = std::min(min_whole, whole);
      }
      if (settings.on_frame) settings.on_frame(run.steps.size(), step, f);
      run.steps.push_back(step);
      prev = std::move(f);
    }
  }
  if (run.steps.size() >= 2) {
    run.min_consecutive_ssim = min_ssim;
    run.min_consecutive_whole_ssim = min_whole;
  }
  return run;
}

GrowthComparison grow_near_region_both(const Scene& scene, const EmbreeScene& rt,
                                       const std::vector<uint32_t>& visible, const Camera& camera,
                                       const Frame& truth, const GrowthPlan& plan,
                                       GrowthSettings settings, const ScheduleFrameFn& on_frame) {
  GrowthComparison c;
  for (const char* schedule : {"merged", "equal_area"}) {
    settings.on_frame = nullptr;
    if (on_frame)
      settings.on_frame = [&on_frame, schedule](size_t i, const GrowthStep& step, const Frame& f) {
        on_frame(schedule, i, step, f);
      };
    const bool merged = std::string(schedule) == "merged";
    (merged ? c.merged : c.equal_area) = grow_near_region(
        scene, rt, visible, camera, truth, merged ? plan.merged : plan.equal, settings);
  }
  return c;
}

}  // namespace vislib
