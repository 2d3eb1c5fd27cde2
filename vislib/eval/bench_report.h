// bench_report.h: the files of a `pvs bench` run (docs/bench.md) that come straight from its
// result: bench.json, the CSV tables, the frames at equal time, and where the plotting script
// lives. Writes are atomic (file_util.h); failures throw InputError naming the file.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "vislib/eval/benchmark_compare.h"

namespace vislib {

// What bench.json records besides the result: the run as asked for and the files written.
struct BenchRunInfo {
  std::string scene;                // the scene path as given
  size_t scene_triangles = 0;       // of the loaded scene
  BenchOptions given;               // the options as given (point_runs 0 = automatic)
  int threads = 0;                  // worker threads as given (0 = all cores)
  double load_seconds = 0;          // loading the scene
  double total_seconds = 0;         // run_bench
  std::vector<std::string> frames;  // write_bench_frames' patterns (empty: no frames)
  std::vector<std::string> plots;   // PNG plots written, relative to the output folder
};

// The text of bench.json (docs/bench.md): settings, both methods at equal time, equal quality,
// timings and the files written; pretty-printed with one space per level, ending in a newline.
// Non-finite numbers are written as null (JSON has no infinities). Deterministic except for the
// seconds it reports.
std::string bench_json(const BenchRunInfo& info, const BenchResult& r);

// A CSV cell: %.10g, or "inf" / "-inf" / "nan" for non-finite values (Python's float() reads them).
std::string csv_number(double v);

// The CSV tables of docs/bench.md, each with its header line.
std::string growth_segment_csv(const BenchResult& r);  // runs,pass,segment,seconds,found
std::string growth_point_csv(const BenchResult& r);    // runs,seconds,found,x,y,z
std::string quality_csv(const BenchResult& r);         // one line per method and checkpoint
std::string quality_views_csv(const BenchResult& r);   // one line per method, checkpoint and view
std::string views_csv(const BenchResult& r);           // the fixed views' eyes and directions

// Writes growth_segment.csv, growth_point.csv, quality.csv, quality_views.csv and views.csv into
// the existing folder `dir`.
void write_bench_csv(const BenchResult& r, const std::string& dir);

// Writes the frames at equal time into dir/frames (created): per view the truth (PNG and EXR
// depth), both methods' frames and heat maps. Returns one pattern per view, relative to `dir`.
std::vector<std::string> write_bench_frames(const BenchResult& r, const std::string& dir);

// bench/plot_bench.py: `given` when not empty; else beside the source tree of the build that made
// the executable `exe` (its build folder's CMakeCache.txt names it); else <exe dir>/../../bench;
// else <exe dir>/../share/vislib. Empty when none exists.
std::string find_plot_script(const std::string& given, const std::string& exe);

// `s` quoted for a POSIX shell.
std::string shell_quote(const std::string& s);

}  // namespace vislib
