// view_options.h: the options of `pvs view` (cmd_view.cpp) without --ods and --stereo (their own
// files), and their parsing into numbers (CLI::ValidationError naming the option, exit 2).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "vislib/base/vec.h"
#include "vislib/eval/discontinuity.h"

namespace pvs_cli {

struct ViewArgs {
  std::string file, scene, at, look, near_far, centre, output, json_path, frames_out;
  std::string frame = "640x480", lookup = "eye";
  bool grow = false;
  int env_size = 0, rings = 8, states = 1, frames_per_ring = 4;
  double near_fraction = 0.7, tau = 0, merge_min = -1;
  double delta_radius = vislib::kDiscontinuityRadius;
};

// Adds the options of `pvs view` to `cmd`, storing into `a` (which must outlive `cmd`).
void add_view_options(CLI::App* cmd, ViewArgs& a);

// --frame, --near-far, --at and --look, parsed.
struct ViewInputs {
  int fw = 0, fh = 0;
  std::vector<double> radii;  // empty: derived from the cell
  vislib::Vec3 eye, target;
};

ViewInputs parse_view(const ViewArgs& a);

}  // namespace pvs_cli
