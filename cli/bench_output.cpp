// bench_output.cpp: the summary of `pvs bench` on stderr.
#include "cli/bench_output.h"

#include <cmath>
#include <cstdio>

#include "cli/commands.h"
#include "cli/options.h"
#include "vislib/eval/bench_report.h"

namespace pvs_cli {

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
  if (eq.all_found)
    std::fprintf(stderr,
                 "pvs bench: every id: from-point held all %zu confirmed ids of the from-segment "
                 "set after %.0f runs, %.2f s: %.2fx\n",
                 eq.confirmed, eq.all_point_runs, eq.all_point_seconds, eq.all_time_ratio);
  else
    std::fprintf(stderr,
                 "pvs bench: every id: from-point held %zu of %zu confirmed ids (%.1f%%) after its "
                 "%d runs: a bound, ratio > %.2fx (raise --point-runs to measure)\n",
                 eq.confirmed_found, eq.confirmed, pct(eq.confirmed_share), r.options.point_runs,
                 eq.all_time_ratio_bound);
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
