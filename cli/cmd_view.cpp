// pvs view: the near-far frame of a cell's visible set (near-far paper §3, CloVR §3) from a user
// eye, its ground truth (the full scene) and error heat map, and the metrics: epsilon, PSNR, SSIM,
// OVC, OFC with and without the Eq. 1 morph, triangles per region, and with --grow the continuity
// (minimum SSIM between consecutive frames) while the near region grows ring by ring.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/cmd_view_ods.h"
#include "cli/cmd_view_stereo.h"
#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/view_report.h"
#include "pvs_format/pvs_format.h"
#include "runtime/near_far.h"
#include "vislib/bake/cell_set.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/discontinuity.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/render/near_far_render.h"
#include "vislib/render/near_region_growth.h"
#include "vislib/scene/scene_fingerprint.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

struct ViewArgs {
  std::string file, scene, at, look, near_far, centre, output, json_path, frames_out;
  std::string frame = "640x480", lookup = "eye";
  bool grow = false;
  int env_size = 0, rings = 8, states = 1, frames_per_ring = 4;
  double near_fraction = 0.7, tau = 0, merge_min = -1;
  double delta_radius = vislib::kDiscontinuityRadius;
};

// The cell of the eye and its visible triangles, read from the PVS file for the scene.
struct ViewCell {
  vislib::Scene full_scene;  // every key state
  uint32_t cell = 0;
  std::vector<uint32_t> tris;
  vislib::Vec3 centre;  // of the cell's view region
  vislib::Box3 region;  // the cell's view region
  pvs::Box box;         // the cell's lookup box
};

ViewCell read_view_cell(const ViewArgs& a, vislib::Vec3 eye) {
  ViewCell v;
  v.full_scene = load_scene_for_cli(a.scene, a.states);
  pvs::ReadOptions opt;
  opt.expected_fingerprint = vislib::scene_fingerprint(v.full_scene);
  vislib::reading_pvs(a.file, [&] {
    pvs::Reader r = pvs::Reader::from_file(a.file, opt);
    const pvs::FileInfo& info = r.info();
    vislib::check_universe(a.file, info, v.full_scene);
    double q[3] = {eye.x, eye.y, eye.z};
    std::optional<uint32_t> c = info.layout.find_cell(q);
    if (!c) {
      std::fprintf(stderr, "pvs: error: no cell contains %s\n", a.at.c_str());
      throw Exit{2};
    }
    v.cell = *c;
    if (r.block_info(v.cell).encoding == pvs::Encoding::Absent) {
      std::fprintf(stderr, "pvs: error: cell %u is absent from this shard\n", v.cell);
      throw Exit{2};
    }
    v.tris =
        vislib::visible_triangles(v.full_scene, r.read_cell(v.cell), vislib::granularity_of(info));
    v.centre = vislib::view_region_centre(info.layout, v.cell);
    v.region = vislib::to_box3(info.layout.view_region(v.cell));
    v.box = info.layout.cell_box(v.cell);
  });
  return v;
}

