// view_report.cpp: the JSON and text output of `pvs view`.
#include "cli/view_report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli/options.h"
#include "vislib/eval/discontinuity.h"
#include "vislib/eval/metrics.h"

namespace pvs_cli {

using nlohmann::json;

json frame_error_json(const vislib::Frame& truth, const vislib::Frame& test) {
  const vislib::FrameQuality q = vislib::frame_quality(truth, test);
  // Share of pixels showing another triangle than the truth (epsilon compares depths, and the
  // morph and the environment map change depths even where the right surface is shown).
  size_t other = 0;
  for (size_t p = 0; p < truth.pixel_count(); ++p) other += truth.tri[p] != test.tri[p];
  return {{"triangle_mismatch", double(other) / double(truth.pixel_count())},
          {"epsilon", q.epsilon},
          {"missed_pixels", q.missed_pixels},
          {"psnr", std::isfinite(q.psnr) ? json(q.psnr) : json(nullptr)},
          {"ssim", q.ssim}};
}

json quality_json(const vislib::Scene& scene, const vislib::Frame& truth,
                  const vislib::Frame& test) {
  json j = frame_error_json(truth, test);
  const vislib::ObjectCompletion c = vislib::object_completion(scene, truth, test);
  j["ovc"] = c.ovc;
  j["object_pixel_agreement"] = c.object_pixel_agreement;
  j["ofc_eq2"] = c.ofc_eq2;
  j["objects_in_truth"] = c.objects;
  return j;
}

json near_far_json(const vislib::Frame& truth, const vislib::Frame& test,
                   const vislib::PixelSources& sources, const vislib::Camera& camera,
                   double radius) {
  const std::vector<uint8_t> missed = vislib::missed_pixels(truth, test);
  // Pixels and missed pixels per source: geometry (drawn where it is) or background, morphed
  // geometry, environment map (dynamic far pixels count with geometry: drawn from the eye).
  size_t count[3] = {0, 0, 0}, miss[3] = {0, 0, 0};
  for (size_t p = 0; p < missed.size(); ++p) {
    const int k = sources.source[p] == vislib::PixelSource::MorphedGeometry  ? 1
                  : sources.source[p] == vislib::PixelSource::EnvironmentMap ? 2
                                                                             : 0;
    ++count[k];
    miss[k] += missed[p] != 0;
  }
  const double n = double(missed.size());
  const vislib::Discontinuity d = vislib::frame_discontinuity(camera, sources.point, radius);
  return {{"morphed_pixels", double(count[1]) / n},
          {"env_map_pixels", double(count[2]) / n},
          {"epsilon_geometry", double(miss[0]) / n},
          {"epsilon_morphed", double(miss[1]) / n},
          {"epsilon_env_map", double(miss[2]) / n},
          {"delta",
           {{"mean", d.mean},
            {"mean_abs", d.mean_abs},
            {"max", d.max},
            {"share_above_half", d.share_above_half},
            {"pixels", d.pixels},
            {"radius", radius}}}};
}

// "dir/name.png" -> "dir/name<suffix>.png"
std::string sibling(const std::string& out, const std::string& suffix) {
  std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

json growth_json(const vislib::GrowthRun& g) {
  json steps = json::array();
  for (const vislib::GrowthStep& s : g.steps) {
    json step = {{"ring", s.ring},
                 {"ring_radius", s.ring_radius},
                 {"radius", s.radius},
                 {"ssim_to_truth", s.ssim_to_truth}};
    if (s.ssim_to_previous) step["ssim_to_previous"] = *s.ssim_to_previous;
    if (s.whole_ssim_to_previous) step["whole_ssim_to_previous"] = *s.whole_ssim_to_previous;
    steps.push_back(step);
  }
  return json{{"radii", g.radii},
              {"min_consecutive_ssim",
               g.min_consecutive_ssim ? json(*g.min_consecutive_ssim) : json(nullptr)},
              {"min_consecutive_whole_ssim",
               g.min_consecutive_whole_ssim ? json(*g.min_consecutive_whole_ssim) : json(nullptr)},
              {"frames", g.steps.size()},
              {"steps", steps}};
}

void print_view(const json& j, const vislib::RegionCounts& rc, bool dynamic) {
  if (!show_progress()) return;  // the summary on stderr obeys -q (the JSON has it all)
  auto fmt_psnr = [](const json& v) {
    return v.is_null() ? std::string("inf") : std::to_string(v.get<double>());
  };
  const json& w = j["without_morph"];
  std::fprintf(
      stderr,
      "cell %u: visible %zu triangles: near %zu, intermediate %zu, far %zu (env map %zu)\n"
      "  morph:    epsilon %.4f PSNR %s SSIM %.4f OVC %.3f object pixel agreement %.3f OFC (CloVR "
      "Eq. 2) %.3f triangle mismatch %.4f\n"
      "  no morph: epsilon %.4f PSNR %s SSIM %.4f OVC %.3f object pixel agreement %.3f OFC (CloVR "
      "Eq. 2) %.3f triangle mismatch %.4f\n",
      j["cell"].get<uint32_t>(), j["triangles"]["visible"].get<size_t>(), rc.near, rc.intermediate,
      rc.far, rc.env_map, j["epsilon"].get<double>(), fmt_psnr(j["psnr"]).c_str(),
      j["ssim"].get<double>(), j["ovc"].get<double>(), j["object_pixel_agreement"].get<double>(),
      j["ofc_eq2"].get<double>(), j["triangle_mismatch"].get<double>(), w["epsilon"].get<double>(),
      fmt_psnr(w["psnr"]).c_str(), w["ssim"].get<double>(), w["ovc"].get<double>(),
      w["object_pixel_agreement"].get<double>(), w["ofc_eq2"].get<double>(),
      w["triangle_mismatch"].get<double>());
  std::fprintf(stderr,
               "  delta (Eqs. 7-8, radius %g px), mean (mean |delta|): morph %.4f (%.4f), no "
               "morph %.4f (%.4f)\n"
               "  epsilon by source (morph / no morph): geometry %.4f / %.4f, morphed %.4f (%.1f%% "
               "of pixels), environment map %.4f / %.4f (%.1f%% / %.1f%% of pixels)\n",
               j["delta"]["radius"].get<double>(), j["delta"]["mean"].get<double>(),
               j["delta"]["mean_abs"].get<double>(), w["delta"]["mean"].get<double>(),
               w["delta"]["mean_abs"].get<double>(), j["epsilon_geometry"].get<double>(),
               w["epsilon_geometry"].get<double>(), j["epsilon_morphed"].get<double>(),
               100 * j["morphed_pixels"].get<double>(), j["epsilon_env_map"].get<double>(),
               w["epsilon_env_map"].get<double>(), 100 * j["env_map_pixels"].get<double>(),
               100 * w["env_map_pixels"].get<double>());
  if (dynamic)
    std::fprintf(stderr, "  tau %.4f: dynamic far triangles drawn %zu, shown %zu\n",
                 j["tau"].get<double>(), rc.far_dynamic, rc.far_dynamic_shown);
  if (j.contains("continuity"))
    for (const char* k : {"merged", "equal_area"}) {
      const json& g = j["continuity"][k];
      if (g["min_consecutive_ssim"].is_null()) continue;
      std::fprintf(stderr,
                   "  growth (%s, %zu rings): %zu frames, min consecutive SSIM %.4f (whole "
                   "image %.4f)\n",
                   k, g["radii"].size(), g["frames"].get<size_t>(),
                   g["min_consecutive_ssim"].get<double>(),
                   g["min_consecutive_whole_ssim"].get<double>());
    }
}

void print_view_stereo(const json& j) {
  for (const char* name : {"left", "right"}) {
    const json& ej = j["eyes"][name];
    if (ej["rendered"].get<bool>() || !show_progress()) continue;  // -q: the JSON has it all
    const json& m = ej["method_error"];
    std::fprintf(stderr,
                 "stereo %s eye (cells %zu, %zu triangles): holes %.4f%s, method error PSNR %s "
                 "SSIM %.4f triangle "
                 "mismatch %.4f; total error SSIM %.4f\n",
                 name, j["cells"].size(), j["visible_triangles"].get<size_t>(),
                 ej["holes"]["share"].get<double>(),
                 ej["fallback"].get<bool>() ? " (fallback: rendered)" : "",
                 m["psnr"].is_null() ? "inf" : std::to_string(m["psnr"].get<double>()).c_str(),
                 m["ssim"].get<double>(), m["triangle_mismatch"].get<double>(),
                 ej["total_error"]["ssim"].get<double>());
  }
  const json& cpu = j["cpu_seconds"];
  if (show_progress())
    std::fprintf(
        stderr,
        "stereo CPU time: render %.4f s + reproject %.4f s + patch %.4f s vs both eyes %.4f s; "
        "rays %zu vs %zu\n",
        cpu["render"].get<double>(), cpu["reproject"].get<double>(), cpu["patch"].get<double>(),
        cpu["render_both_eyes"].get<double>(), j["rays"]["cast"].get<size_t>(),
        j["rays"]["both_eyes"].get<size_t>());
}

}  // namespace pvs_cli
