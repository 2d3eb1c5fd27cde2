// pvs segment / pvs region: continuous from-segment visibility from the command line.
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "vislib/file_util.h"
#include "vislib/import.h"
#include "vislib/region_visibility.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

// Options shared by `segment` and `region`.
struct VisibilityArgs {
  std::string scene;
  int resolution = 512;
  double near = vislib::kDefaultNear;
  double eps_len = vislib::kDefaultEpsLen;
  int threads = 0;
  int tile = 32;
  int states = 1;
  std::string granularity = "triangle";
  std::string mode = "diagonal";
  std::string json_out;
};

void add_common(CLI::App* cmd, VisibilityArgs& a) {
  cmd->add_option("SCENE", a.scene, "Scene file (.glb .gltf .obj .ply .off .stl)")->required();
  cmd->add_option("--res", a.resolution, "Cube face resolution N (N x N pixels per face)")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--near", a.near, "Near plane: view depth below which hits do not count")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--eps-len", a.eps_len, "Final pieces must be longer than this (in t) to count")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--granularity", a.granularity, "Report visible triangles or objects")
      ->check(CLI::IsMember({"triangle", "object"}))
      ->capture_default_str();
  cmd->add_option("--threads", a.threads, "Worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--tile", a.tile, "Tile side in pixels (memory/parallelism grain)")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  cmd->add_option("--states", a.states, "Key states to sample glTF animations into (dynamic scenes)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--mode", a.mode,
                  "Dynamic scenes: 'diagonal' (animation time advances with the eye, the paper's mode) or "
                  "'decoupled' (also the eye fixed at each end while the scene animates, and the scene "
                  "frozen at each state while the eye moves)")
      ->check(CLI::IsMember({"diagonal", "decoupled"}))
      ->capture_default_str();
  cmd->add_option("--json", a.json_out, "Write the result as JSON to this file ('-' = stdout)")->required();
}

vislib::SegmentOptions segment_options(const VisibilityArgs& a) {
  vislib::SegmentOptions o;
  o.resolution = a.resolution;
  o.near = a.near;
  o.eps_len = a.eps_len;
  o.tile_size = a.tile;
  o.mode = a.mode == "decoupled" ? vislib::DynamicMode::Decoupled : vislib::DynamicMode::Diagonal;
  return o;
}

double peak_rss_bytes() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) * 1024.0;  // Linux: kilobytes
}

json vec_json(vislib::Vec3 v) { return json::array({v.x, v.y, v.z}); }
json mat_json(const vislib::Mat3& m) { return json(std::vector<double>(m.m, m.m + 9)); }

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
          {"peak_tile_bytes", s.peak_tile_bytes}};
}

std::vector<uint32_t> at_granularity(const vislib::Scene& scene, const std::vector<uint32_t>& tris,
                                     const std::vector<uint32_t>& spheres, const std::string& granularity) {
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
  vislib::Scene scene = load_scene_for_cli(a.scene, a.states);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return scene;
}

std::unique_ptr<tbb::global_control> thread_limit(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
}

void add_segment(CLI::App& app) {
  auto a = std::make_shared<VisibilityArgs>();
  auto from = std::make_shared<std::string>(), to = std::make_shared<std::string>();
  auto orientation = std::make_shared<std::string>();
  auto seed = std::make_shared<uint64_t>(0);
  auto witness = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "segment",
      "Triangles visible from a view segment: continuous from-segment visibility over a cubemap "
      "(six N x N faces) translating from --from to --to.");
  add_common(cmd, *a);
  cmd->add_option("--from", *from, "Segment start x,y,z")->required();
  cmd->add_option("--to", *to, "Segment end x,y,z")->required();
  auto* o_opt = cmd->add_option("--orientation", *orientation, "Cube orientation r00,...,r22 (row-major rotation)");
  cmd->add_option("--seed", *seed, "Random cube orientation from this seed (0 = world-aligned)")->excludes(o_opt);
  cmd->add_flag("--witness", *witness, "Add one witness (face, x, y, t) per visible triangle");
  cmd->callback([=] {
    auto limit = thread_limit(a->threads);
    vislib::SegmentOptions so = segment_options(*a);
    so.want_witnesses = *witness;
    if (!orientation->empty()) {
      auto m = parse_doubles(*orientation, "--orientation", 9);
      std::copy(m.begin(), m.end(), so.orientation.m);
      if (!vislib::is_rotation(so.orientation))
        throw CLI::ValidationError("--orientation", "not a rotation matrix (orthonormal, det +1)");
    } else if (*seed != 0) {
      so.orientation = vislib::run_orientation(*seed, 0, 1);
    }
    vislib::Vec3 v0 = parse_vec3(*from, "--from"), v1 = parse_vec3(*to, "--to");
    double load_s;
    vislib::Scene scene = load(*a, load_s);
    vislib::SegmentResult r = vislib::segment_visibility(scene, v0, v1, so);
    json j = {{"scene", a->scene},
              {"resolution", so.resolution},
              {"near", so.near},
              {"eps_len", so.eps_len},
              {"from", vec_json(v0)},
              {"to", vec_json(v1)},
              {"orientation", mat_json(so.orientation)},
              {"granularity", a->granularity},
              {"mode", a->mode},
              {"states", scene.state_count()},
              {"visible", at_granularity(scene, r.visible, r.visible_spheres, a->granularity)},
              {"visible_spheres", r.visible_spheres},
              {"visible_triangles", r.visible.size()}};
    json w = json::array();
    for (const auto& x : r.witnesses)
      w.push_back({{x.is_sphere ? "sphere" : "tri", x.tri}, {"face", x.face}, {"x", x.x}, {"y", x.y}, {"t", x.t},
                   {"tau", x.tau}});
    j["witnesses"] = w;
    j["timings"] = {{"load_seconds", load_s}, {"visibility_seconds", r.stats.seconds}};
    j["counts"] = counts_json(r.stats);
    j["counts"]["scene_triangles"] = scene.triangle_count();
    j["counts"]["peak_rss_bytes"] = peak_rss_bytes();
    write_json(a->json_out, j);
    std::fprintf(stderr, "pvs segment: %zu of %zu triangles and %zu of %zu spheres visible (%.3f s, %.2f pieces/pixel)\n",
                 r.visible.size(), scene.triangle_count(), r.visible_spheres.size(), scene.sphere_count(),
                 r.stats.seconds, r.stats.pieces_per_pixel());
  });
}

