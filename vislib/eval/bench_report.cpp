// bench_report.cpp: CSV tables, frames and the plotting script of a `pvs bench` run.
#include "vislib/eval/bench_report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "vislib/base/file_util.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"

namespace vislib {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Finite numbers as numbers, +-inf and NaN as null (JSON has no infinities).
json num(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}
json vec_json(Vec3 v) {
  return json::array({v.x, v.y, v.z});
}

json quality_json(const QualitySummary& q) {
  return {{"epsilon", num(q.epsilon_mean)},
          {"epsilon_max", num(q.epsilon_max)},
          {"psnr", num(q.psnr)},
          {"psnr_min", num(q.psnr_min)},
          {"ssim", num(q.ssim_mean)},
          {"ssim_min", num(q.ssim_min)},
          {"missed_pixels", q.missed_pixels}};
}

json set_json(const SetComparison& c) {
  return {{"size", c.size},
          {"reference_size", c.reference_size},
          {"common", c.common},
          {"missed", c.missed},
          {"extra", c.extra}};
}

json method_json(const QualityCheckpoint& c, const SetComparison& vs_reference) {
  json j = quality_json(c.quality);
  j["runs"] = c.runs;
  j["seconds"] = num(c.seconds);
  j["found"] = c.set_size;
  j["vs_frame_triangles"] = set_json(c.vs_frames);
  j["vs_reference"] = set_json(vs_reference);
  return j;
}

}  // namespace

std::string bench_json(const BenchRunInfo& info, const BenchResult& r) {
  const BenchOptions& given = info.given;
  const auto& et = r.equal_time;
  const auto& eq = r.equal_quality;
  json j;
  j["scene"] = info.scene;
  j["scene_triangles"] = info.scene_triangles;
  j["box"] = {{"min", vec_json(given.box.min)}, {"max", vec_json(given.box.max)}};
  j["settings"] = {{"resolution", given.resolution},
                   {"near", given.near},
                   {"segment_runs", given.segment_runs},
                   {"perimeter_segments", r.segments.size()},
                   {"point_runs", r.options.point_runs},
                   {"point_runs_automatic", given.point_runs == 0},
                   {"point_time_factor", given.point_time_factor},
                   {"views", given.views},
                   {"view_path", given.path == ViewPath::Random ? "random" : "walk"},
                   {"frame", {given.width, given.height}},
                   {"vfov_degrees", given.vfov_degrees},
                   {"seed", given.seed},
                   {"threads", info.threads}};
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
                        {"note", eq.note},
                        {"confirmed", eq.confirmed},
                        {"confirmed_found", eq.confirmed_found},
                        {"confirmed_share", num(eq.confirmed_share)},
                        {"all_found", eq.all_found},
                        {"all_point_runs", num(eq.all_point_runs)},
                        {"all_point_seconds", num(eq.all_point_seconds)},
                        {"all_time_ratio", num(eq.all_time_ratio)},
                        {"all_time_ratio_bound", num(eq.all_time_ratio_bound)}};
  j["frame_triangles"] = r.frame_triangles.size();
  j["reference_triangles"] = r.reference.size();
  j["timings"] = {{"load_seconds", info.load_seconds},
                  {"bvh_build_seconds", r.bvh_build_seconds},
                  {"truth_frames_seconds", r.truth_seconds},
                  {"segment_seconds", num(et.seconds)},
                  {"point_seconds", num(r.point.growth.back().seconds)},
                  {"point_seconds_per_run", num(r.point_seconds_per_run)},
                  {"point_calibration_seconds_per_run", num(r.calibration_seconds_per_run)},
                  {"quality_seconds", r.quality_seconds},
                  {"total_seconds", info.total_seconds}};
  j["files"] = {
      {"csv",
       {"growth_segment.csv", "growth_point.csv", "quality.csv", "quality_views.csv", "views.csv"}},
      {"frames", info.frames},
      {"plots", info.plots}};
  return j.dump(1) + "\n";
}

std::string csv_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string growth_segment_csv(const BenchResult& r) {
  const int segments = int(r.segments.size());
  std::ostringstream s;
  s << "runs,pass,segment,seconds,found\n";
  for (const auto& g : r.segment.growth)
    s << g.runs << ',' << (g.runs - 1) / segments << ',' << (g.runs - 1) % segments << ','
      << csv_number(g.seconds) << ',' << g.found << '\n';
  return s.str();
}

std::string growth_point_csv(const BenchResult& r) {
  std::ostringstream s;
  s << "runs,seconds,found,x,y,z\n";
  for (size_t i = 0; i < r.point.growth.size(); ++i) {
    const auto& g = r.point.growth[i];
    const auto& p = r.point_viewpoints[i];
    s << g.runs << ',' << csv_number(g.seconds) << ',' << g.found << ',' << csv_number(p.x) << ','
      << csv_number(p.y) << ',' << csv_number(p.z) << '\n';
  }
  return s.str();
}

