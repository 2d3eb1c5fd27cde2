// bench_output.cpp: bench.json and the summary of `pvs bench`.
#include "cli/bench_output.h"

#include <cmath>
#include <cstdio>

#include "cli/commands.h"
#include "cli/options.h"
#include "vislib/eval/bench_report.h"

namespace pvs_cli {

using nlohmann::json;

namespace {

// Finite numbers as numbers, +-inf and NaN as null (JSON has no infinities).
json num(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}
json vec_json(vislib::Vec3 v) {
  return json::array({v.x, v.y, v.z});
}

json quality_json(const vislib::QualitySummary& q) {
  return {{"epsilon", num(q.epsilon_mean)},
          {"epsilon_max", num(q.epsilon_max)},
          {"psnr", num(q.psnr)},
          {"psnr_min", num(q.psnr_min)},
          {"ssim", num(q.ssim_mean)},
          {"ssim_min", num(q.ssim_min)},
          {"missed_pixels", q.missed_pixels}};
}

json set_json(const vislib::SetComparison& c) {
  return {{"size", c.size},
          {"reference_size", c.reference_size},
          {"common", c.common},
          {"missed", c.missed},
          {"extra", c.extra}};
}

json method_json(const vislib::QualityCheckpoint& c, const vislib::SetComparison& vs_reference) {
  json j = quality_json(c.quality);
  j["runs"] = c.runs;
  j["seconds"] = num(c.seconds);
  j["found"] = c.set_size;
  j["vs_frame_triangles"] = set_json(c.vs_frames);
  j["vs_reference"] = set_json(vs_reference);
  return j;
}

}  // namespace

// bench.json (docs/bench.md).
json bench_json(const BenchArgs& a, const vislib::Scene& scene, const vislib::BenchResult& r,
                double load_s, double total_s, const json& frames,
                const std::vector<std::string>& plots) {
  const auto& et = r.equal_time;
  const auto& eq = r.equal_quality;
  json j;
  j["scene"] = a.scene;
  j["scene_triangles"] = scene.triangle_count();
  j["box"] = {{"min", vec_json(a.o.box.min)}, {"max", vec_json(a.o.box.max)}};
  j["settings"] = {{"resolution", a.o.resolution},
                   {"near", a.o.near},
                   {"segment_runs", a.o.segment_runs},
                   {"perimeter_segments", r.segments.size()},
                   {"point_runs", r.options.point_runs},
                   {"point_runs_automatic", a.o.point_runs == 0},
                   {"point_time_factor", a.o.point_time_factor},
                   {"views", a.o.views},
                   {"view_path", a.path},
                   {"frame", {a.o.width, a.o.height}},
                   {"vfov_degrees", a.o.vfov_degrees},
                   {"seed", a.o.seed},
                   {"threads", a.threads}};
  j["equal_time_share"] = num(et.share);
  j["equal_quality_time_ratio"] = num(eq.time_ratio);
  j["equal_quality_extrapolated"] = eq.extrapolated;
  j["segment"] = method_json(et.segment, r.segment_vs_reference);
  j["point"] = method_json(et.point, r.point_equal_time_vs_reference);
  j["point_final"] = method_json(r.point.checkpoints.back(), r.point_vs_reference);
  j["equal_time"] = {{"seconds", num(et.seconds)},
                     {"point_runs", et.point_runs},
                     {"point_seconds", num(et.point_seconds)},
                     {"segment_found", et.segment_found},
                     {"point_found", et.point_found},
                     {"point_found_of_segment", et.point_found_of_segment},
                     {"share", num(et.share)},
                     {"overlap_share", num(et.overlap_share)},
                     {"within_measured", et.within_measured}};
  j["equal_quality"] = {{"target_found", eq.target},
                        {"segment_seconds", num(eq.segment_seconds)},
                        {"reached", eq.reached},
                        {"extrapolated", eq.extrapolated},
                        {"finite", eq.finite},
                        {"point_runs", num(eq.point_runs)},
                        {"point_seconds", num(eq.point_seconds)},
                        {"time_ratio", num(eq.time_ratio)},
                        {"time_ratio_lower_bound", num(eq.time_ratio_lower_bound)},
                        {"time_ratio_range", {num(eq.time_ratio_low), num(eq.time_ratio_high)}},
                        {"rate_coefficient", num(eq.rate_coefficient)},
                        {"rate_exponent", num(eq.rate_exponent)},
                        {"fit_points", eq.fit_points},
                        {"note", eq.note}};
  j["frame_triangles"] = r.frame_triangles.size();
  j["reference_triangles"] = r.reference.size();
  j["timings"] = {{"load_seconds", load_s},
                  {"bvh_build_seconds", r.bvh_build_seconds},
                  {"truth_frames_seconds", r.truth_seconds},
                  {"segment_seconds", num(et.seconds)},
                  {"point_seconds", num(r.point.growth.back().seconds)},
                  {"point_seconds_per_run", num(r.point_seconds_per_run)},
                  {"point_calibration_seconds_per_run", num(r.calibration_seconds_per_run)},
                  {"quality_seconds", r.quality_seconds},
                  {"total_seconds", total_s}};
  j["files"] = {
      {"csv",
       {"growth_segment.csv", "growth_point.csv", "quality.csv", "quality_views.csv", "views.csv"}},
      {"frames", frames},
      {"plots", plots}};
  return j;
}

// The summary on stderr.
void print_bench(const BenchArgs& a, const vislib::BenchResult& r, double total_s) {
  if (!show_progress()) return;  // the summary on stderr obeys -q (bench.json has it all)
  const auto& et = r.equal_time;
  const auto& eq = r.equal_quality;
  if (!et.within_measured)
    warn("from-point stopped (" + std::to_string(r.options.point_runs) + " runs, " +
         vislib::csv_number(r.point.growth.back().seconds) + " s) before the from-segment time " +
         vislib::csv_number(et.seconds) +
         " s: equal_time_share is a lower bound; raise --point-runs");
  auto pct = [](double v) { return 100.0 * v; };
  if (show_progress())
    std::fprintf(stderr,
                 "pvs bench: from-segment %zu triangles in %.2f s (%zu segments x %d runs); "
                 "from-point %zu in the same time (%d runs): equal-time share %.1f%%\n",
                 et.segment_found, et.seconds, r.segments.size(), a.o.segment_runs, et.point_found,
                 et.point_runs, pct(et.share));
  if (eq.reached)
    std::fprintf(stderr, "pvs bench: equal quality: from-point needs %.2f s (%.0f runs), %.2fx\n",
                 eq.point_seconds, eq.point_runs, eq.time_ratio);
  else {
    std::string detail = eq.note;
    if (!std::isnan(eq.time_ratio) && !std::isfinite(eq.time_ratio))
      detail = "the extrapolation never gets there (see bench.json)";
    else if (std::isfinite(eq.time_ratio))
      detail = "extrapolated ratio " + vislib::csv_number(eq.time_ratio) +
               "x (power-law fit of the discovery rate; " + vislib::csv_number(eq.time_ratio_low) +
               " to " + vislib::csv_number(eq.time_ratio_high) + "x over three fit windows)";
    if (show_progress())
      std::fprintf(stderr,
                   "pvs bench: equal quality not reached in %d from-point runs (%zu of %zu "
                   "triangles): measured ratio > %.2fx; %s\n",
                   r.options.point_runs, r.point.set.size(), eq.target, eq.time_ratio_lower_bound,
                   detail.c_str());
  }
  if (show_progress())
    std::fprintf(
        stderr,
        "pvs bench: at equal time: segment eps %.3f%% PSNR %s SSIM %.5f | point eps %.3f%% "
        "PSNR %s SSIM %.5f\npvs bench: wrote %s/bench.json (total %.1f s)\n",
        pct(et.segment.quality.epsilon_mean), vislib::csv_number(et.segment.quality.psnr).c_str(),
        et.segment.quality.ssim_mean, pct(et.point.quality.epsilon_mean),
        vislib::csv_number(et.point.quality.psnr).c_str(), et.point.quality.ssim_mean,
        a.out.c_str(), total_s);
}

}  // namespace pvs_cli
