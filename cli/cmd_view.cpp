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

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "pvs_format/pvs_format.h"
#include "runtime/near_far.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/render/near_far_render.h"
#include "vislib/scene/scene_fingerprint.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

struct ViewArgs {
  std::string file, scene, at, look, near_far = "10,20", centre, output, json_path;
  std::string frame = "640x480", lookup = "eye";
  bool grow = false;
  int env_size = 0, rings = 8, states = 1, frames_per_ring = 4;
  double near_fraction = 0.7, tau = 0, merge_min = -1;
};

json quality_json(const vislib::Scene& scene, const vislib::Frame& truth, const vislib::Frame& test) {
  vislib::FrameQuality q = vislib::frame_quality(truth, test);
  vislib::ObjectCompletion c = vislib::object_completion(scene, truth, test);
  // Share of pixels showing another triangle than the truth (epsilon compares depths, and the
  // morph and the environment map change depths even where the right surface is shown).
  size_t other = 0;
  for (size_t p = 0; p < truth.pixel_count(); ++p) other += truth.tri[p] != test.tri[p];
  return {{"triangle_mismatch", double(other) / double(truth.pixel_count())},{"epsilon", q.epsilon}, {"missed_pixels", q.missed_pixels},
          {"psnr", std::isfinite(q.psnr) ? json(q.psnr) : json(nullptr)}, {"ssim", q.ssim},
          {"ovc", c.ovc}, {"ofc", c.ofc}, {"objects_in_truth", c.objects}};
}

