// pvs view: the near-far frame of a cell's visible set (near-far paper §3, CloVR §3) from a user
// eye, its ground truth (the full scene) and error heat map, and the metrics: epsilon, PSNR, SSIM,
// OVC, object pixel agreement, CloVR's OFC with and without the Eq. 1 morph, triangles per region,
// and with --grow the continuity (minimum SSIM between consecutive frames) while the near region
// grows ring by ring.
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
#include "cli/view_options.h"
#include "cli/view_report.h"
#include "pvs_format/pvs_format.h"
#include "runtime/near_far.h"
#include "vislib/bake/cell_set.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/render/near_far_render.h"
#include "vislib/render/near_region_growth.h"
#include "vislib/render/view_setup.h"
#include "vislib/scene/scene_fingerprint.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

// The visible set of the eye's cell (vislib/bake/cell_set.h), or a message and exit 2.
vislib::CellViewSet read_view_cell(const ViewArgs& a, const vislib::Scene& full_scene,
                                   vislib::Vec3 eye) {
  vislib::CellViewSet v = vislib::read_cell_view_set(a.file, full_scene, eye);
  if (v.where.status == vislib::PointCell::NoCell) {
    std::fprintf(stderr, "pvs: error: no cell contains %s\n", a.at.c_str());
    throw Exit{2};
  }
  if (v.where.status == vislib::PointCell::Absent) {
    std::fprintf(stderr, "pvs: error: cell %u is absent from this shard\n", v.where.cell);
    throw Exit{2};
  }
  return v;
}

// --centre, or the cell's default (never a point inside a building).
vislib::Vec3 view_centre(const ViewArgs& a, const vislib::Scene& full_scene,
                         const vislib::CellViewSet& v) {
  if (!a.centre.empty()) return parse_vec3(a.centre, "--centre");
  const uint32_t cell = v.where.cell;
  const std::optional<vislib::ViewCentre> c =
      vislib::default_view_centre(full_scene, v.view_region, v.centre);
  if (!c)
    throw vislib::InputError(a.file, "every sample of cell " + std::to_string(cell) +
                                         "'s view region is enclosed by the scene: give --centre");
  if (c->moved)
    warn("the centre of cell " + std::to_string(cell) +
         "'s view region is enclosed by the scene; the free point " + std::to_string(c->point.x) +
         "," + std::to_string(c->point.y) + "," + std::to_string(c->point.z) + " is the centre");
  return c->point;
}

// --grow: both growths of the near region (vislib/render/near_region_growth.h), as JSON.
json grow_json(const ViewArgs& a, const vislib::Scene& scene, const vislib::EmbreeScene& rt,
               const std::vector<uint32_t>& tris, const vislib::Camera& cam,
               const vislib::Frame& truth, const vislib::NearFarSettings& s) {
  const vislib::GrowthPlan plan =
      vislib::plan_growth(scene, tris, s.centre, s.r2, a.rings, a.merge_min);
  vislib::GrowthSettings g;
  g.centre = s.centre;
  g.near_fraction = a.near_fraction;
  g.env_size = s.env_size;
  g.frames_per_ring = a.frames_per_ring;
  vislib::ScheduleFrameFn on_frame;
  if (!a.frames_out.empty())
    on_frame = [&a, &cam](const std::string& schedule, size_t i, const vislib::GrowthStep&,
                          const vislib::Frame& f) {
      char name[64];
      std::snprintf(name, sizeof name, "/%s_%04zu.png", schedule.c_str(), i);
      vislib::write_rgb8_image(a.frames_out + name, cam.width, cam.height, f.rgb);
    };
  if (!a.frames_out.empty()) std::filesystem::create_directories(a.frames_out);
  const vislib::GrowthComparison runs =
      vislib::grow_near_region_both(scene, rt, tris, cam, truth, plan, g, on_frame);
  const json merged_json = growth_json(runs.merged), equal_json = growth_json(runs.equal_area);
  return {{"min_consecutive_ssim", merged_json["min_consecutive_ssim"]},
          {"near_fraction", a.near_fraction},
          {"ring_area", plan.ring_area},
          {"frames_per_ring", a.frames_per_ring},
          {"ring_contribution", plan.contribution},
          {"merge_min_contribution", plan.merge_min_contribution},
          {"merged", merged_json},
          {"equal_area", equal_json}};
}

void run_view(const ViewArgs& a, const ViewStereoArgs& stereo) {
  const ViewInputs in = parse_view(a);
  const vislib::Vec3 eye = in.eye, target = in.target;
  const int fw = in.fw, fh = in.fh;
  const vislib::Scene full_scene = load_scene_for_cli(a.scene, a.states);  // every key state
  const vislib::CellViewSet v = read_view_cell(a, full_scene, eye);
  const vislib::Vec3 centre = view_centre(a, full_scene, v);
  const double eye_axis =
      pvs_runtime::axis_distance({eye.x, eye.y, eye.z}, {centre.x, centre.y, centre.z});
  vislib::NearFarRadii radii = vislib::default_near_far_radii(v.box, eye_axis);
  if (!in.radii.empty()) radii = {in.radii[0], in.radii[1]};
  if (!(eye_axis < radii.r1))
    throw CLI::ValidationError("--near-far", "the eye is " + std::to_string(eye_axis) +
                                                 " from the centre's axis: r1 must exceed it");

  const vislib::Camera cam = vislib::look_at_camera(eye, target, fw, fh);
  vislib::NearFarSettings s;
  s.centre = centre;
  s.r1 = radii.r1;
  s.r2 = radii.r2;
  s.env_size = a.env_size > 0 ? a.env_size : fh;
  s.lookup = a.lookup == "cylinder" ? vislib::EnvironmentLookup::CylinderR2
                                    : vislib::EnvironmentLookup::EyeDirection;

  // Everything is rendered from the scene at tau (one state); the moving triangles are those of
  // the loaded key states.
  const std::vector<uint8_t> moving = vislib::moving_triangles(full_scene);
  s.dynamic = moving.data();
  const vislib::Scene scene = vislib::scene_at(full_scene, a.tau);
  const std::vector<uint32_t>& tris = v.triangles;
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
  j["cell"] = v.where.cell;
  j["eye"] = {eye.x, eye.y, eye.z};
  j["look"] = {target.x, target.y, target.z};
  j["centre"] = {centre.x, centre.y, centre.z};
  j["r1"] = s.r1;
  j["r2"] = s.r2;
  j["tau"] = a.tau;
  j["states"] = full_scene.state_count();
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
  if (a.grow) j["continuity"] = grow_json(a, scene, rt, tris, cam, truth, s);
  if (stereo.enabled()) j["stereo"] = run_view_stereo(stereo, a.file, scene, rt, cam, a.output);
  print_view(j, rc, !moving.empty() && full_scene.is_dynamic());
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
  add_view_options(cmd, *a);
  auto ods = std::make_shared<OdsViewArgs>();
  add_ods_view_options(cmd, ods);
  std::shared_ptr<ViewStereoArgs> stereo = add_view_stereo_options(cmd);
  cmd->callback([a, ods, stereo] {
    // Every output checked before any work, --ods and --stereo too.
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