namespace {

void checkpoint_lines(std::ostringstream& s, const char* method, const MethodRun& m) {
  for (const auto& c : m.checkpoints) {
    const auto& q = c.quality;
    s << method << ',' << c.runs << ',' << csv_number(c.seconds) << ',' << c.set_size << ','
      << csv_number(q.epsilon_mean) << ',' << csv_number(q.epsilon_max) << ',' << csv_number(q.psnr)
      << ',' << csv_number(q.psnr_min) << ',' << csv_number(q.ssim_mean) << ','
      << csv_number(q.ssim_min) << ',' << q.missed_pixels << ',' << c.vs_frames.missed << '\n';
  }
}

void view_lines(std::ostringstream& v, const char* method, const MethodRun& m) {
  for (const auto& c : m.checkpoints)
    for (size_t i = 0; i < c.views.size(); ++i) {
      const auto& f = c.views[i];
      v << method << ',' << c.runs << ',' << csv_number(c.seconds) << ',' << i << ','
        << csv_number(f.epsilon) << ',' << csv_number(f.mse) << ',' << csv_number(f.psnr) << ','
        << csv_number(f.ssim) << ',' << f.missed_pixels << '\n';
    }
}

}  // namespace

std::string quality_csv(const BenchResult& r) {
  std::ostringstream s;
  s << "method,runs,seconds,found,epsilon,epsilon_max,psnr,psnr_min,ssim,ssim_min,missed_pixels,"
       "frame_triangles_missed\n";
  checkpoint_lines(s, "segment", r.segment);
  checkpoint_lines(s, "point", r.point);
  return s.str();
}

std::string quality_views_csv(const BenchResult& r) {
  std::ostringstream v;
  v << "method,runs,seconds,view,epsilon,mse,psnr,ssim,missed_pixels\n";
  view_lines(v, "segment", r.segment);
  view_lines(v, "point", r.point);
  return v.str();
}

std::string views_csv(const BenchResult& r) {
  std::ostringstream s;
  s << "view,eye_x,eye_y,eye_z,forward_x,forward_y,forward_z\n";
  for (size_t i = 0; i < r.views.size(); ++i) {
    const auto& c = r.views[i];
    s << i << ',' << csv_number(c.eye.x) << ',' << csv_number(c.eye.y) << ',' << csv_number(c.eye.z)
      << ',' << csv_number(c.forward.x) << ',' << csv_number(c.forward.y) << ','
      << csv_number(c.forward.z) << '\n';
  }
  return s.str();
}

void write_bench_csv(const BenchResult& r, const std::string& dir) {
  const fs::path d(dir);
  write_file_atomic((d / "growth_segment.csv").string(), growth_segment_csv(r));
  write_file_atomic((d / "growth_point.csv").string(), growth_point_csv(r));
  write_file_atomic((d / "quality.csv").string(), quality_csv(r));
  write_file_atomic((d / "quality_views.csv").string(), quality_views_csv(r));
  write_file_atomic((d / "views.csv").string(), views_csv(r));
}

std::vector<std::string> write_bench_frames(const BenchResult& r, const std::string& out) {
  std::vector<std::string> frames;
  const fs::path dir = fs::path(out) / "frames";
  fs::create_directories(dir);
  for (size_t i = 0; i < r.truth_frames.size(); ++i) {
    const std::string v = "view" + std::to_string(i);
    const auto& t = r.truth_frames[i];
    auto file = [&](const std::string& name) { return (dir / (v + name)).string(); };
    write_rgb8_image(file("_truth.png"), t.width, t.height, t.rgb);
    write_float_image(file("_truth_depth.exr"), t.width, t.height, t.depth);
    write_rgb8_image(file("_segment.png"), t.width, t.height, r.segment_frames[i].rgb);
    write_rgb8_image(file("_point.png"), t.width, t.height, r.point_frames[i].rgb);
    write_rgb8_image(file("_segment_heat.png"), t.width, t.height,
                     error_heat_map(t, r.segment_missed[i]));
    write_rgb8_image(file("_point_heat.png"), t.width, t.height,
                     error_heat_map(t, r.point_missed[i]));
    frames.push_back("frames/" + v + "_{truth,truth_depth,segment,point,segment_heat,point_heat}");
  }
  return frames;
}

std::string find_plot_script(const std::string& given, const std::string& exe) {
  if (!given.empty()) return given;
  std::error_code ec;
  const fs::path dir = fs::path(exe).parent_path();
  std::ifstream cache(dir.parent_path() / "CMakeCache.txt");
  std::string line;
  while (std::getline(cache, line)) {
    const std::string key = "vislib_SOURCE_DIR:STATIC=";
    if (line.rfind(key, 0) == 0) {
      fs::path p = fs::path(line.substr(key.size())) / "bench" / "plot_bench.py";
      if (fs::exists(p, ec)) return p.string();
    }
  }
  for (fs::path p : {dir / ".." / ".." / "bench" / "plot_bench.py",
                     dir / ".." / "share" / "vislib" / "plot_bench.py"})
    if (fs::exists(p, ec)) return p.lexically_normal().string();
  return "";
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace vislib
