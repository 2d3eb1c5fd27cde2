// bench_output.h: the options of `pvs bench` and its summary on stderr (bench.json is assembled by
// vislib/eval/bench_report.h).
#pragma once

#include <string>
#include <vector>

#include "vislib/eval/benchmark_compare.h"

namespace pvs_cli {

struct BenchArgs {
  std::string scene, box, frame = "640x480", out, path = "walk", python = "/usr/bin/python3";
  std::string plot_script;
  vislib::BenchOptions o;
  int threads = 0;
  bool no_frames = false, no_plots = false;
};

// The summary on stderr (warns when from-point stopped before the from-segment time).
void print_bench(const BenchArgs& a, const vislib::BenchResult& r, double total_s);

}  // namespace pvs_cli
