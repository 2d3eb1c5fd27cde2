// pvs segment / pvs region: continuous from-segment visibility from the command line.
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "cli/visibility_common.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/kernel/region_visibility.h"
#include "vislib/scene/import.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

void add_segment(CLI::App& app) {
  auto a = std::make_shared<VisibilityArgs>();
  auto from = std::make_shared<std::string>(), to = std::make_shared<std::string>();
  auto orientation = std::make_shared<std::string>();
  auto seed = std::make_shared<uint64_t>(0);
  auto witness = std::make_shared<bool>(false);
  auto transform = std::make_shared<TransformArgs>();
  CLI::App* cmd = app.add_subcommand(
      "segment",
      "Triangles visible from a view segment: continuous from-segment visibility over a cubemap "
      "(six N x N faces) translating from --from to --to.");
  add_common(cmd, *a);
  cmd->add_option("--from", *from, "Segment start x,y,z")->required();
  cmd->add_option("--to", *to, "Segment end x,y,z")->required();
  auto* o_opt = cmd->add_option("--orientation", *orientation,
                                "Cube orientation r00,...,r22 (row-major rotation)");
  cmd->add_option("--seed", *seed, "Random cube orientation from this seed (0 = world-aligned)")
      ->excludes(o_opt);
  cmd->add_flag("--witness", *witness, "Add one witness (face, x, y, t) per visible triangle");
  add_transform_options(cmd, *transform,
                        "the scene, --from, --to and the cube orientation (and --near by S)");
  cmd->callback([=] {
    check_output_file(a->json_out, "--json", true);  // before any work
    run_with_threads(a->threads, [&] {
      vislib::SegmentOptions so = segment_options(*a);
      so.want_witnesses = *witness;
      if (!orientation->empty()) {
        auto m = parse_doubles(*orientation, "--orientation", 9);
        std::copy(m.begin(), m.end(), so.orientation.m);
        if (!vislib::is_rotation(so.orientation))
          throw CLI::ValidationError("--orientation",
                                     "not a rotation matrix (orthonormal, det +1)");
      } else if (*seed != 0) {
        so.orientation = vislib::run_orientation(*seed, 0, 1);
      }
      vislib::Vec3 v0 = parse_vec3(*from, "--from"), v1 = parse_vec3(*to, "--to");
      double load_s;
      vislib::Scene scene = load(*a, load_s);
      if (transform->any()) {  // the whole computation moved: scene, segment, cube, near
        const vislib::Similarity sim = parse_transform(*transform);
        transform_scene_for_cli(scene, sim);
        v0 = vislib::apply(sim, v0);
        v1 = vislib::apply(sim, v1);
        so.orientation = vislib::multiply(sim.rotation, so.orientation);
        so.near *= sim.scale;
      }
      vislib::TriangleBvh tree;
      const double bvh_s = maybe_build_bvh(*a, false, scene, tree, so);
      vislib::EdgeLines lines;
      const double lines_s = build_edge_lines(scene, lines, so);
      vislib::SegmentResult r = vislib::with_memory_stage(
          "computing from-segment visibility at N = " + std::to_string(so.resolution) + " on " +
              std::to_string(scene.triangle_count()) + " triangles",
          [&] { return vislib::segment_visibility(scene, v0, v1, so); });
      json j = {{"scene", a->scene},
                {"resolution", so.resolution},
                {"near", so.near},
                {"eps_len", so.eps_len},
                {"from", vec_json(v0)},
                {"to", vec_json(v1)},
                {"orientation", mat_json(so.orientation)},
                {"granularity", a->granularity},
                {"mode", a->mode},
                {"coplanar", a->coplanar},
                {"eps_z", so.eps_z},
                {"states", scene.state_count()},
                {"visible", at_granularity(scene, r.visible, r.visible_spheres, a->granularity)},
                {"visible_spheres", r.visible_spheres},
                {"visible_triangles", r.visible.size()}};
      json w = json::array();
      for (const auto& x : r.witnesses) w.push_back(witness_json(x));
      j["witnesses"] = w;
      // Both times whatever --bvh says: building the tree (0 when none was built) and the
      // kernel's run, which never includes the build (nor that of the edge lines).
      j["timings"] = {{"load_seconds", load_s},
                      {"bvh_seconds", bvh_s},
                      {"edge_lines_seconds", lines_s},
                      {"visibility_seconds", r.stats.seconds},
                      {"bvh_and_visibility_seconds", bvh_s + r.stats.seconds}};
      j["bvh"] = so.bvh != nullptr;
      j["counts"] = counts_json(r.stats);
      j["counts"]["scene_triangles"] = scene.triangle_count();
      j["counts"]["peak_rss_bytes"] = peak_rss_bytes();
      write_json(a->json_out, j);
      if (show_progress())
        std::fprintf(
            stderr,
            "pvs segment: %zu of %zu triangles and %zu of %zu spheres visible (%.3f s, %.2f "
            "pieces/pixel)\n",
            r.visible.size(), scene.triangle_count(), r.visible_spheres.size(),
            scene.sphere_count(), r.stats.seconds, r.stats.pieces_per_pixel());
    });
  });
}

