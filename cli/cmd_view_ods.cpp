// pvs view --ods: the omnidirectional stereo panoramas (omnidirectional-stereo.txt) of
// the PVS cells that cover the viewing disc at --at, the full-scene truth with the same settings,
// and the metrics. Options and output documented in docs/ods.md.
#include "cli/cmd_view_ods.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/view_report.h"
#include "pvs_format/pvs_format.h"
#include "runtime/ods.h"
#include "runtime/pvs_runtime.h"
#include "vislib/bake/cell_set.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/render/near_far_render.h"
#include "vislib/render/ods_render.h"
#include "vislib/scene/scene_fingerprint.h"

namespace pvs_cli {
namespace {

using nlohmann::json;
using pvs_runtime::Eye;

pvs_runtime::PoleMerge parse_pole_merge(const std::string& text) {
  pvs_runtime::PoleMerge m;
  if (text.empty()) return m;
  const size_t colon = text.find(':');
  auto side = [&](const std::string& part) {
    const std::vector<double> v = parse_doubles(part, "--pole-merge", 3);
    if (!(v[1] >= 0 && v[1] <= v[0] && v[0] <= 90 && v[2] > 0 && std::isfinite(v[2])))
      throw CLI::ValidationError("--pole-merge",
                                 "expected start,end,exponent with 0 <= end <= start <= 90 "
                                 "(degrees from the pole) and exponent > 0, got '" +
                                     part + "'");
    return pvs_runtime::PoleMergeSide{v[0], v[1], v[2]};
  };
  m.top = side(text.substr(0, colon));
  m.bottom = colon == std::string::npos ? m.top : side(text.substr(colon + 1));
  return m;
}

json side_json(const pvs_runtime::PoleMergeSide& s) {
  return {{"start_deg", s.start_deg}, {"end_deg", s.end_deg}, {"exponent", s.exponent}};
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The cells whose visible sets serve the viewing disc of radius `radius` at `eye` (the eye's
// cell, and its neighbours touching the disc when the disc leaves its view region), and the
// triangles of their union; a message and exit 2 when the eye is in no cell or one is absent.
struct OdsCells {
  uint32_t cell = 0;
  std::vector<uint32_t> cells, tris;
  bool disc_in_region = false, disc_covered = false;
};
OdsCells ods_cells(const ViewCommonArgs& c, const vislib::Scene& full_scene, vislib::Vec3 eye,
                   double radius) {
  pvs_runtime::OpenOptions opt;
  opt.expected_fingerprint = vislib::scene_fingerprint(full_scene);
  OdsCells u;
  try {
    pvs_runtime::Pvs pvs = pvs_runtime::Pvs::open(c.file, opt);
    const pvs::FileInfo& info = pvs.info();
    vislib::check_universe(c.file, info, full_scene);  // the bake's id rule (id_universe.h)
    const double q[3] = {eye.x, eye.y, eye.z};
    const std::optional<uint32_t> found = pvs.find_cell(q);
    if (!found) {
      std::fprintf(stderr, "pvs: error: no cell contains %s\n", c.at.c_str());
      throw Exit{2};
    }
    u.cell = *found;
    const pvs_runtime::Point3 centre{eye.x, eye.y, eye.z};
    const pvs::Box region = info.layout.view_region(u.cell);
    u.disc_in_region = pvs_runtime::disc_inside_box(centre, radius, region.min, region.max);
    u.cells.push_back(u.cell);
    if (!u.disc_in_region)
      for (uint32_t n : pvs.neighbours(u.cell, radius)) {
        const pvs::Box r = info.layout.view_region(n);
        if (pvs_runtime::disc_touches_box(centre, radius, r.min, r.max)) u.cells.push_back(n);
      }
    u.disc_covered = vislib::ods_disc_covered(info.layout, u.cells, eye, radius);
    std::vector<std::vector<uint32_t>> sets;
    for (uint32_t k : u.cells) {
      if (pvs.is_absent(k)) {
        std::fprintf(stderr, "pvs: error: cell %u is absent from this shard\n", k);
        throw Exit{2};
      }
      sets.push_back(pvs.visible_ids(k));
    }
    u.tris = vislib::visible_triangles_union(full_scene, sets, vislib::granularity_of(info));
  } catch (const pvs_runtime::OpenError& e) {
    throw vislib::InputError(c.file, e.what());
  } catch (const pvs::FormatError& e) {
    throw vislib::InputError(c.file, e.what());
  }

  return u;
}

}  // namespace

void run_view_ods(const OdsViewArgs& o, const ViewCommonArgs& c) {
  if (o.size % 2 != 0)
    throw CLI::ValidationError("--ods-size", "must be even (height = width / 2)");
  const pvs_runtime::PoleMerge merge = parse_pole_merge(o.pole_merge);
  const vislib::Vec3 eye = parse_vec3(c.at, "--at");
  const double ipd = o.ipd_m * o.units_per_metre;  // scene units
  const double radius = 0.5 * ipd;

  vislib::Scene full_scene = load_scene_for_cli(c.scene, c.states);
  const OdsCells used = ods_cells(c, full_scene, eye, radius);
  const std::vector<uint32_t>& tris = used.tris;

  const vislib::Scene scene = vislib::scene_at(full_scene, c.tau);
  vislib::OdsSettings s;
  s.centre = eye;
  s.ipd = ipd;
  s.merge = merge;
  s.width = o.size;
  s.height = o.size / 2;
  const auto t_build = std::chrono::steady_clock::now();
  vislib::EmbreeScene rt(scene, 0.0, eye);  // BVH re-centred at the panorama centre
  const double build_seconds = seconds_since(t_build);
  const std::vector<uint8_t> mask = vislib::triangle_mask(scene.triangle_count(), tris);
  std::vector<uint32_t> all(scene.triangle_count());
  for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;

  vislib::OdsRasterSettings raster;
  raster.formula =
      o.method == "raster-paper" ? vislib::OdsFormula::Paper : vislib::OdsFormula::Exact;
  raster.static_level = o.tessellation;
  const bool rays = o.method == "rays";
  json counts = json::object(), seconds = json::object();
  // Renders one eye of the triangles `ids` (mask for rays) with the chosen method.
  auto render = [&](Eye e, bool full, const char* name) {
    const auto t0 = std::chrono::steady_clock::now();
    vislib::Frame f;
    if (rays) {
      f = vislib::render_ods_rays(scene, rt, s, e, full ? nullptr : mask.data());
      counts[name] = {{"rays", size_t(s.width) * size_t(s.height)}};
    } else {
      vislib::OdsRasterStats st;
      f = vislib::render_ods_raster(scene, full ? all : tris, s, e, raster, &st);
      counts[name] = {{"input_triangles", st.input_triangles},
                      {"tessellated", st.tessellated},
                      {"drawn", st.drawn},
                      {"pole_triangles", st.pole_triangles},
                      {"dropped_inside_circle", st.dropped_inside_circle}};
    }
    seconds[name] = seconds_since(t0);
    return f;
  };
  const vislib::Frame left = render(Eye::Left, false, "left");
  const vislib::Frame right = render(Eye::Right, false, "right");
  const vislib::Frame truth_left = render(Eye::Left, true, "truth_left");
  const vislib::Frame truth_right = render(Eye::Right, true, "truth_right");

  const int w = s.width, h = s.height;
  vislib::write_rgb8_image(c.output, w, 2 * h, vislib::pack_top_bottom(left, right));
  vislib::write_rgb8_image(sibling(c.output, "_left"), w, h, left.rgb);
  vislib::write_rgb8_image(sibling(c.output, "_right"), w, h, right.rgb);
  vislib::write_rgb8_image(sibling(c.output, "_anaglyph"), w, h, vislib::anaglyph(left, right));
  vislib::write_rgb8_image(sibling(c.output, "_truth"), w, 2 * h,
                           vislib::pack_top_bottom(truth_left, truth_right));

  json bands = json::array();
  for (const vislib::BandDisagreement& b : vislib::lr_disagreement_by_latitude(left, right, 5))
    bands.push_back({{"lat_max", b.lat_max_deg},
                     {"lat_min", b.lat_min_deg},
                     {"pixels", b.pixels},
                     {"triangle_mismatch", b.triangle_mismatch},
                     {"mean_abs_luma", b.mean_abs_luma}});
  auto seam = [](const vislib::Frame& f) {
    const vislib::SeamContinuity sc = vislib::seam_continuity(f);
    return json{{"triangle_mismatch", sc.seam_triangle_mismatch},
                {"mean_abs_rgb", sc.seam_mean_abs_rgb},
                {"typical_adjacent_triangle_mismatch", sc.typical_triangle_mismatch},
                {"typical_adjacent_mean_abs_rgb", sc.typical_mean_abs_rgb}};
  };
  json ods = {
      {"method", o.method},
      {"tessellation",
       rays ? json(nullptr) : (o.tessellation == 0 ? json("dynamic") : json(o.tessellation))},
      {"ipd_m", o.ipd_m},
      {"units_per_metre", o.units_per_metre},
      {"ipd_scene_units", ipd},
      {"size", {w, h}},
      {"pole_merge", {{"top", side_json(merge.top)}, {"bottom", side_json(merge.bottom)}}},
      {"centre", {eye.x, eye.y, eye.z}},
      {"cell", used.cell},
      {"cells_used", used.cells},
      {"disc_in_cell_view_region", used.disc_in_region},
      {"disc_covered", used.disc_covered},
      {"triangles", {{"scene", scene.triangle_count()}, {"visible", tris.size()}}},
      {"left", frame_error_json(truth_left, left)},
      {"right", frame_error_json(truth_right, right)},
      {"lr_disagreement_by_latitude", bands},
      {"seam", {{"left", seam(left)}, {"right", seam(right)}}},
      {"counts", counts},
      {"seconds", seconds},
      {"bvh_build_seconds", build_seconds},
      {"images",
       {{"top_bottom", c.output},
        {"left", sibling(c.output, "_left")},
        {"right", sibling(c.output, "_right")},
        {"anaglyph", sibling(c.output, "_anaglyph")},
        {"truth_top_bottom", sibling(c.output, "_truth")}}}};
  if (!rays) {
    // The raster method's own error: the full scene rasterised against the full scene ray cast.
    vislib::Frame ref_left = vislib::render_ods_rays(scene, rt, s, Eye::Left);
    vislib::Frame ref_right = vislib::render_ods_rays(scene, rt, s, Eye::Right);
    ods["truth_against_rays"] = {{"left", frame_error_json(ref_left, truth_left)},
                                 {"right", frame_error_json(ref_right, truth_right)}};
  }
  json j = {{"file", c.file}, {"scene", c.scene}, {"tau", c.tau}, {"ods", ods}};

  if (show_progress())  // the summary on stderr obeys -q (the JSON has it all)
    std::fprintf(
        stderr,
        "ODS %dx%d %s, IPD %.4g m, cell %u, cells used %zu%s, visible %zu of %zu triangles\n"
        "  left:  epsilon %.5f SSIM %.4f triangle mismatch %.5f (%.2f s)\n"
        "  right: epsilon %.5f SSIM %.4f triangle mismatch %.5f (%.2f s)\n",
        w, h, o.method.c_str(), o.ipd_m, used.cell, used.cells.size(),
        used.disc_covered ? "" : " (disc NOT covered)", tris.size(), size_t(scene.triangle_count()),
        ods["left"]["epsilon"].get<double>(), ods["left"]["ssim"].get<double>(),
        ods["left"]["triangle_mismatch"].get<double>(), seconds["left"].get<double>(),
        ods["right"]["epsilon"].get<double>(), ods["right"]["ssim"].get<double>(),
        ods["right"]["triangle_mismatch"].get<double>(), seconds["right"].get<double>());
  if (c.json_path == "-") {
    std::printf("%s\n", j.dump(1).c_str());
  } else if (!c.json_path.empty()) {
    vislib::write_file_atomic(c.json_path, j.dump(1) + "\n");
  }
}

}  // namespace pvs_cli
