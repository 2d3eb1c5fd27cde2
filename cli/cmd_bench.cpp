// pvs bench: from-segment against from-point visibility on one view region, with frame quality
// (vislib/benchmark_compare.h). Writes CSV, JSON, frames and (through bench/plot_bench.py and
// matplotlib) PNG plots into --out. docs/bench.md describes every file and key.
#include <sys/stat.h>
#include <sys/wait.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "vislib/benchmark_compare.h"
#include "vislib/file_util.h"
#include "vislib/image_io.h"

namespace pvs_cli {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct BenchArgs {
  std::string scene, box, frame = "640x480", out, path = "walk", python = "/usr/bin/python3";
  std::string plot_script;
  vislib::BenchOptions o;
  int threads = 0;
  bool no_frames = false, no_plots = false;
};

// Finite numbers as numbers, +-inf and NaN as null (JSON has no infinities).
json num(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}
// CSV cells: "inf" / "nan" for non-finite values (Python's float() reads both).
std::string cell(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
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

std::string csv_growth(const vislib::MethodRun& m, size_t segments, bool segment_method) {
  std::ostringstream s;
  s << (segment_method ? "runs,pass,segment,seconds,found\n" : "runs,seconds,found\n");
  for (const auto& g : m.growth) {
    s << g.runs << ',';
    if (segment_method)
      s << (g.runs - 1) / int(segments) << ',' << (g.runs - 1) % int(segments) << ',';
    s << cell(g.seconds) << ',' << g.found << '\n';
  }
  return s.str();
}

void csv_checkpoints(std::ostringstream& s, std::ostringstream& v, const char* method,
                     const vislib::MethodRun& m) {
  for (const auto& c : m.checkpoints) {
    const auto& q = c.quality;
    s << method << ',' << c.runs << ',' << cell(c.seconds) << ',' << c.set_size << ','
      << cell(q.epsilon_mean) << ',' << cell(q.epsilon_max) << ',' << cell(q.psnr) << ','
      << cell(q.psnr_min) << ',' << cell(q.ssim_mean) << ',' << cell(q.ssim_min) << ','
      << q.missed_pixels << ',' << c.vs_frames.missed << '\n';
    for (size_t i = 0; i < c.views.size(); ++i) {
      const auto& f = c.views[i];
      v << method << ',' << c.runs << ',' << cell(c.seconds) << ',' << i << ',' << cell(f.epsilon)
        << ',' << cell(f.mse) << ',' << cell(f.psnr) << ',' << cell(f.ssim) << ','
        << f.missed_pixels << '\n';
    }
  }
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// bench/plot_bench.py: --plot-script, else beside the source tree of this build (the build
// folder's CMakeCache.txt names it), else <exe>/../../bench, else <exe>/../share/vislib.
std::string find_plot_script(const std::string& given) {
  if (!given.empty()) return given;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "";
  const fs::path dir = exe.parent_path();
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

// Runs the plotting script; returns the PNG names written, or warns and returns nothing.
std::vector<std::string> make_plots(const BenchArgs& a) {
  const std::string script = find_plot_script(a.plot_script);
  const std::string manual = "python3-with-matplotlib bench/plot_bench.py " + shell_quote(a.out);
  if (script.empty()) {
    warn(
        "plots skipped: bench/plot_bench.py not found (give --plot-script); the CSV files are "
        "written, plot them later with: " +
        manual);
    return {};
  }
  if (::access(a.python.c_str(), X_OK) != 0) {
    warn("plots skipped: " + a.python +
         " is not an executable Python (give --python); later run: " + a.python + " " +
         shell_quote(script) + " " + shell_quote(a.out));
    return {};
  }
  const std::string cmd =
      shell_quote(a.python) + " " + shell_quote(script) + " " + shell_quote(a.out);
  std::fflush(stderr);
  const int status = std::system(cmd.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 3) {
    warn("plots skipped: matplotlib is missing for " + a.python +
         " (Debian: apt-get install python3-matplotlib); the CSV and JSON files are complete. "
         "Later run: " +
         cmd);
    return {};
  }
  if (code != 0) {
    warn("plots failed (" + cmd + " exited with " + std::to_string(code) +
         "); the CSV and JSON files are complete");
    return {};
  }
  return {"found_vs_seconds.png", "found_vs_runs.png", "epsilon_vs_seconds.png"};
}

void run(BenchArgs& a) {
  std::unique_ptr<tbb::global_control> limit;
  if (a.threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  size_t(a.threads));
  auto b = parse_doubles(a.box, "--box", 6);
  a.o.box = vislib::Box3{};
  a.o.box.extend({b[0], b[1], b[2]});
  a.o.box.extend({b[3], b[4], b[5]});
  {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(a.frame.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
      throw CLI::ValidationError("--frame", "expected WxH, e.g. 640x480, got '" + a.frame + "'");
    if (w < vislib::kSsimWindow || h < vislib::kSsimWindow || w > 16384 || h > 16384)
      throw CLI::ValidationError("--frame", "width and height must be in [11, 16384]");
    a.o.width = w;
    a.o.height = h;
  }
  a.o.path = a.path == "random" ? vislib::ViewPath::Random : vislib::ViewPath::Walk;
  a.o.keep_frames = !a.no_frames;

  auto t0 = std::chrono::steady_clock::now();
  vislib::Scene scene = load_scene_for_cli(a.scene);
  if (scene.sphere_count() > 0) warn(a.scene + ": spheres are ignored by the bench");
  if (scene.is_dynamic()) warn(a.scene + ": the scene is animated; the bench uses key state 0");
  const double load_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "pvs bench: %s: %zu triangles (loaded in %.2f s)\n", a.scene.c_str(),
               scene.triangle_count(), load_s);
  fs::create_directories(a.out);

  const bool tty = isatty(fileno(stderr));
  std::string last_stage;
  auto last_print = std::chrono::steady_clock::now();
  auto progress = [&](const std::string& stage, size_t done, size_t total) {
    const auto now = std::chrono::steady_clock::now();
    const bool first = stage != last_stage, final = done == total;
    if (!first && !final &&
        std::chrono::duration<double>(now - last_print).count() < (tty ? 0.2 : 5.0))
      return;
    last_print = now;
    if (first && tty && !last_stage.empty()) std::fprintf(stderr, "\n");
    last_stage = stage;
    std::fprintf(stderr, tty ? "\rpvs bench: %s %zu/%zu" : "pvs bench: %s %zu/%zu\n", stage.c_str(),
                 done, total);
    if (tty && final) std::fprintf(stderr, "\n"), last_stage.clear();
  };
  t0 = std::chrono::steady_clock::now();
  const vislib::BenchResult r = vislib::run_bench(scene, a.o, progress);
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // CSV.
  vislib::write_file_atomic((fs::path(a.out) / "growth_segment.csv").string(),
                            csv_growth(r.segment, r.segments.size(), true));
  {
    std::ostringstream s;
    s << "runs,seconds,found,x,y,z\n";
    for (size_t i = 0; i < r.point.growth.size(); ++i) {
      const auto& g = r.point.growth[i];
      const auto& p = r.point_viewpoints[i];
      s << g.runs << ',' << cell(g.seconds) << ',' << g.found << ',' << cell(p.x) << ','
        << cell(p.y) << ',' << cell(p.z) << '\n';
    }
    vislib::write_file_atomic((fs::path(a.out) / "growth_point.csv").string(), s.str());
  }
  {
    std::ostringstream s, v;
    s << "method,runs,seconds,found,epsilon,epsilon_max,psnr,psnr_min,ssim,ssim_min,missed_pixels,"
         "frame_triangles_missed\n";
    v << "method,runs,seconds,view,epsilon,mse,psnr,ssim,missed_pixels\n";
    csv_checkpoints(s, v, "segment", r.segment);
    csv_checkpoints(s, v, "point", r.point);
    vislib::write_file_atomic((fs::path(a.out) / "quality.csv").string(), s.str());
    vislib::write_file_atomic((fs::path(a.out) / "quality_views.csv").string(), v.str());
  }
  {
    std::ostringstream s;
    s << "view,eye_x,eye_y,eye_z,forward_x,forward_y,forward_z\n";
    for (size_t i = 0; i < r.views.size(); ++i) {
      const auto& c = r.views[i];
      s << i << ',' << cell(c.eye.x) << ',' << cell(c.eye.y) << ',' << cell(c.eye.z) << ','
        << cell(c.forward.x) << ',' << cell(c.forward.y) << ',' << cell(c.forward.z) << '\n';
    }
    vislib::write_file_atomic((fs::path(a.out) / "views.csv").string(), s.str());
  }

  // Frames at equal time.
  json frames = json::array();
  if (!a.no_frames) {
    const fs::path dir = fs::path(a.out) / "frames";
    fs::create_directories(dir);
    for (size_t i = 0; i < r.truth_frames.size(); ++i) {
      const std::string v = "view" + std::to_string(i);
      const auto& t = r.truth_frames[i];
      auto file = [&](const std::string& name) { return (dir / (v + name)).string(); };
      vislib::write_rgb8_image(file("_truth.png"), t.width, t.height, t.rgb);
      vislib::write_float_image(file("_truth_depth.exr"), t.width, t.height, t.depth);
      vislib::write_rgb8_image(file("_segment.png"), t.width, t.height, r.segment_frames[i].rgb);
      vislib::write_rgb8_image(file("_point.png"), t.width, t.height, r.point_frames[i].rgb);
      vislib::write_rgb8_image(file("_segment_heat.png"), t.width, t.height,
                               vislib::error_heat_map(t, r.segment_missed[i]));
      vislib::write_rgb8_image(file("_point_heat.png"), t.width, t.height,
                               vislib::error_heat_map(t, r.point_missed[i]));
      frames.push_back("frames/" + v +
                       "_{truth,truth_depth,segment,point,segment_heat,point_heat}");
    }
  }

  std::vector<std::string> plots;
  if (!a.no_plots) plots = make_plots(a);

  // JSON.
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
  vislib::write_file_atomic((fs::path(a.out) / "bench.json").string(), j.dump(1) + "\n");

  if (!et.within_measured)
    warn("from-point stopped (" + std::to_string(r.options.point_runs) + " runs, " +
         cell(r.point.growth.back().seconds) + " s) before the from-segment time " +
         cell(et.seconds) + " s: equal_time_share is a lower bound; raise --point-runs");
  auto pct = [](double v) { return 100.0 * v; };
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
      detail = "extrapolated ratio " + cell(eq.time_ratio) +
               "x (power-law fit of the discovery rate; " + cell(eq.time_ratio_low) + " to " +
               cell(eq.time_ratio_high) + "x over three fit windows)";
    std::fprintf(stderr,
                 "pvs bench: equal quality not reached in %d from-point runs (%zu of %zu "
                 "triangles): measured ratio > %.2fx; %s\n",
                 r.options.point_runs, r.point.set.size(), eq.target, eq.time_ratio_lower_bound,
                 detail.c_str());
  }
  std::fprintf(stderr,
               "pvs bench: at equal time: segment eps %.3f%% PSNR %s SSIM %.5f | point eps %.3f%% "
               "PSNR %s SSIM %.5f\npvs bench: wrote %s/bench.json (total %.1f s)\n",
               pct(et.segment.quality.epsilon_mean), cell(et.segment.quality.psnr).c_str(),
               et.segment.quality.ssim_mean, pct(et.point.quality.epsilon_mean),
               cell(et.point.quality.psnr).c_str(), et.point.quality.ssim_mean, a.out.c_str(),
               total_s);
}

void add_bench(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Compare from-segment and from-point visibility on one view region: triangles found "
      "against runs and seconds, frame quality (pixel error, PSNR, SSIM) over test views, the "
      "equal-time and equal-quality ratios; CSV, JSON, frames and plots in --out.");
  cmd->add_option("SCENE", a->scene, "Scene file (.glb .gltf .obj .ply .off .stl)")->required();
  cmd->add_option("--box", a->box, "View region x0,y0,z0,x1,y1,z1 (flat in y = view rectangle)")
      ->required();
  cmd->add_option("--out", a->out, "Output folder (created)")->required();
  cmd->add_option("--views", a->o.views, "Test views inside the region")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--view-path", a->path, "Test views on a walking path or at random in the box")
      ->check(CLI::IsMember({"walk", "random"}))
      ->capture_default_str();
  cmd->add_option("--segment-runs", a->o.segment_runs,
                  "From-segment cube orientations per perimeter segment (run 0 world-aligned)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--point-runs", a->o.point_runs,
                  "From-point viewpoints (0 = run for --point-time-factor x the from-segment time)")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  cmd->add_option("--point-time-factor", a->o.point_time_factor,
                  "Automatic --point-runs: this multiple of the from-segment seconds")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--max-point-runs", a->o.max_point_runs,
                  "Upper bound of the automatic --point-runs")
      ->check(CLI::Range(2, 10000000))
      ->capture_default_str();
  cmd->add_option("--res", a->o.resolution, "Cube face resolution N of both methods")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--near", a->o.near, "Near plane (view depth) of both methods and the frames")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--frame", a->frame, "Test frame size WxH")->capture_default_str();
  cmd->add_option("--fov", a->o.vfov_degrees, "Vertical field of view of the test frames (degrees)")
      ->check(CLI::Range(1.0, 179.0))
      ->capture_default_str();
  cmd->add_option("--seed", a->o.seed, "Seed of orientations, viewpoints and test views")
      ->capture_default_str();
  cmd->add_option("--threads", a->threads, "Worker threads (0 = all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-frames", a->no_frames, "Do not write the equal-time frames and heat maps");
  cmd->add_flag("--no-plots", a->no_plots, "Do not run the plotting script");
  cmd->add_option("--python", a->python, "Python with matplotlib for the plots")
      ->capture_default_str();
  cmd->add_option("--plot-script", a->plot_script,
                  "Path of bench/plot_bench.py (default: found "
                  "from the build tree)");
  cmd->callback([a] { run(*a); });
}

Registration bench_registration("bench", add_bench);

}  // namespace
}  // namespace pvs_cli