// "dir/name.png" -> "dir/name<suffix>.png"
std::string sibling(const std::string& out, const std::string& suffix) {
  std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

void add_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Render the near-far frame of the cell at --at (near region from geometry, intermediate region "
              "morphed by Eq. 1, far region through an environment map from the centre), with the full-scene "
              "frame, the error heat map and the metrics");
  cmd->add_option("PVS", a->file, "PVS file")->required();
  cmd->add_option("--scene", a->scene, "The scene the PVS was baked for (checked by its fingerprint)")->required();
  cmd->add_option("--at", a->at, "User eye x,y,z (its cell's visible set is used)")->required();
  cmd->add_option("--look", a->look, "Point x,y,z the user looks at")->required();
  cmd->add_option("--near-far", a->near_far, "Radii r1,r2 of the cylinders about the centre (scene units)")
      ->capture_default_str();
  cmd->add_option("--centre", a->centre,
                  "Centre O x,y,z of the cylinders and environment map (default: the "
                  "centre of the cell's view region, or when that is enclosed by the scene "
                  "the free sample of the region nearest it)");
  cmd->add_flag("--grow", a->grow, "Also render the progressive near region (CloVR rings up to r2) and report "
                                   "the minimum SSIM between consecutive frames");
  cmd->add_option("--rings", a->rings, "--grow: equal-area rings up to r2")->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--frames-per-ring", a->frames_per_ring,
                  "--grow: frames over which each ring is injected (Alg. 1 with R animated from the previous "
                  "ring's radius to the ring's)")->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--merge-min", a->merge_min,
                  "--grow: merged rings contribute at least this many visible triangles (entering the near "
                  "region) each (default: the mean over the equal-area rings)");
  cmd->add_option("--states", a->states, "Key states to sample glTF animations into (as for the bake)")
      ->check(CLI::Range(1, 100000))->capture_default_str();
  cmd->add_option("--time", a->tau, "Animation time tau in [0,1] of the frame (dynamic scenes)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  cmd->add_option("--near-fraction", a->near_fraction, "--grow: R_n / R of Alg. 1")
      ->check(CLI::Range(0.01, 0.99))->capture_default_str();
  cmd->add_option("--frame", a->frame, "Frame size WxH")->capture_default_str();
  cmd->add_option("--env-size", a->env_size, "Environment map face side in pixels (default: the frame height)")
      ->check(CLI::Range(0, 8192));
  cmd->add_option("--lookup", a->lookup, "Environment map lookup: eye (along the eye ray, the paper) or cylinder "
                                         "(from O through the eye ray's exit point on the r2 cylinder)")
      ->check(CLI::IsMember({"eye", "cylinder"}))->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Near-far frame (.png); <out>_truth.png, <out>_heat.png and "
                                            "<out>_nomorph.png are written next to it")->required();
  cmd->add_option("--json", a->json_path, "Write the metrics as JSON ('-' = stdout)");
  cmd->callback([a] {
    int fw = 0, fh = 0;
    if (std::sscanf(a->frame.c_str(), "%dx%d", &fw, &fh) != 2 || fw < 11 || fh < 11 || fw > 8192 || fh > 8192)
      throw CLI::ValidationError("--frame", "expected WxH with 11 <= W, H <= 8192, got '" + a->frame + "'");
    std::vector<double> radii = parse_doubles(a->near_far, "--near-far", 2);
    if (!(radii[0] >= 0 && radii[0] < radii[1]))
      throw CLI::ValidationError("--near-far", "expected 0 <= r1 < r2, got '" + a->near_far + "'");
    const vislib::Vec3 eye = parse_vec3(a->at, "--at"), target = parse_vec3(a->look, "--look");
    if (length(target - eye) == 0) throw CLI::ValidationError("--look", "must differ from --at");

    vislib::Scene full_scene = load_scene_for_cli(a->scene, a->states);
    pvs::ReadOptions opt;
    opt.expected_fingerprint = vislib::scene_fingerprint(full_scene);
    std::vector<uint32_t> tris;
    uint32_t cell = 0;
    vislib::Vec3 centre;
    try {
      pvs::Reader r = pvs::Reader::from_file(a->file, opt);
      const pvs::FileInfo& info = r.info();
      const bool object = info.granularity == pvs::Granularity::Object;
      if ((object ? full_scene.objects.size() : full_scene.triangle_count()) != info.universe)
        throw vislib::InputError(a->file, "universe " + std::to_string(info.universe) + " differs from the scene's");
      double q[3] = {eye.x, eye.y, eye.z};
      std::optional<uint32_t> c = info.layout.find_cell(q);
      if (!c) {
        std::fprintf(stderr, "pvs: error: no cell contains %s\n", a->at.c_str());
        throw Exit{2};
      }
      cell = *c;
      if (r.block_info(cell).encoding == pvs::Encoding::Absent) {
        std::fprintf(stderr, "pvs: error: cell %u is absent from this shard\n", cell);
        throw Exit{2};
      }
      std::vector<uint32_t> ids = r.read_cell(cell);
      if (object) {
        std::vector<uint8_t> keep(full_scene.objects.size(), 0);
        for (uint32_t o : ids) keep[o] = 1;
        for (uint32_t t = 0; t < full_scene.triangle_count(); ++t)
          if (keep[full_scene.triangle_object[t]]) tris.push_back(t);
      } else {
        tris = ids;
      }
      pvs::Box region = info.layout.view_region(cell);
      centre = {(region.min[0] + region.max[0]) / 2, (region.min[1] + region.max[1]) / 2,
                (region.min[2] + region.max[2]) / 2};
      if (a->centre.empty()) {
        // Never a point inside a building as the default centre (issue 17 item 6).
        vislib::CellFreeSpace fs = vislib::cell_free_space(full_scene, vislib::to_box3(region));
        if (fs.centre_enclosed) {
          if (!fs.free_point)
            throw vislib::InputError(a->file,
                                     "every sample of cell " + std::to_string(cell) +
                                         "'s view region is enclosed by the scene: give --centre");
          centre = *fs.free_point;
          warn("the centre of cell " + std::to_string(cell) +
               "'s view region is enclosed by the scene; using " + "the free point " +
               std::to_string(centre.x) + "," + std::to_string(centre.y) + "," +
               std::to_string(centre.z) + " as the centre");
        }
      }
    } catch (const pvs::FormatError& e) {
      throw vislib::InputError(a->file, e.what());
    }
    if (!a->centre.empty()) centre = parse_vec3(a->centre, "--centre");
    const double eye_axis = pvs_runtime::axis_distance({eye.x, eye.y, eye.z}, {centre.x, centre.y, centre.z});
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
    s.env_size = a->env_size > 0 ? a->env_size : fh;
    s.lookup = a->lookup == "cylinder" ? vislib::EnvironmentLookup::CylinderR2 : vislib::EnvironmentLookup::EyeDirection;

    // Everything is rendered from the scene at tau (one state); the moving triangles are those of
    // the loaded key states.
    const std::vector<uint8_t> moving = vislib::moving_triangles(full_scene);
    s.dynamic = moving.data();
    const vislib::Scene scene = vislib::scene_at(full_scene, a->tau);
    vislib::EmbreeScene rt(scene, 0.0, eye);
    vislib::Frame truth = vislib::render_frame(scene, rt, cam);
    vislib::RegionCounts rc;
    vislib::Frame morphed = vislib::render_near_far(scene, rt, tris, cam, s, &rc);
    s.morph = false;
    vislib::Frame unmorphed = vislib::render_near_far(scene, rt, tris, cam, s);

    vislib::write_rgb8_image(a->output, fw, fh, morphed.rgb);
    vislib::write_rgb8_image(sibling(a->output, "_truth"), fw, fh, truth.rgb);
    vislib::write_rgb8_image(sibling(a->output, "_nomorph"), fw, fh, unmorphed.rgb);
    vislib::write_rgb8_image(sibling(a->output, "_heat"), fw, fh,
                             vislib::error_heat_map(morphed, vislib::missed_pixels(truth, morphed)));

    json j = quality_json(scene, truth, morphed);
    j["file"] = a->file;
    j["cell"] = cell;
    j["eye"] = {eye.x, eye.y, eye.z};
    j["look"] = {target.x, target.y, target.z};
    j["centre"] = {centre.x, centre.y, centre.z};
    j["r1"] = s.r1;
    j["r2"] = s.r2;
    j["tau"] = a->tau;
    j["states"] = full_scene.state_count();
    j["frame"] = {fw, fh};
    j["env_size"] = s.env_size;
    j["lookup"] = a->lookup;
    j["triangles"] = {{"scene", scene.triangle_count()}, {"visible", tris.size()}, {"near", rc.near},
                      {"intermediate", rc.intermediate}, {"far", rc.far}, {"env_map", rc.env_map},
                      {"moving_in_scene", size_t(std::count(moving.begin(), moving.end(), uint8_t(1)))},
                      {"far_dynamic_drawn", rc.far_dynamic}, {"far_dynamic_shown", rc.far_dynamic_shown}};
    j["without_morph"] = quality_json(scene, truth, unmorphed);
    // Baseline: the cell's visible set rendered from geometry, no near-far partition.
    vislib::Frame pvs_frame = vislib::render_frame(scene, rt, cam, vislib::triangle_mask(scene.triangle_count(), tris).data());
    j["pvs_only"] = quality_json(scene, truth, pvs_frame);
    j["images"] = {{"near_far", a->output}, {"truth", sibling(a->output, "_truth")},
                   {"nomorph", sibling(a->output, "_nomorph")}, {"heat_map", sibling(a->output, "_heat")}};

    if (a->grow) {
      const double ring_area = M_PI * s.r2 * s.r2 / a->rings;
      const std::vector<double> equal = pvs_runtime::equal_area_ring_radii(ring_area, s.r2);
      const std::vector<double> contribution =
          vislib::ring_visible_triangle_contribution(scene, tris, centre, equal);
      double total = 0;
      for (double c : contribution) total += c;
      const double min_contribution = a->merge_min >= 0 ? a->merge_min : total / double(equal.size());
      const std::vector<double> merged = pvs_runtime::merge_rings(equal, contribution, min_contribution);
      // The growth through the ring radii `radii`: ring i injected over frames_per_ring frames
      // (Alg. 1 with R = R_{i-1} + (R_i - R_{i-1}) j / F, j = 1..F); the first ring appears at once.
      auto grow = [&](const std::vector<double>& radii) {
        json steps = json::array();
        double min_ssim = 1;
        std::optional<vislib::Frame> prev;
        for (size_t i = 0; i < radii.size(); ++i) {
          const int frames = i == 0 ? 1 : a->frames_per_ring;
          for (int k = 1; k <= frames; ++k) {
            const double big_r = i == 0 ? radii[0] : radii[i - 1] + (radii[i] - radii[i - 1]) * k / frames;
            if (!(eye_axis < a->near_fraction * big_r)) continue;  // Alg. 1 needs the eye inside R_n
            vislib::Frame f = vislib::render_progressive(scene, rt, tris, cam, centre, big_r, a->near_fraction,
                                                         s.env_size, radii[i]);
            json step = {{"ring", i}, {"ring_radius", radii[i]}, {"radius", big_r},
                         {"ssim_to_truth", vislib::frame_quality(truth, f).ssim}};
            if (prev) {
              double ss = vislib::ssim_luminance(fw, fh, prev->rgb, f.rgb);
              step["ssim_to_previous"] = ss;
              min_ssim = std::min(min_ssim, ss);
            }
            steps.push_back(step);
            prev = std::move(f);
          }
        }
        return json{{"radii", radii},
                    {"min_consecutive_ssim", steps.size() >= 2 ? json(min_ssim) : json(nullptr)},
                    {"frames", steps.size()}, {"steps", steps}};
      };
      json merged_json = grow(merged);
      json equal_json = grow(equal);
      j["continuity"] = {{"min_consecutive_ssim", merged_json["min_consecutive_ssim"]},
                         {"near_fraction", a->near_fraction}, {"ring_area", ring_area},
                         {"frames_per_ring", a->frames_per_ring}, {"ring_contribution", contribution},
                         {"merge_min_contribution", min_contribution}, {"merged", merged_json},
                         {"equal_area", equal_json}};
    }

    auto fmt_psnr = [](const json& v) { return v.is_null() ? std::string("inf") : std::to_string(v.get<double>()); };
    std::fprintf(stderr,
                 "cell %u: visible %zu triangles: near %zu, intermediate %zu, far %zu (env map %zu)\n"
                 "  morph:    epsilon %.4f PSNR %s SSIM %.4f OVC %.3f OFC %.3f triangle mismatch %.4f\n"
                 "  no morph: epsilon %.4f PSNR %s SSIM %.4f OVC %.3f OFC %.3f triangle mismatch %.4f\n",
                 cell, tris.size(), rc.near, rc.intermediate, rc.far, rc.env_map, j["epsilon"].get<double>(),
                 fmt_psnr(j["psnr"]).c_str(), j["ssim"].get<double>(), j["ovc"].get<double>(), j["ofc"].get<double>(),
                 j["triangle_mismatch"].get<double>(), j["without_morph"]["epsilon"].get<double>(), fmt_psnr(j["without_morph"]["psnr"]).c_str(),
                 j["without_morph"]["ssim"].get<double>(), j["without_morph"]["ovc"].get<double>(),
                 j["without_morph"]["ofc"].get<double>(), j["without_morph"]["triangle_mismatch"].get<double>());
    if (!moving.empty() && full_scene.is_dynamic())
      std::fprintf(stderr, "  tau %.4f: dynamic far triangles drawn %zu, shown %zu\n", a->tau, rc.far_dynamic,
                   rc.far_dynamic_shown);
    if (j.contains("continuity"))
      for (const char* k : {"merged", "equal_area"}) {
        const json& g = j["continuity"][k];
        if (g["min_consecutive_ssim"].is_null()) continue;
        std::fprintf(stderr, "  growth (%s, %zu rings): %zu frames, min consecutive SSIM %.4f\n", k,
                     g["radii"].size(), g["frames"].get<size_t>(), g["min_consecutive_ssim"].get<double>());
      }
    if (a->json_path == "-") {
      std::printf("%s\n", j.dump(1).c_str());
    } else if (!a->json_path.empty()) {
      vislib::write_file_atomic(a->json_path, j.dump(1) + "\n");
    }
  });
}

Registration view_registration("view", add_view);

}  // namespace
}  // namespace pvs_cli
