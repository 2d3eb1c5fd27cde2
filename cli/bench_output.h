// bench_output.h: the options of `pvs bench` and its outputs that cmd_bench.cpp assembles:
// bench.json (docs/bench.md) and the summary on stderr.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "vislib/eval/benchmark_compare.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

struct BenchArgs {
  std::string scene, box, frame = "640x480", out, path = "walk", python = "/usr/bin/python3";
  std::string plot_script;
  vislib::BenchOptions o;
  int threads = 0;
  bool no_frames = false, no_plots = false;
};

// bench.json: settings, both methods at equal time, equal quality, timings and the files written.
nlohmann::json bench_json(const BenchArgs& a, const vislib::Scene& scene,
                          const vislib::BenchResult& r, double load_s, double total_s,
                          const nlohmann::json& frames, const std::vector<std::string>& plots);

// The summary on stderr (warns when from-point stopped before the from-segment time).
void print_bench(const BenchArgs& a, const vislib::BenchResult& r, double total_s);

}  // namespace pvs_cli