void run_view(const ViewArgs& a, const ViewStereoArgs& stereo) {
  int fw = 0, fh = 0;
  if (std::sscanf(a.frame.c_str(), "%dx%d", &fw, &fh) != 2 || fw < 11 || fh < 11 || fw > 8192 ||
      fh > 8192)
    throw CLI::ValidationError("--frame",
                               "expected WxH with 11 <= W, H <= 8192, got '" + a.frame + "'");
  std::vector<double> radii;
  if (!a.near_far.empty()) {
    radii = parse_doubles(a.near_far, "--near-far", 2);
    if (!(radii[0] >= 0 && radii[0] < radii[1]))
      throw CLI::ValidationError("--near-far", "expected 0 <= r1 < r2, got '" + a.near_far + "'");
  }
  const vislib::Vec3 eye = parse_vec3(a.at, "--at"), target = parse_vec3(a.look, "--look");
  if (length(target - eye) == 0) throw CLI::ValidationError("--look", "must differ from --at");

  ViewCell v = read_view_cell(a, eye);
  vislib::Vec3 centre = a.centre.empty() ? v.centre : parse_vec3(a.centre, "--centre");
  if (a.centre.empty()) {
    // Never a point inside a building as the default centre (issue 17 item 6).
    vislib::CellFreeSpace fs = vislib::cell_free_space(v.full_scene, v.region);
    if (fs.centre_enclosed) {
      if (!fs.free_point)
        throw vislib::InputError(a.file,
                                 "every sample of cell " + std::to_string(v.cell) +
                                     "'s view region is enclosed by the scene: give --centre");
      centre = *fs.free_point;
      warn("the centre of cell " + std::to_string(v.cell) +
           "'s view region is enclosed by the scene; the free point " + std::to_string(centre.x) +
           "," + std::to_string(centre.y) + "," + std::to_string(centre.z) + " is the centre");
    }
  }
  const double eye_axis =
      pvs_runtime::axis_distance({eye.x, eye.y, eye.z}, {centre.x, centre.y, centre.z});
  if (radii.empty()) {  // derived from the cell, as pvs_rt_cell_near_far (docs/runtime.md)
    const double half_diagonal =
        0.5 * std::hypot(v.box.max[0] - v.box.min[0], v.box.max[2] - v.box.min[2]);
    const double r1 = 1.25 * std::max({half_diagonal, eye_axis, 1e-6});
    radii = {r1, 2 * r1};
  }
  if (!(eye_axis < radii[0]))
    throw CLI::ValidationError("--near-far", "the eye is " + std::to_string(eye_axis) +
                                                 " from the centre's axis: r1 must exceed it");

  vislib::Camera cam;
  cam.eye = eye;
  cam.forward = target - eye;
  if (length(cross(cam.forward, cam.up)) == 0) cam.up = {0, 0, -1};
  cam.width = fw;
  cam.height = fh;
  vislib::NearFarSettings s;
  s.centre = centre;
  s.r1 = radii[0];
  s.r2 = radii[1];
  s.env_size = a.env_size > 0 ? a.env_size : fh;
  s.lookup = a.lookup == "cylinder" ? vislib::EnvironmentLookup::CylinderR2
                                    : vislib::EnvironmentLookup::EyeDirection;

  // Everything is rendered from the scene at tau (one state); the moving triangles are those of
  // the loaded key states.
  const std::vector<uint8_t> moving = vislib::moving_triangles(v.full_scene);
  s.dynamic = moving.data();
  const vislib::Scene scene = vislib::scene_at(v.full_scene, a.tau);
  const std::vector<uint32_t>& tris = v.tris;
  vislib::EmbreeScene rt(scene, 0.0, eye);
  vislib::Frame truth = vislib::render_frame(scene, rt, cam);
  vislib::RegionCounts rc;
  vislib::PixelSources morphed_sources, unmorphed_sources;
  vislib::Frame morphed = vislib::render_near_far(scene, rt, tris, cam, s, &rc, &morphed_sources);
  s.morph = false;
  vislib::Frame unmorphed =
      vislib::render_near_far(scene, rt, tris, cam, s, nullptr, &unmorphed_sources);

  vislib::write_rgb8_image(a.output, fw, fh, morphed.rgb);
  vislib::write_rgb8_image(sibling(a.output, "_truth"), fw, fh, truth.rgb);
  vislib::write_rgb8_image(sibling(a.output, "_nomorph"), fw, fh, unmorphed.rgb);
  vislib::write_rgb8_image(sibling(a.output, "_heat"), fw, fh,
                           vislib::error_heat_map(morphed, vislib::missed_pixels(truth, morphed)));

  json j = quality_json(scene, truth, morphed);
  j.update(near_far_json(truth, morphed, morphed_sources, cam, a.delta_radius));
  j["file"] = a.file;
  j["cell"] = v.cell;
  j["eye"] = {eye.x, eye.y, eye.z};
  j["look"] = {target.x, target.y, target.z};
  j["centre"] = {centre.x, centre.y, centre.z};
  j["r1"] = s.r1;
  j["r2"] = s.r2;
  j["tau"] = a.tau;
  j["states"] = v.full_scene.state_count();
  j["frame"] = {fw, fh};
  j["env_size"] = s.env_size;
  j["lookup"] = a.lookup;
  j["triangles"] = {
      {"scene", scene.triangle_count()},
      {"visible", tris.size()},
      {"near", rc.near},
      {"intermediate", rc.intermediate},
      {"far", rc.far},
      {"env_map", rc.env_map},
      {"moving_in_scene", size_t(std::count(moving.begin(), moving.end(), uint8_t(1)))},
      {"far_dynamic_drawn", rc.far_dynamic},
      {"far_dynamic_shown", rc.far_dynamic_shown}};
  j["without_morph"] = quality_json(scene, truth, unmorphed);
  j["without_morph"].update(
      near_far_json(truth, unmorphed, unmorphed_sources, cam, a.delta_radius));
  // Baseline: the cell's visible set rendered from geometry, no near-far partition.
  vislib::Frame pvs_frame = vislib::render_frame(
      scene, rt, cam, vislib::triangle_mask(scene.triangle_count(), tris).data());
  j["pvs_only"] = quality_json(scene, truth, pvs_frame);
  j["images"] = {{"near_far", a.output},
                 {"truth", sibling(a.output, "_truth")},
                 {"nomorph", sibling(a.output, "_nomorph")},
                 {"heat_map", sibling(a.output, "_heat")}};

  if (a.grow) {
    const vislib::GrowthPlan plan =
        vislib::plan_growth(scene, tris, centre, s.r2, a.rings, a.merge_min);
    vislib::GrowthSettings g;
    g.centre = centre;
    g.near_fraction = a.near_fraction;
    g.env_size = s.env_size;
    g.frames_per_ring = a.frames_per_ring;
    auto frames_to = [&](const char* prefix) {
      if (!a.frames_out.empty()) {
        std::filesystem::create_directories(a.frames_out);
        g.on_frame = [&a, prefix, fw, fh](size_t i, const vislib::GrowthStep&,
                                          const vislib::Frame& f) {
          char name[64];
          std::snprintf(name, sizeof name, "/%s_%04zu.png", prefix, i);
          vislib::write_rgb8_image(a.frames_out + name, fw, fh, f.rgb);
        };
      }
    };
    frames_to("merged");
    json merged_json =
        growth_json(vislib::grow_near_region(scene, rt, tris, cam, truth, plan.merged, g));
    frames_to("equal_area");
    json equal_json =
        growth_json(vislib::grow_near_region(scene, rt, tris, cam, truth, plan.equal, g));
    j["continuity"] = {{"min_consecutive_ssim", merged_json["min_consecutive_ssim"]},
                       {"near_fraction", a.near_fraction},
                       {"ring_area", plan.ring_area},
                       {"frames_per_ring", a.frames_per_ring},
                       {"ring_contribution", plan.contribution},
                       {"merge_min_contribution", plan.merge_min_contribution},
                       {"merged", merged_json},
                       {"equal_area", equal_json}};
  }

  if (stereo.enabled()) j["stereo"] = run_view_stereo(stereo, a.file, scene, rt, cam, a.output);
  print_view(j, rc, !moving.empty() && v.full_scene.is_dynamic());
  if (a.json_path == "-") {
    std::printf("%s\n", j.dump(1).c_str());
  } else if (!a.json_path.empty()) {
    vislib::write_file_atomic(a.json_path, j.dump(1) + "\n");
  }
}