void add_region(CLI::App& app) {
  auto a = std::make_shared<VisibilityArgs>();
  auto box = std::make_shared<std::string>();
  auto runs = std::make_shared<int>(1);
  auto seed = std::make_shared<uint64_t>(1);
  auto witness = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "region",
      "Triangles visible from a view region: from-segment runs on the perimeter of a view "
      "rectangle (a box flat along one axis) or of a box, K cube orientations each, united.");
  add_common(cmd, *a);
  cmd->add_option("--box", *box, "Region x0,y0,z0,x1,y1,z1 (flat along one axis = view rectangle)")
      ->required();
  cmd->add_option("--runs", *runs, "Cube orientations per perimeter segment (run 0 world-aligned)")
      ->check(in_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", *seed, "Seed of the random orientations")->capture_default_str();
  cmd->add_flag("--witness", *witness,
                "Add one witness per id of the union: the perimeter segment and run that saw it, "
                "and its (face, x, y, t, tau) in that run");
  cmd->callback([=] {
    check_output_file(a->json_out, "--json", true);  // before any work
    run_with_threads(a->threads, [&] {
      auto b = parse_doubles(*box, "--box", 6);
      vislib::Box3 region;
      region.extend({b[0], b[1], b[2]});
      region.extend({b[3], b[4], b[5]});
      vislib::RegionOptions ro;
      ro.segment = segment_options(*a);
      ro.segment.want_witnesses = *witness;
      ro.runs = *runs;
      ro.seed = *seed;
      double load_s;
      vislib::Scene scene = load(*a, load_s);
      vislib::TriangleBvh tree;
      const double bvh_s = maybe_build_bvh(*a, true, scene, tree, ro.segment);
      vislib::EdgeLines lines;
      build_edge_lines(scene, lines, ro.segment);
      bool tty = isatty(fileno(stderr));
      auto r = vislib::region_visibility(scene, region, ro, [&](size_t done, size_t total) {
        if (!show_progress()) return;
        if (show_progress())
          std::fprintf(stderr, tty ? "\rpvs region: run %zu/%zu" : "pvs region: run %zu/%zu\n",
                       done, total);
        if (tty && done == total) std::fprintf(stderr, "\n");
      });
      json segs = json::array();
      for (size_t s = 0; s < r.segments.size(); ++s) {
        json runs_j = json::array();
        for (const auto& rec : r.runs) {
          if (rec.segment != s) continue;
          runs_j.push_back(
              {{"run", rec.run},
               {"orientation", mat_json(rec.orientation)},
               {"visible", at_granularity(scene, rec.visible, rec.visible_spheres, a->granularity)},
               {"visible_spheres", rec.visible_spheres},
               {"timings", {{"visibility_seconds", rec.stats.seconds}}},
               {"counts", counts_json(rec.stats)},
               {"union_triangles_after", rec.union_size_after},
               {"cumulative_seconds", rec.seconds_after}});
        }
        segs.push_back({{"from", vec_json(r.segments[s].from)},
                        {"to", vec_json(r.segments[s].to)},
                        {"runs", runs_j}});
      }
      json j = {
          {"scene", a->scene},
          {"resolution", ro.segment.resolution},
          {"near", ro.segment.near},
          {"eps_len", ro.segment.eps_len},
          {"box", {{"min", vec_json(region.min)}, {"max", vec_json(region.max)}}},
          {"runs", ro.runs},
          {"seed", ro.seed},
          {"granularity", a->granularity},
          {"segments", segs},
          {"mode", a->mode},
          {"coplanar", a->coplanar},
          {"eps_z", ro.segment.eps_z},
          {"states", scene.state_count()},
          {"visible", at_granularity(scene, r.visible, r.visible_spheres, a->granularity)},
          {"visible_spheres", r.visible_spheres},
          {"visible_triangles", r.visible.size()},
          {"timings",
           {{"load_seconds", load_s}, {"bvh_seconds", bvh_s}, {"visibility_seconds", r.seconds}}},
          {"counts",
           {{"scene_triangles", scene.triangle_count()}, {"peak_rss_bytes", peak_rss_bytes()}}}};
      if (*witness) {
        json w = json::array();
        for (const auto& x : r.witnesses) {
          json e = witness_json(x.witness);
          e["segment"] = x.segment;
          e["run"] = x.run;
          w.push_back(e);
        }
        j["witnesses"] = w;
      }
      write_json(a->json_out, j);
      if (show_progress())
        std::fprintf(
            stderr,
            "pvs region: %zu of %zu triangles visible from %zu segments x %d runs (%.3f s)\n",
            r.visible.size(), scene.triangle_count(), r.segments.size(), ro.runs, r.seconds);
    });
  });
}

Registration segment_registration("segment", add_segment);
Registration region_registration("region", add_region);

}  // namespace
}  // namespace pvs_cli
