// bench_report.cpp: CSV tables, frames and the plotting script of a `pvs bench` run.
#include "vislib/eval/bench_report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "vislib/base/file_util.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"

namespace vislib {

namespace fs = std::filesystem;

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
