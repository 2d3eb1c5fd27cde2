// visibility_common.cpp: options and JSON output shared by `pvs segment` and `pvs region`.
#include "cli/visibility_common.h"

#include <sys/resource.h>

#include <chrono>
#include <cstdio>

#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "vislib/base/file_util.h"

namespace pvs_cli {

using nlohmann::json;

void add_common(CLI::App* cmd, VisibilityArgs& a) {
  cmd->add_option("SCENE", a.scene, "Scene file (.glb .gltf .obj .ply .off .stl)")->required();
  cmd->add_option("--res", a.resolution, "Cube face resolution N (N x N pixels per face)")
      ->check(in_range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--near", a.near, "Near plane: view depth below which hits do not count")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--eps-len", a.eps_len, "Final pieces must be longer than this (in t) to count")
      ->check(in_range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--granularity", a.granularity, "Report visible triangles or objects")
      ->check(CLI::IsMember({"triangle", "object"}))
      ->capture_default_str();
  cmd->add_option("-j,--threads", a.threads, "Threads, as make -j (0 = one per core)")
      ->check(in_range(0, kMaxThreads));
  cmd->add_option("--tile", a.tile,
                  "Tile side in pixels (memory/parallelism grain); 0: 32 for static scenes, 16 "
                  "with moving triangles or spheres")
      ->check(in_range(0, vislib::kMaxTileSize))
      ->capture_default_str();
  add_import_options(cmd, a.import);
  cmd->add_option("--states", a.states,
                  "Key states to sample glTF animations into (dynamic scenes)")
      ->check(in_range(1, 100000));
  cmd->add_option(
         "--mode", a.mode,
         "Dynamic scenes: 'diagonal' (animation time advances with the eye, the paper's mode) or "
         "'decoupled' (also the eye fixed at each end while the scene animates, and the scene "
         "frozen at each state while the eye moves)")
      ->check(CLI::IsMember({"diagonal", "decoupled"}))
      ->capture_default_str();
  cmd->add_option(
         "--coplanar", a.coplanar,
         "Depth ties (coplanar or near-coplanar overlaps): 'both' = surfaces within --eps-z of the "
         "front depth are visible too (a z-buffer z-fights there); 'first' = the old rule, the "
         "nearer surface wins and exact ties go to the lower id")
      ->check(CLI::IsMember({"both", "first"}))
      ->capture_default_str();
  cmd->add_option(
         "--eps-z", a.eps_z,
         "Depth tie tolerance with --coplanar both, relative to the front depth (unitless: 1e-6 = "
         "1 um at 1 m)")
      ->check(in_range(0.0, 0.1))
      ->capture_default_str();
  cmd->add_option("--bvh", a.bvh,
                  "Static scenes: walk a BVH of the triangles front to back per tile instead of "
                  "binning every triangle on every face (same results; pays on big scenes and "
                  "over many runs). 'auto' = on for region, off for a single segment")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  add_fans_option(*cmd, a.fans);
  cmd->add_option("--json", a.json_out, "Write the result as JSON to this file ('-' = stdout)")
      ->required();
}

double maybe_build_bvh(const VisibilityArgs& a, bool auto_on, const vislib::Scene& scene,
                       vislib::TriangleBvh& tree, vislib::SegmentOptions& so) {
  const bool want = a.bvh == "on" || (a.bvh == "auto" && auto_on);
  if (!want || !vislib::bvh_applies(scene)) return 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  tree = vislib::build_triangle_bvh(
      scene, so.fans ? vislib::BvhPrimitives::Groups : vislib::BvhPrimitives::Triangles, so.state);
  so.bvh = &tree;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double build_edge_lines(const vislib::Scene& scene, vislib::EdgeLines& lines,
                        vislib::SegmentOptions& so) {
  if (!vislib::bvh_applies(scene)) return 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  lines = vislib::build_edge_lines(scene, so.state);
  so.edge_lines = &lines;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

vislib::SegmentOptions segment_options(const VisibilityArgs& a) {
  vislib::SegmentOptions o;
  o.resolution = a.resolution;
  o.near = a.near;
  o.eps_len = a.eps_len;
  o.tile_size = a.tile;
  o.mode = a.mode == "decoupled" ? vislib::DynamicMode::Decoupled : vislib::DynamicMode::Diagonal;
  o.coplanar = a.coplanar == "first" ? vislib::CoplanarRule::First : vislib::CoplanarRule::Both;
  o.fans = a.fans == "on";
  o.eps_z = a.eps_z;
  return o;
}

double peak_rss_bytes() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) * 1024.0;  // Linux: kilobytes
}

json witness_json(const vislib::Witness& x) {
  return {{x.is_sphere ? "sphere" : "tri", x.tri},
          {"face", x.face},
          {"x", x.x},
          {"y", x.y},
          {"t", x.t},
          {"tau", x.tau}};
}

json vec_json(vislib::Vec3 v) {
  return json::array({v.x, v.y, v.z});
}
json mat_json(const vislib::Mat3& m) {
  return json(std::vector<double>(m.m, m.m + 9));
}

json counts_json(const vislib::SegmentStats& s) {
  return {{"triangle_pixel_pairs", s.pair_tests},
          {"culled_pixel_pairs", s.culled_pairs},
          {"covered_pairs", s.covered_pairs},
          {"hidden_pairs", s.hidden_pairs},
          {"final_pieces", s.final_pieces},
          {"pixels_with_pieces", s.pixels_with_pieces},
          {"pieces_per_pixel", s.pieces_per_pixel()},
          {"max_pieces_per_pixel", s.max_pieces_per_pixel},
          {"triangle_tiles", s.triangle_tiles},
          {"culled_triangle_tiles", s.culled_triangle_tiles},
          {"bvh_nodes_opened", s.bvh_nodes_opened},
          {"primitives_bounded", s.primitives_bounded},
          {"peak_tile_bytes", s.peak_tile_bytes}};
}

std::vector<uint32_t> at_granularity(const vislib::Scene& scene, const std::vector<uint32_t>& tris,
                                     const std::vector<uint32_t>& spheres,
                                     const std::string& granularity) {
  return granularity == "object" ? vislib::objects_of(scene, tris, spheres) : tris;
}

void write_json(const std::string& path, const json& j) {
  std::string text = j.dump(1) + "\n";
  if (path == "-")
    std::fwrite(text.data(), 1, text.size(), stdout);
  else
    vislib::write_file_atomic(path, text);
}

vislib::Scene load(const VisibilityArgs& a, double& seconds) {
  auto t0 = std::chrono::steady_clock::now();
  vislib::Scene scene = load_scene_for_cli(a.scene, a.states, a.import);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return scene;
}

}  // namespace pvs_cli
