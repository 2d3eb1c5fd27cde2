// visibility_common.h: what `pvs segment` and `pvs region` (cmd_visibility.cpp) share: their
// common options, the kernel options they map to, and their JSON output.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/load_scene.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/kernel/segment_visibility.h"
#include "vislib/scene/scene.h"

namespace pvs_cli {

// Options shared by `segment` and `region`.
struct VisibilityArgs {
  std::string scene;
  int resolution = 512;
  double near = vislib::kDefaultNear;
  double eps_len = vislib::kDefaultEpsLen;
  int threads = 0;
  int tile = 0;
  int states = 1;
  ImportArgs import;
  std::string granularity = "triangle";
  std::string mode = "diagonal";
  std::string coplanar = "both";
  double eps_z = vislib::kDefaultEpsZ;
  std::string json_out;
  std::string bvh = "auto";  // auto | on | off (--bvh)
  std::string fans = "on";   // on | off (--fans)
};

// Builds the triangle BVH the runs walk (SegmentOptions::bvh) when --bvh says so: "on", or
// "auto" with `auto_on` (a command running many segments); static scenes without spheres only.
// Sets so.bvh to `tree` and returns the build's wall seconds (0 when none was built).
double maybe_build_bvh(const VisibilityArgs& a, bool auto_on, const vislib::Scene& scene,
                       vislib::TriangleBvh& tree, vislib::SegmentOptions& so);

// Builds the runs of collinear edges (SegmentOptions::edge_lines) into `lines` for a static scene
// without spheres and sets so.edge_lines; returns the build's wall seconds (0 when none was
// built: the kernel then builds none either, or its own for a moving scene's static kernel).
double build_edge_lines(const vislib::Scene& scene, vislib::EdgeLines& lines,
                        vislib::SegmentOptions& so);

void add_common(CLI::App* cmd, VisibilityArgs& a);
vislib::SegmentOptions segment_options(const VisibilityArgs& a);
double peak_rss_bytes();  // of this process, bytes
nlohmann::json vec_json(vislib::Vec3 v);
nlohmann::json mat_json(const vislib::Mat3& m);
nlohmann::json counts_json(const vislib::SegmentStats& s);
// {"tri"|"sphere": id, "face", "x", "y", "t", "tau"}
nlohmann::json witness_json(const vislib::Witness& w);
// The visible triangles, or their objects (spheres included) when granularity is "object".
std::vector<uint32_t> at_granularity(const vislib::Scene& scene, const std::vector<uint32_t>& tris,
                                     const std::vector<uint32_t>& spheres,
                                     const std::string& granularity);
// Writes j to `path` (atomically), or to stdout when path is "-".
void write_json(const std::string& path, const nlohmann::json& j);
// Loads the scene of `a`; `seconds` gets the time it took.
vislib::Scene load(const VisibilityArgs& a, double& seconds);

}  // namespace pvs_cli
