// view_report.h: the JSON and text output of `pvs view` (cmd_view.cpp): frame metrics, the
// growth of the near region, the summary on stderr, and the names of the images written.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "vislib/eval/render.h"
#include "vislib/render/near_far_render.h"
#include "vislib/render/near_region_growth.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

// epsilon, missed pixels, PSNR (null when infinite), SSIM and the share of pixels showing another
// triangle than the truth, of `test` against `truth`.
nlohmann::json frame_error_json(const vislib::Frame& truth, const vislib::Frame& test);

// frame_error_json and OVC, the object pixel agreement, CloVR's OFC (ofc_eq2) and the share of
// pixels showing another triangle than the truth, of `test` against `truth` (object_completion).
nlohmann::json quality_json(const vislib::Scene& scene, const vislib::Frame& truth,
                            const vislib::Frame& test);

// A near-far frame's epsilon split by pixel source (docs/runtime.md, "Metrics"): epsilon_geometry
// and epsilon_env_map, shares of all pixels that are missed and drawn from geometry (or
// background) / looked up in the environment map (they add up to epsilon), env_map_pixels, and
// the discontinuity delta of the near-far paper (Eqs. 7-8) at `radius` pixels from each pixel's
// scene point against the truth camera.
nlohmann::json near_far_json(const vislib::Frame& truth, const vislib::Frame& test,
                             const vislib::PixelSources& sources, const vislib::Camera& camera,
                             double radius);

// "dir/name.png" -> "dir/name<suffix>.png"
std::string sibling(const std::string& out, const std::string& suffix);

// One growth of the near region: radii, frames, steps and the minimum consecutive SSIM.
nlohmann::json growth_json(const vislib::GrowthRun& g);

// The summary on stderr of the view's JSON `j`.
void print_view(const nlohmann::json& j, const vislib::RegionCounts& rc, bool dynamic);

// The summary on stderr of the `stereo` block `j` of the view's JSON (run_view_stereo).
void print_view_stereo(const nlohmann::json& j);

}  // namespace pvs_cli
