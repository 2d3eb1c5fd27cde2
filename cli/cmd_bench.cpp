// pvs bench: from-segment against from-point visibility on one view region, with frame quality
// (vislib/eval/benchmark_compare.h). Writes CSV, JSON, frames and (through bench/plot_bench.py and
// matplotlib) PNG plots into --out. docs/bench.md describes every file and key.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "cli/bench_output.h"
#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/bench_report.h"
#include "vislib/eval/benchmark_compare.h"
#include "vislib/eval/image_io.h"

namespace pvs_cli {
namespace {

namespace fs = std::filesystem;

// Runs the plotting script; returns the PNG names written, or warns and returns nothing.
std::vector<std::string> make_plots(const BenchArgs& a) {
  std::error_code ec;
  const std::string script =
      vislib::find_plot_script(a.plot_script, fs::read_symlink("/proc/self/exe", ec).string());
  const std::string manual =
      "python3-with-matplotlib bench/plot_bench.py " + vislib::shell_quote(a.out);
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
         vislib::shell_quote(script) + " " + vislib::shell_quote(a.out));
    return {};
  }
  // -q: the script prints errors only (its "wrote" line and missing-matplotlib note are not).
  const std::string cmd = vislib::shell_quote(a.python) + " " + vislib::shell_quote(script) +
                          (show_progress() ? " " : " -q ") + vislib::shell_quote(a.out);
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
  check_output_dir(a.out, "--out");  // before any work
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
  if (show_progress())
    std::fprintf(stderr, "pvs bench: %s: %zu triangles (loaded in %.2f s)\n", a.scene.c_str(),
                 scene.triangle_count(), load_s);

  const bool tty = isatty(fileno(stderr));
  std::string last_stage;
  auto last_print = std::chrono::steady_clock::now();
  auto progress = [&](const std::string& stage, size_t done, size_t total) {
    if (!show_progress()) return;
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
  vislib::write_bench_csv(r, a.out);

  vislib::BenchRunInfo info;
  info.scene = a.scene;
  info.scene_triangles = scene.triangle_count();
  info.given = a.o;
  info.threads = a.threads;
  info.load_seconds = load_s;
  info.total_seconds = total_s;
  if (!a.no_frames) info.frames = vislib::write_bench_frames(r, a.out);  // frames at equal time
  if (!a.no_plots) info.plots = make_plots(a);
  vislib::write_file_atomic((fs::path(a.out) / "bench.json").string(), vislib::bench_json(info, r));
  print_bench(a, r, total_s);
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
      ->check(in_range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--view-path", a->path, "Test views on a walking path or at random in the box")
      ->check(CLI::IsMember({"walk", "random"}))
      ->capture_default_str();
  cmd->add_option("--segment-runs", a->o.segment_runs,
                  "From-segment cube orientations per perimeter segment (run 0 world-aligned)")
      ->check(in_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--point-runs", a->o.point_runs,
                  "From-point viewpoints (0 = run for --point-time-factor x the from-segment time)")
      ->check(in_range(0, 10000000))
      ->capture_default_str();
  cmd->add_option("--point-time-factor", a->o.point_time_factor,
                  "Automatic --point-runs: this multiple of the from-segment seconds")
      ->check(in_range(1.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--max-point-runs", a->o.max_point_runs,
                  "Upper bound of the automatic --point-runs")
      ->check(in_range(2, 10000000))
      ->capture_default_str();
  cmd->add_option("--res", a->o.resolution, "Cube face resolution N of both methods")
      ->check(in_range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--near", a->o.near, "Near plane (view depth) of both methods and the frames")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--frame", a->frame, "Test frame size WxH")->capture_default_str();
  cmd->add_option("--fov", a->o.vfov_degrees, "Vertical field of view of the test frames (degrees)")
      ->check(in_range(1.0, 179.0))
      ->capture_default_str();
  cmd->add_option("--seed", a->o.seed, "Seed of orientations, viewpoints and test views")
      ->capture_default_str();
  cmd->add_option("-j,--threads", a->threads, "Threads, as make -j (0 = one per core)")
      ->check(in_range(0, kMaxThreads));
  cmd->add_flag("--no-frames", a->no_frames, "Do not write the equal-time frames and heat maps");
  cmd->add_flag("--no-plots", a->no_plots, "Do not run the plotting script");
  cmd->add_option("--python", a->python, "Python with matplotlib for the plots")
      ->capture_default_str();
  cmd->add_option("--plot-script", a->plot_script,
                  "Path of bench/plot_bench.py (default: found "
                  "from the build tree)");
  cmd->callback([a] { run_with_threads(a->threads, [&] { run(*a); }); });
}

Registration bench_registration("bench", add_bench);

}  // namespace
}  // namespace pvs_cli
