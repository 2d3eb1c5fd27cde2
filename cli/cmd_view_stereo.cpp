// pvs view --stereo: single-render stereo by reprojection (YORO, MobiSys '25, with the
// fixes of docs/stereo.md). The dominant eye is rendered from the visible set of the cells that
// hold the eyes; the other eye is reprojected (vislib/render/stereo.h), its holes patched; both
// are compared with true renders of that eye from the same set (the method's error) and from the
// full scene (the total error).
#include "cli/cmd_view_stereo.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <optional>

#include "cli/commands.h"
#include "cli/options.h"
#include "cli/view_report.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/cell_set.h"
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

// The errors of `test` against `truth`, without the missed pixels.
json quality(const vislib::Frame& truth, const vislib::Frame& test) {
  json j = frame_error_json(truth, test);
  j.erase("missed_pixels");
  return j;
}

// The visible triangles of the cells holding `points` (union), and those cells.
std::vector<uint32_t> cells_union(const std::string& file, const vislib::Scene& scene,
                                  const std::vector<std::pair<std::string, vislib::Vec3>>& points,
                                  std::vector<uint32_t>* cells) {
  return vislib::reading_pvs(file, [&] {
    pvs::Reader r = pvs::Reader::from_file(file, pvs::ReadOptions{});
    std::vector<std::vector<uint32_t>> sets;
    for (const auto& [name, p] : points) {
      const vislib::PointCell c = vislib::find_point_cell(r, p);
      if (c.status == vislib::PointCell::NoCell) {
        std::fprintf(stderr, "pvs: error: --stereo: the %s eye (%g,%g,%g) is in no cell of %s\n",
                     name.c_str(), p.x, p.y, p.z, file.c_str());
        throw Exit{2};
      }
      if (c.status == vislib::PointCell::Absent) {
        std::fprintf(stderr,
                     "pvs: error: --stereo: cell %u of the %s eye is absent from this shard\n",
                     c.cell, name.c_str());
        throw Exit{2};
      }
      if (std::find(cells->begin(), cells->end(), c.cell) != cells->end()) continue;
      cells->push_back(c.cell);
      sets.push_back(r.read_cell(c.cell));
    }
    return vislib::visible_triangles_union(scene, sets, vislib::granularity_of(r.info()));
  });
}

// What every eye of the pair shares: the scene, the allowed set, the source frame and camera.
struct StereoSource {
  const vislib::Scene& scene;
  const vislib::EmbreeScene& rt;
  const std::vector<uint8_t>& allowed;
  const vislib::Frame& frame;
  const vislib::Camera& camera;
  vislib::Splatting splatting;
  size_t pixels;
};
struct StereoTimes {
  Seconds render, reproject, patch, both;
  size_t rays = 0;
};

// The eye `cam` reprojected from the source and patched (or rendered when too many of its pixels
// are holes), into `out` and `holes_image`; its JSON block without the errors.
json reprojected_eye(const ViewStereoArgs& a, const StereoSource& src, const vislib::Camera& cam,
                     const vislib::Frame& truth, StereoTimes& t, vislib::Frame& out,
                     std::vector<uint8_t>& holes_image) {
  json ej;
  ej["rendered"] = false;
  Stopwatch t0;
  vislib::Reprojection r = vislib::reproject(src.frame, src.camera, cam, src.splatting);
  t.reproject.add(t0);
  const size_t holes = r.holes();
  const double pixels = double(src.pixels), share = double(holes) / pixels;
  ej["holes"] = {{"share", share},
                 {"disocclusion", double(r.count(vislib::HoleKind::Disocclusion)) / pixels},
                 {"crack", double(r.count(vislib::HoleKind::Crack)) / pixels},
                 {"outside_view", double(r.count(vislib::HoleKind::OutsideView)) / pixels}};
  holes_image = vislib::hole_mask_image(truth, r.hole);
  const bool fallback = share > a.max_hole_share;
  ej["fallback"] = fallback;
  if (fallback) {
    t0 = Stopwatch();
    out = vislib::render_frame(src.scene, src.rt, cam, src.allowed.data());
    t.render.add(t0);
    t.rays += src.pixels;
    ej["patched_share"] = 0.0;
    return ej;
  }
  t0 = Stopwatch();
  size_t patched = 0, cast = 0;
  vislib::ReshadeStats rs;
  if (a.reshade) rs = vislib::reshade(r, src.scene, cam);
  if (a.patch == "none") {
    out = vislib::patch_none(r, &patched);
  } else if (a.patch == "median") {
    out = vislib::patch_median(r, &patched);
  } else if (a.patch == "yoro") {
    out = vislib::patch_yoro(r, false, &patched);
  } else {
    out = vislib::patch_rays(r, src.scene, src.rt, cam, src.allowed.data(), &cast);
    patched = cast;
    t.rays += cast;
  }
  t.patch.add(t0);
  // Holes that show a surface afterwards, over the holes plus the filled pixels --reshade found
  // wrong (they are patched too).
  const size_t open = holes + rs.unresolved;
  ej["patched_share"] = open ? double(patched + rs.cracks_resolved) / double(open) : 1.0;
  ej["reshade"] = {{"cracks_resolved", rs.cracks_resolved}, {"unresolved", rs.unresolved}};
  return ej;
}

}  // namespace

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

  StereoTimes t;
  t.rays = pixels;
  Stopwatch t0;
  const vislib::Frame source = vislib::render_frame(scene, rt, source_cam, allowed.data());
  t.render.add(t0);

  // Reference cost: both eyes rendered from the same set.
  t0 = Stopwatch();
  const vislib::Frame truth_left = vislib::render_frame(scene, rt, eyes.left, allowed.data());
  const vislib::Frame truth_right = vislib::render_frame(scene, rt, eyes.right, allowed.data());
  t.both.add(t0);

  const StereoSource src{scene, rt, allowed, source, source_cam, splatting, pixels};
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
      ej = reprojected_eye(a, src, cam, truth, t, out_frame[e], hole_images[e]);
    }
    ej["method_error"] = quality(truth, out_frame[e]);
    const vislib::Frame full = vislib::render_frame(scene, rt, cam);
    ej["total_error"] = quality(full, out_frame[e]);
    eyes_json[name] = ej;
  }

  const int w = head.width, h = head.height;
  json images = {{"left", sibling(output, "_stereo_left")},
                 {"right", sibling(output, "_stereo_right")},
                 {"left_truth", sibling(output, "_stereo_left_truth")},
                 {"right_truth", sibling(output, "_stereo_right_truth")},
                 {"side_by_side", sibling(output, "_stereo_sbs")},
                 {"holes", sibling(output, "_stereo_holes")}};
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
             {{"render", t.render.wall},
              {"reproject", t.reproject.wall},
              {"patch", t.patch.wall},
              {"single_render_total", t.render.wall + t.reproject.wall + t.patch.wall},
              {"render_both_eyes", t.both.wall}}},
            {"cpu_seconds",
             {{"render", t.render.cpu},
              {"reproject", t.reproject.cpu},
              {"patch", t.patch.cpu},
              {"single_render_total", t.render.cpu + t.reproject.cpu + t.patch.cpu},
              {"render_both_eyes", t.both.cpu}}},
            {"rays", {{"cast", t.rays}, {"both_eyes", 2 * pixels}}},
            {"images", images}};
  print_view_stereo(j);
  return j;
}

}  // namespace pvs_cli