void add_region(CLI::App& app) {
  auto a = std::make_shared<VisibilityArgs>();
  auto box = std::make_shared<std::string>();
  auto runs = std::make_shared<int>(1);
  auto seed = std::make_shared<uint64_t>(1);
  CLI::App* cmd = app.add_subcommand(
      "region",
      "Triangles visible from a view region: from-segment runs on the perimeter of a view "
      "rectangle (a box flat along one axis) or of a box, K cube orientations each, united.");
  add_common(cmd, *a);
  cmd->add_option("--box", *box, "Region x0,y0,z0,x1,y1,z1 (flat along one axis = view rectangle)")->required();
  cmd->add_option("--runs", *runs, "Cube orientations per perimeter segment (run 0 world-aligned)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", *seed, "Seed of the random orientations")->capture_default_str();
  cmd->callback([=] {
    auto limit = thread_limit(a->threads);
    auto b = parse_doubles(*box, "--box", 6);
    vislib::Box3 region;
    region.extend({b[0], b[1], b[2]});
    region.extend({b[3], b[4], b[5]});
    vislib::RegionOptions ro;
    ro.segment = segment_options(*a);
    ro.runs = *runs;
    ro.seed = *seed;
    double load_s;
    vislib::Scene scene = load(*a, load_s);
    bool tty = isatty(fileno(stderr));
    auto r = vislib::region_visibility(scene, region, ro, [&](size_t done, size_t total) {
      std::fprintf(stderr, tty ? "\rpvs region: run %zu/%zu" : "pvs region: run %zu/%zu\n", done, total);
      if (tty && done == total) std::fprintf(stderr, "\n");
    });
    json segs = json::array();
    for (size_t s = 0; s < r.segments.size(); ++s) {
      json runs_j = json::array();
      for (const auto& rec : r.runs) {
        if (rec.segment != s) continue;
        runs_j.push_back({{"run", rec.run},
                          {"orientation", mat_json(rec.orientation)},
                          {"visible", at_granularity(scene, rec.visible, rec.visible_spheres, a->granularity)},
                          {"visible_spheres", rec.visible_spheres},
                          {"timings", {{"visibility_seconds", rec.stats.seconds}}},
                          {"counts", counts_json(rec.stats)},
                          {"union_triangles_after", rec.union_size_after},
                          {"cumulative_seconds", rec.seconds_after}});
      }
      segs.push_back({{"from", vec_json(r.segments[s].from)}, {"to", vec_json(r.segments[s].to)}, {"runs", runs_j}});
    }
    json j = {{"scene", a->scene},
              {"resolution", ro.segment.resolution},
              {"near", ro.segment.near},
              {"eps_len", ro.segment.eps_len},
              {"box", {{"min", vec_json(region.min)}, {"max", vec_json(region.max)}}},
              {"runs", ro.runs},
              {"seed", ro.seed},
              {"granularity", a->granularity},
              {"segments", segs},
              {"mode", a->mode},
              {"states", scene.state_count()},
              {"visible", at_granularity(scene, r.visible, r.visible_spheres, a->granularity)},
              {"visible_spheres", r.visible_spheres},
              {"visible_triangles", r.visible.size()},
              {"timings", {{"load_seconds", load_s}, {"visibility_seconds", r.seconds}}},
              {"counts", {{"scene_triangles", scene.triangle_count()}, {"peak_rss_bytes", peak_rss_bytes()}}}};
    write_json(a->json_out, j);
    std::fprintf(stderr, "pvs region: %zu of %zu triangles visible from %zu segments x %d runs (%.3f s)\n",
                 r.visible.size(), scene.triangle_count(), r.segments.size(), ro.runs, r.seconds);
  });
}

Registration segment_registration("segment", add_segment);
Registration region_registration("region", add_region);

}  // namespace
}  // namespace pvs_cli
