// cmd_view_stereo.h: `pvs view ... --stereo`: single-render stereo by reprojection (YORO)
// after the PVS: the dominant eye draws the cells' visible set, the other eye is reprojected
// and patched. Options are registered by view_options.cpp, the run lives in cmd_view_stereo.cpp;
// cmd_view.cpp only hooks them in.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "vislib/eval/embree_scene.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

struct ViewStereoArgs {
  std::string mode;  // empty: no stereo; "yoro"/"true": fixed splatting; "alg2": Alg. 2 as printed
  double ipd = 0.064;  // scene units; set from --ipd x --units-per-metre (shared with --ods)
  std::string dominant = "left", patch = "yoro";
  bool reshade = false;
  double max_hole_share = 1;
  bool enabled() const { return !mode.empty(); }
};

// Registers --stereo, --dominant, --patch, --reshade, --max-hole-share on `view` (--ipd and
// --units-per-metre are registered by the --ods options and shared).
std::shared_ptr<ViewStereoArgs> add_view_stereo_options(CLI::App* view);

// Runs the stereo stage for the head camera `head` (its eye is the point between the eyes): finds
// the cells of both eyes in `pvs_file` (its fingerprint already checked against `scene`), renders
// the dominant eye from the union of their visible sets, reprojects and patches the other eye,
// renders the truths, writes the images next to `output` and returns the JSON `stereo` block.
// Throws Exit{2} (after a message) when an eye is in no cell or its cell is absent.
nlohmann::json run_view_stereo(const ViewStereoArgs& args, const std::string& pvs_file,
                               const vislib::Scene& scene, const vislib::EmbreeScene& rt,
                               const vislib::Camera& head, const std::string& output);

}  // namespace pvs_cli
