// view_options.cpp: the options of `pvs view` (--ods and --stereo included) and their parsing
// (view_options.h, cmd_view_ods.h, cmd_view_stereo.h).
#include "cli/view_options.h"

#include <cstdio>

#include "cli/cmd_view_ods.h"
#include "cli/cmd_view_stereo.h"
#include "cli/commands.h"
#include "cli/options.h"

namespace pvs_cli {

void add_view_options(CLI::App* cmd, ViewArgs& a) {
  cmd->add_option("PVS", a.file, "PVS file")->required();
  cmd->add_option("--scene", a.scene,
                  "The scene the PVS was baked for (checked by its fingerprint)")
      ->required();
  cmd->add_option("--at", a.at, "User eye x,y,z (its cell's visible set is used)")->required();
  cmd->add_option("--look", a.look, "Point x,y,z the user looks at (required without --ods)");
  cmd->add_option(
      "--near-far", a.near_far,
      "Radii r1,r2 of the cylinders about the centre (scene units; default: r1 = 1.25 x "
      "the half x-z diagonal of the cell's box, r2 = 2 r1, as pvs_rt_cell_near_far)");
  cmd->add_option("--frames-out", a.frames_out,
                  "--grow: also write every growth frame as DIR/merged_NNNN.png and "
                  "DIR/equal_area_NNNN.png");
  cmd->add_option("--centre", a.centre,
                  "Centre O x,y,z of the cylinders and environment map (default: the "
                  "centre of the cell's view region, or the free sample of the region nearest "
                  "it when that is enclosed by the scene)");
  cmd->add_flag("--grow", a.grow,
                "Also render the progressive near region (CloVR rings up to r2) and report "
                "the minimum SSIM between consecutive frames");
  cmd->add_option("--rings", a.rings, "--grow: equal-area rings up to r2")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--frames-per-ring", a.frames_per_ring,
                  "--grow: frames over which each ring is injected (Alg. 1 with R animated from "
                  "the previous "
                  "ring's radius to the ring's)")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  cmd->add_option(
      "--merge-min", a.merge_min,
      "--grow: merged rings contribute at least this many visible triangles (entering the near "
      "region) each (default: the mean over the equal-area rings)");
  cmd->add_option("--states", a.states,
                  "Key states to sample glTF animations into (as for the bake)")
      ->check(in_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--time", a.tau, "Animation time tau in [0,1] of the frame (dynamic scenes)")
      ->check(in_range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--near-fraction", a.near_fraction, "--grow: R_n / R of Alg. 1")
      ->check(in_range(0.01, 0.99))
      ->capture_default_str();
  cmd->add_option("--frame", a.frame, "Frame size WxH")->capture_default_str();
  cmd->add_option("--delta-radius", a.delta_radius,
                  "Neighbourhood radius (pixels) of the near-far paper's discontinuity metric "
                  "delta (Eq. 8), reported with and without the morph")
      ->check(CLI::Range(0.5, 1000.0))
      ->capture_default_str();
  cmd->add_option("--env-size", a.env_size,
                  "Environment map face side in pixels (default: the frame height)")
      ->check(in_range(0, 8192));
  cmd->add_option("--lookup", a.lookup,
                  "Environment map lookup: eye (along the eye ray, the paper) or cylinder "
                  "(from O through the eye ray's exit point on the r2 cylinder)")
      ->check(CLI::IsMember({"eye", "cylinder"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", a.output,
                  "Near-far frame (.png); <out>_truth.png, <out>_heat.png and "
                  "<out>_nomorph.png are written next to it")
      ->required();
  cmd->add_option("--json", a.json_path, "Write the metrics as JSON ('-' = stdout)");
}

ViewInputs parse_view(const ViewArgs& a) {
  ViewInputs in;
  if (std::sscanf(a.frame.c_str(), "%dx%d", &in.fw, &in.fh) != 2 || in.fw < 11 || in.fh < 11 ||
      in.fw > 8192 || in.fh > 8192)
    throw CLI::ValidationError("--frame",
                               "expected WxH with 11 <= W, H <= 8192, got '" + a.frame + "'");
  if (!a.near_far.empty()) {
    in.radii = parse_doubles(a.near_far, "--near-far", 2);
    if (!(in.radii[0] >= 0 && in.radii[0] < in.radii[1]))
      throw CLI::ValidationError("--near-far", "expected 0 <= r1 < r2, got '" + a.near_far + "'");
  }
  in.eye = parse_vec3(a.at, "--at");
  in.target = parse_vec3(a.look, "--look");
  if (length(in.target - in.eye) == 0)
    throw CLI::ValidationError("--look", "must differ from --at");
  return in;
}

void add_ods_view_options(CLI::App* cmd, const std::shared_ptr<OdsViewArgs>& a) {
  cmd->add_flag("--ods", a->enabled,
                "Render omnidirectional stereo panoramas (left, right, top-bottom, anaglyph) from "
                "--at instead of "
                "the near-far frame; --look is then not needed (docs/ods.md)");
  cmd->add_option("--ipd", a->ipd_m, "--ods: interpupillary distance in metres")
      ->check(in_range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_option(
         "--units-per-metre", a->units_per_metre,
         "--ods: scene units in one metre (the IPD is multiplied by it; glTF is in metres: 1)")
      ->check(positive())
      ->capture_default_str();
  cmd->add_option("--ods-size", a->size, "--ods: panorama width W in pixels (height W/2), even")
      ->check(in_range(16, 16384))
      ->capture_default_str();
  cmd->add_option("--pole-merge", a->pole_merge,
                  "--ods: pole merging (Eq. 6) start,end,exponent for both poles or top:bottom, "
                  "angles in degrees "
                  "from the pole (e.g. 45,0,3); default none");
  cmd->add_option("--ods-method", a->method,
                  "--ods: rays (Embree reference), raster-paper (the paper's per-vertex Eq. 5) or "
                  "raster-exact "
                  "(exact tangent-ray projection), both rasterised after Alg. 1 tessellation and "
                  "seam/pole split")
      ->check(CLI::IsMember({"rays", "raster-paper", "raster-exact"}))
      ->capture_default_str();
  cmd->add_option("--ods-tessellation", a->tessellation,
                  "--ods raster methods: 0 = dynamic (Alg. 1 + Eq. 4), k = static level k for "
                  "every triangle")
      ->check(in_range(0, 64))
      ->capture_default_str();
}

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

}  // namespace pvs_cli
