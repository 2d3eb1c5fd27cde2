// pvs view --stereo: single-render stereo by reprojection (issue 15; YORO, MobiSys '25, with the
// fixes of docs/stereo.md). The dominant eye is rendered from the visible set of the cells that
// hold the eyes; the other eye is reprojected (vislib/render/stereo.h), its holes patched; both
// are compared with true renders of that eye from the same set (the method's error) and from the
// full scene (the total error).
#include "cli/cmd_view_stereo.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>

#include "cli/commands.h"
#include "cli/options.h"
#include "pvs_format/pvs_format.h"
#include "vislib/base/error.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/render/stereo.h"

namespace pvs_cli {

using nlohmann::json;

namespace {

// Wall-clock and process CPU seconds (all threads) of a stage; CPU time is the fairer figure on a
// shared machine, where a waiting process accrues wall time but no CPU time.
struct Stopwatch {
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
  std::clock_t cpu = std::clock();
};
struct Seconds {
  double wall = 0, cpu = 0;
  void add(const Stopwatch& s) {
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - s.wall).count();
    cpu += double(std::clock() - s.cpu) / CLOCKS_PER_SEC;
  }
};

std::string with_suffix(const std::string& out, const std::string& suffix) {
  std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

json quality(const vislib::Frame& truth, const vislib::Frame& test) {
  const vislib::FrameQuality q = vislib::frame_quality(truth, test);
  size_t other = 0;
  for (size_t p = 0; p < truth.pixel_count(); ++p) other += truth.tri[p] != test.tri[p];
  return {{"epsilon", q.epsilon},
          {"psnr", std::isfinite(q.psnr) ? json(q.psnr) : json(nullptr)},
          {"ssim", q.ssim},
          {"triangle_mismatch", double(other) / double(truth.pixel_count())}};
}

// The visible triangles of the cells holding `points` (union), and those cells.
std::vector<uint32_t> cells_union(const std::string& file, const vislib::Scene& scene,
                                  const std::vector<std::pair<std::string, vislib::Vec3>>& points,
                                  std::vector<uint32_t>* cells) {
  std::vector<uint8_t> keep;
  try {
    pvs::Reader r = pvs::Reader::from_file(file, pvs::ReadOptions{});
    const pvs::FileInfo& info = r.info();
    const bool object = info.granularity == pvs::Granularity::Object;
    keep.assign(object ? scene.objects.size() : scene.triangle_count(), 0);
    for (const auto& [name, p] : points) {
      double q[3] = {p.x, p.y, p.z};
      std::optional<uint32_t> c = info.layout.find_cell(q);
      if (!c) {
        std::fprintf(stderr, "pvs: error: --stereo: the %s eye (%g,%g,%g) is in no cell of %s\n",
                     name.c_str(), p.x, p.y, p.z, file.c_str());
        throw Exit{2};
      }
      if (r.block_info(*c).encoding == pvs::Encoding::Absent) {
        std::fprintf(stderr,
                     "pvs: error: --stereo: cell %u of the %s eye is absent from this shard\n", *c,
                     name.c_str());
        throw Exit{2};
      }
      if (std::find(cells->begin(), cells->end(), *c) != cells->end()) continue;
      cells->push_back(*c);
      for (uint32_t id : r.read_cell(*c)) keep[id] = 1;
    }
    std::vector<uint32_t> tris;
    for (uint32_t t = 0; t < scene.triangle_count(); ++t)
      if (keep[object ? scene.triangle_object[t] : t]) tris.push_back(t);
    return tris;
  } catch (const pvs::FormatError& e) {
    throw vislib::InputError(file, e.what());
  }
}

}  // namespace

std::shared_ptr<ViewStereoArgs> add_view_stereo_options(CLI::App* view) {
  auto a = std::make_shared<ViewStereoArgs>();
  view->add_option(
          "--stereo", a->mode,
          "Also build a stereo pair by single-render reprojection (YORO): yoro or true (exact "
          "world-space splatting, holes kept open) or alg2 (the paper's Alg. 2 as printed, "
          "parallel "
          "eyes only); --at is the point between the eyes")
      ->check(CLI::IsMember({"yoro", "true", "alg2"}));
  view->add_option("--dominant", a->dominant,
                   "--stereo: the eye that is rendered: left, right or centre (a view between the "
                   "eyes, both "
                   "eyes reprojected)")
      ->check(CLI::IsMember({"left", "right", "centre"}))
      ->capture_default_str();
  view->add_option("--patch", a->patch,
                   "--stereo: hole filler: yoro (Alg. 3 fixed, 3-row kernel), median, rays "
                   "(re-cast the hole "
                   "pixels against the visible set) or none")
      ->check(CLI::IsMember({"yoro", "median", "rays", "none"}))
      ->capture_default_str();
  view->add_flag("--reshade", a->reshade,
                 "--stereo: recompute each reprojected pixel for its eye from its triangle id "
                 "(exact hit of the "
                 "eye's ray among the neighbouring pixels' triangles, the eye's own shading)");
  view->add_option("--max-hole-share", a->max_hole_share,
                   "--stereo: render the second eye instead when more than this share of its "
                   "pixels are holes "
                   "(the paper's §14 fallback)")
      ->check(in_range(0.0, 1.0))
      ->capture_default_str();
  return a;
}

json run_view_stereo(const ViewStereoArgs& a, const std::string& pvs_file,
                     const vislib::Scene& scene, const vislib::EmbreeScene& rt,
                     const vislib::Camera& head, const std::string& output) {
  const vislib::StereoPair eyes = vislib::stereo_pair(head, a.ipd);
  const bool centre = a.dominant == "centre";
  std::vector<std::pair<std::string, vislib::Vec3>> points = {{"left", eyes.left.eye},
                                                              {"right", eyes.right.eye}};
  if (centre) points.push_back({"centre", head.eye});
  std::vector<uint32_t> cells;
  const std::vector<uint32_t> tris = cells_union(pvs_file, scene, points, &cells);
  const std::vector<uint8_t> allowed = vislib::triangle_mask(scene.triangle_count(), tris);
  const vislib::Splatting splatting =
      a.mode == "alg2" ? vislib::Splatting::Alg2AsPrinted : vislib::Splatting::Exact;
  const vislib::Camera& source_cam =
      centre ? head : (a.dominant == "left" ? eyes.left : eyes.right);
  const size_t pixels = size_t(head.width) * size_t(head.height);

  Seconds t_render, t_reproject, t_patch, t_both;
  size_t rays = pixels;
  Stopwatch t0;
  const vislib::Frame source = vislib::render_frame(scene, rt, source_cam, allowed.data());
  t_render.add(t0);

  // Reference cost: both eyes rendered from the same set.
  t0 = Stopwatch();
  const vislib::Frame truth_left = vislib::render_frame(scene, rt, eyes.left, allowed.data());
  const vislib::Frame truth_right = vislib::render_frame(scene, rt, eyes.right, allowed.data());
  t_both.add(t0);

  json eyes_json;
  vislib::Frame out_frame[2];
  std::vector<uint8_t> hole_images[2];
  for (int e = 0; e < 2; ++e) {
    const char* name = e == 0 ? "left" : "right";
    const vislib::Camera& cam = e == 0 ? eyes.left : eyes.right;
    const vislib::Frame& truth = e == 0 ? truth_left : truth_right;
    json ej;
    if (!centre && a.dominant == name) {
      out_frame[e] = source;
      ej["rendered"] = true;
    } else {
      ej["rendered"] = false;
      t0 = Stopwatch();
      vislib::Reprojection r = vislib::reproject(source, source_cam, cam, splatting);
      t_reproject.add(t0);
      const size_t holes = r.holes();
      const double share = double(holes) / double(pixels);
      ej["holes"] = {
          {"share", share},
          {"disocclusion", double(r.count(vislib::HoleKind::Disocclusion)) / double(pixels)},
          {"crack", double(r.count(vislib::HoleKind::Crack)) / double(pixels)},
          {"outside_view", double(r.count(vislib::HoleKind::OutsideView)) / double(pixels)}};
      hole_images[e] = vislib::hole_mask_image(truth, r.hole);
      const bool fallback = share > a.max_hole_share;
      ej["fallback"] = fallback;
      if (fallback) {
        t0 = Stopwatch();
        out_frame[e] = vislib::render_frame(scene, rt, cam, allowed.data());
        t_render.add(t0);
        rays += pixels;
        ej["patched_share"] = 0.0;
      } else {
        t0 = Stopwatch();
        size_t patched = 0, cast = 0;
        vislib::ReshadeStats rs;
        if (a.reshade) rs = vislib::reshade(r, scene, cam);
        if (a.patch == "none") {
          out_frame[e] = vislib::patch_none(r, &patched);
        } else if (a.patch == "median") {
          out_frame[e] = vislib::patch_median(r, &patched);
        } else if (a.patch == "yoro") {
          out_frame[e] = vislib::patch_yoro(r, false, &patched);
        } else {
          out_frame[e] = vislib::patch_rays(r, scene, rt, cam, allowed.data(), &cast);
          patched = cast;
          rays += cast;
        }
        t_patch.add(t0);
        // Holes that show a surface afterwards, over the holes plus the filled pixels --reshade
        // found wrong (they are patched too).
        const size_t open = holes + rs.unresolved;
        ej["patched_share"] = open ? double(patched + rs.cracks_resolved) / double(open) : 1.0;
        ej["reshade"] = {{"cracks_resolved", rs.cracks_resolved}, {"unresolved", rs.unresolved}};
      }
    }
    ej["method_error"] = quality(truth, out_frame[e]);
    const vislib::Frame full = vislib::render_frame(scene, rt, cam);
    ej["total_error"] = quality(full, out_frame[e]);
    eyes_json[name] = ej;
  }

  const int w = head.width, h = head.height;
  json images = {{"left", with_suffix(output, "_stereo_left")},
                 {"right", with_suffix(output, "_stereo_right")},
                 {"left_truth", with_suffix(output, "_stereo_left_truth")},
                 {"right_truth", with_suffix(output, "_stereo_right_truth")},
                 {"side_by_side", with_suffix(output, "_stereo_sbs")},
                 {"holes", with_suffix(output, "_stereo_holes")}};
  vislib::write_rgb8_image(images["left"], w, h, out_frame[0].rgb);
  vislib::write_rgb8_image(images["right"], w, h, out_frame[1].rgb);
  vislib::write_rgb8_image(images["left_truth"], w, h, truth_left.rgb);
  vislib::write_rgb8_image(images["right_truth"], w, h, truth_right.rgb);
  vislib::write_rgb8_image(images["side_by_side"], 2 * w, h,
                           vislib::side_by_side(w, h, out_frame[0].rgb, out_frame[1].rgb));
  // The hole mask of the reprojected eye(s): left | right when both were reprojected.
  if (centre) {
    vislib::write_rgb8_image(images["holes"], 2 * w, h,
                             vislib::side_by_side(w, h, hole_images[0], hole_images[1]));
  } else {
    vislib::write_rgb8_image(images["holes"], w, h, hole_images[a.dominant == "left" ? 1 : 0]);
  }

  json j = {{"mode", a.mode == "true" ? "yoro" : a.mode},
            {"splatting", splatting == vislib::Splatting::Exact ? "exact" : "alg2_as_printed"},
            {"ipd", a.ipd},
            {"dominant", a.dominant},
            {"patch", a.patch},
            {"reshade", a.reshade},
            {"max_hole_share", a.max_hole_share},
            {"cells", cells},
            {"visible_triangles", tris.size()},
            {"eyes", eyes_json},
            {"seconds",
             {{"render", t_render.wall},
              {"reproject", t_reproject.wall},
              {"patch", t_patch.wall},
              {"single_render_total", t_render.wall + t_reproject.wall + t_patch.wall},
              {"render_both_eyes", t_both.wall}}},
            {"cpu_seconds",
             {{"render", t_render.cpu},
              {"reproject", t_reproject.cpu},
              {"patch", t_patch.cpu},
              {"single_render_total", t_render.cpu + t_reproject.cpu + t_patch.cpu},
              {"render_both_eyes", t_both.cpu}}},
            {"rays", {{"cast", rays}, {"both_eyes", 2 * pixels}}},
            {"images", images}};
  for (const char* name : {"left", "right"}) {
    const json& ej = j["eyes"][name];
    if (ej["rendered"].get<bool>() || !show_progress()) continue;  // -q: the JSON has it all
    const json& m = ej["method_error"];
    std::fprintf(stderr,
                 "stereo %s eye (cells %zu, %zu triangles): holes %.4f%s, method error PSNR %s "
                 "SSIM %.4f triangle "
                 "mismatch %.4f; total error SSIM %.4f\n",
                 name, cells.size(), tris.size(), ej["holes"]["share"].get<double>(),
                 ej["fallback"].get<bool>() ? " (fallback: rendered)" : "",
                 m["psnr"].is_null() ? "inf" : std::to_string(m["psnr"].get<double>()).c_str(),
                 m["ssim"].get<double>(), m["triangle_mismatch"].get<double>(),
                 ej["total_error"]["ssim"].get<double>());
  }
  if (show_progress())
    std::fprintf(
        stderr,
        "stereo CPU time: render %.4f s + reproject %.4f s + patch %.4f s vs both eyes %.4f s; "
        "rays %zu vs %zu\n",
        t_render.cpu, t_reproject.cpu, t_patch.cpu, t_both.cpu, rays, 2 * pixels);
  return j;
}

}  // namespace pvs_cli