void add_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand("view",
                                     "Render the near-far frame of the cell at --at (near region "
                                     "from geometry, intermediate region "
                                     "morphed by Eq. 1, far region through an environment map from "
                                     "the centre), with the full-scene "
                                     "frame, the error heat map and the metrics");
  cmd->add_option("PVS", a->file, "PVS file")->required();
  cmd->add_option("--scene", a->scene,
                  "The scene the PVS was baked for (checked by its fingerprint)")
      ->required();
  cmd->add_option("--at", a->at, "User eye x,y,z (its cell's visible set is used)")->required();
  cmd->add_option("--look", a->look, "Point x,y,z the user looks at (required without --ods)");
  cmd->add_option(
      "--near-far", a->near_far,
      "Radii r1,r2 of the cylinders about the centre (scene units; default: r1 = 1.25 x "
      "the half x-z diagonal of the cell's box, r2 = 2 r1, as pvs_rt_cell_near_far)");
  cmd->add_option("--frames-out", a->frames_out,
                  "--grow: also write every growth frame as DIR/merged_NNNN.png and "
                  "DIR/equal_area_NNNN.png");
  cmd->add_option("--centre", a->centre,
                  "Centre O x,y,z of the cylinders and environment map (default: the "
                  "centre of the cell's view region, or the free sample of the region nearest "
                  "it when that is enclosed by the scene)");
  cmd->add_flag("--grow", a->grow,
                "Also render the progressive near region (CloVR rings up to r2) and report "
                "the minimum SSIM between consecutive frames");
  cmd->add_option("--rings", a->rings, "--grow: equal-area rings up to r2")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--frames-per-ring", a->frames_per_ring,
                  "--grow: frames over which each ring is injected (Alg. 1 with R animated from "
                  "the previous "
                  "ring's radius to the ring's)")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  cmd->add_option(
      "--merge-min", a->merge_min,
      "--grow: merged rings contribute at least this many visible triangles (entering the near "
      "region) each (default: the mean over the equal-area rings)");
  cmd->add_option("--states", a->states,
                  "Key states to sample glTF animations into (as for the bake)")
      ->check(in_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--time", a->tau, "Animation time tau in [0,1] of the frame (dynamic scenes)")
      ->check(in_range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--near-fraction", a->near_fraction, "--grow: R_n / R of Alg. 1")
      ->check(in_range(0.01, 0.99))
      ->capture_default_str();
  cmd->add_option("--frame", a->frame, "Frame size WxH")->capture_default_str();
  cmd->add_option("--delta-radius", a->delta_radius,
                  "Neighbourhood radius (pixels) of the near-far paper's discontinuity metric "
                  "delta (Eq. 8), reported with and without the morph")
      ->check(CLI::Range(0.5, 1000.0))
      ->capture_default_str();
  cmd->add_option("--env-size", a->env_size,
                  "Environment map face side in pixels (default: the frame height)")
      ->check(in_range(0, 8192));
  cmd->add_option("--lookup", a->lookup,
                  "Environment map lookup: eye (along the eye ray, the paper) or cylinder "
                  "(from O through the eye ray's exit point on the r2 cylinder)")
      ->check(CLI::IsMember({"eye", "cylinder"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output,
                  "Near-far frame (.png); <out>_truth.png, <out>_heat.png and "
                  "<out>_nomorph.png are written next to it")
      ->required();
  cmd->add_option("--json", a->json_path, "Write the metrics as JSON ('-' = stdout)");
  auto ods = std::make_shared<OdsViewArgs>();
  add_ods_view_options(cmd, ods);
  std::shared_ptr<ViewStereoArgs> stereo = add_view_stereo_options(cmd);
  cmd->callback([a, ods, stereo] {
    // Every output checked before any work, --ods and --stereo too (issue 17 item 1).
    check_output_file(a->output, "--output");
    if (!a->json_path.empty()) check_output_file(a->json_path, "--json", true);
    if (ods->enabled && stereo->enabled())
      throw CLI::ValidationError("--stereo", "cannot be combined with --ods");
    if (ods->enabled)
      return run_view_ods(*ods,
                          {a->file, a->scene, a->at, a->output, a->json_path, a->states, a->tau});
    if (a->look.empty()) throw CLI::ValidationError("--look", "is required (except with --ods)");
    stereo->ipd = ods->ipd_m * ods->units_per_metre;  // --ipd and --units-per-metre are shared
    run_view(*a, *stereo);
  });
}

Registration view_registration("view", add_view);

}  // namespace
}  // namespace pvs_cli
