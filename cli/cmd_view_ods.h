// cmd_view_ods.h: `pvs view --ods`, the omnidirectional stereo panoramas of a cell:
// the options it adds to `pvs view` (registered by view_options.cpp) and the run. cmd_view.cpp
// hands over to run_view_ods when --ods is given; docs/ods.md documents the command.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

namespace pvs_cli {

struct OdsViewArgs {
  bool enabled = false;
  double ipd_m = 0.064;          // interpupillary distance, metres
  double units_per_metre = 1.0;  // scene units in one metre
  int size = 2048;               // panorama width (height = width / 2)
  std::string pole_merge;  // "start,end,exp[:start,end,exp]" (top[:bottom]), degrees from the pole
  std::string method = "rays";  // rays | raster-paper | raster-exact
  int tessellation = 0;         // raster: 0 = dynamic (Alg. 1 + Eq. 4), k = static k
};

// What `pvs view` passes on: its own options the ODS run shares.
struct ViewCommonArgs {
  std::string file, scene, at, output, json_path;
  int states = 1;
  double tau = 0;
};

// Adds --ods, --ipd, --units-per-metre, --ods-size, --pole-merge, --ods-method,
// --ods-tessellation to `cmd`, storing into `args`.
void add_ods_view_options(CLI::App* cmd, const std::shared_ptr<OdsViewArgs>& args);

// Renders and writes the ODS panoramas, the full-scene truth and the metrics (throws
// CLI::ValidationError, vislib::InputError or pvs_cli::Exit like the other commands).
void run_view_ods(const OdsViewArgs& ods, const ViewCommonArgs& common);

}  // namespace pvs_cli
