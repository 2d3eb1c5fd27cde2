// pvs inspect: a PVS file's summary (cells, bytes, compression mix, visible counts, histogram),
// one cell's details (boundary segments, visible ids, share of the scene), and the scene reduced
// to one cell's set as glTF.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/inspect_report.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/cell_set.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/bake/free_space.h"
#include "vislib/bake/pvs_summary.h"
#include "vislib/bake/scene_subset.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/cell_views.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene_fingerprint.h"
#include "vislib/scene/write_gltf.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

struct InspectArgs {
  std::string file, at, scene, gltf, render_dir;
  std::string frame = "640x480";
  std::string look;
  double fov = 90;
  int64_t cell = -1;
  bool json_out = false;
  int max_ids = 40;
  int states = 1;
};

void run_inspect(const InspectArgs& a) {
  if (!a.gltf.empty()) {
    if (a.scene.empty()) throw CLI::ValidationError("--export-gltf", "needs --scene");
    if (a.cell < 0 && a.at.empty())
      throw CLI::ValidationError("--export-gltf", "needs --cell or --at");
    check_output_file(a.gltf, "--export-gltf");  // before any work
  }
  if (!a.render_dir.empty()) {
    if (a.scene.empty()) throw CLI::ValidationError("--render", "needs --scene");
    if (a.cell < 0 && a.at.empty()) throw CLI::ValidationError("--render", "needs --cell or --at");
    check_output_dir(a.render_dir, "--render");
  }
  pvs::ReadOptions opt;
  vislib::Scene scene;
  if (!a.scene.empty()) {
    scene = load_scene_for_cli(a.scene, a.states);
    opt.expected_fingerprint = vislib::scene_fingerprint(scene);
  }
  int fw = 0, fh = 0;
  if (std::sscanf(a.frame.c_str(), "%dx%d", &fw, &fh) != 2 || fw < 11 || fh < 11 || fw > 8192 ||
      fh > 8192)
    throw CLI::ValidationError("--frame",
                               "expected WxH with 11 <= W, H <= 8192, got '" + a.frame + "'");
  vislib::reading_pvs(a.file, [&] {
    pvs::Reader r = pvs::Reader::from_file(a.file, opt);
    const pvs::FileInfo& info = r.info();
    if (!a.scene.empty()) vislib::check_universe(a.file, info, scene);
    std::optional<uint32_t> cell;
    if (a.cell >= 0) {
      if (a.cell >= int64_t(r.cell_count()))
        throw CLI::ValidationError("--cell", "the file has " + std::to_string(r.cell_count()) +
                                                 " cells (0.." +
                                                 std::to_string(r.cell_count() - 1) + ")");
      cell = uint32_t(a.cell);
    } else if (!a.at.empty()) {
      vislib::Vec3 p = parse_vec3(a.at, "--at");
      double q[3] = {p.x, p.y, p.z};
      cell = info.layout.find_cell(q);
      if (!cell) {
        std::fprintf(stderr, "pvs: error: no cell contains %s\n", a.at.c_str());
        throw Exit{2};
      }
    }
    if (!cell) {
      json j = summary(r);
      j["file"] = a.file;
      std::vector<uint32_t> enclosed;
      if (!a.scene.empty()) {
        // Cells whose view-region centre is enclosed by the scene.
        for (uint32_t k = 0; k < r.cell_count(); ++k)
          if (vislib::point_enclosed(scene, vislib::view_region_centre(info.layout, k)))
            enclosed.push_back(k);
        j["enclosed_centre_cells"] = enclosed;
      }
      if (a.json_out) {
        std::printf("%s\n", j.dump(1).c_str());
      } else {
        print_summary(a.file, j);
        if (!a.scene.empty()) {
          std::printf("  cells whose view-region centre is enclosed by the scene: %zu",
                      enclosed.size());
          for (size_t i = 0; i < enclosed.size() && int(i) < a.max_ids; ++i)
            std::printf(" %u", enclosed[i]);
          std::printf("\n");
        }
      }
      return;
    }
    // One cell.
    const uint32_t c = *cell;
    pvs::BlockInfo b = r.block_info(c);
    json j = {{"file", a.file},
              {"cell", c},
              {"box", box_json(info.layout.cell_box(c))},
              {"view_region", box_json(info.layout.view_region(c))},
              {"encoding", vislib::block_encoding_name(b)},
              {"bytes", b.size}};
    if (b.encoding == pvs::Encoding::Delta) j["reference"] = b.reference;
    json segs = json::array();
    if (info.layout.kind == pvs::LayoutKind::BspTree) {
      // A BSP leaf cell: its segments sweep the leaf's region (the file's metadata says how).
      j["leaf"] = info.layout.cell_leaf[c];
    } else {
      if (a.scene.empty() && vislib::wall_traces_of(info.metadata))
        j["wall_traces"] = "recorded: give --scene to list them among the boundary segments";
      for (const auto& s :
           vislib::recorded_cell_segments(info, c, a.scene.empty() ? nullptr : &scene))
        segs.push_back(
            {{"from", {s.from.x, s.from.y, s.from.z}}, {"to", {s.to.x, s.to.y, s.to.z}}});
    }
    j["boundary_segments"] = segs;
    std::vector<uint32_t> ids;
    if (b.encoding != pvs::Encoding::Absent) ids = r.read_cell(c);
    j["absent"] = b.encoding == pvs::Encoding::Absent;
    j["granularity"] = info.granularity == pvs::Granularity::Object ? "object" : "triangle";
    j["visible_count"] = ids.size();
    j["share"] = info.universe ? double(ids.size()) / info.universe : 0.0;
    const vislib::Granularity g = vislib::granularity_of(info);
    vislib::CellFreeSpace free_space;
    if (!a.scene.empty()) {
      // Points of the view region enclosed by the scene.
      free_space = vislib::cell_free_space(scene, vislib::to_box3(info.layout.view_region(c)));
      j["free_space"] = free_space_json(free_space);
      if (free_space.enclosed > 0)
        warn("cell " + std::to_string(c) + ": " + std::to_string(free_space.enclosed) + " of " +
             std::to_string(free_space.samples) +
             " samples of its view region are enclosed by the scene (it straddles a solid: "
             "boundary segments run through it)");
      vislib::Scene sub = vislib::scene_subset(scene, ids, g);
      j["visible_triangles"] = sub.triangle_count();
      j["triangle_share"] =
          scene.triangle_count() ? double(sub.triangle_count()) / scene.triangle_count() : 0.0;
      if (!a.gltf.empty()) {
        // What a viewer needs besides the triangles: normals, UVs, materials, copyright.
        vislib::LoadOptions lo;
        lo.states = a.states;
        std::vector<std::string> warnings;
        vislib::SceneAppearance app = vislib::load_appearance(a.scene, lo, &warnings);
        for (const auto& w : warnings) warn(w);
        vislib::SceneAppearance sub_app = vislib::appearance_subset(scene, app, ids, g);
        vislib::write_file_atomic(a.gltf, vislib::scene_to_glb(sub, &sub_app));
        j["export_gltf"] = a.gltf;
      }
      if (!a.render_dir.empty()) {
        // The viewpoint: the --at point, else the centre of the cell's view region, else (the
        // centre is enclosed by the scene) the free sample nearest it.
        vislib::Vec3 eye = vislib::view_region_centre(info.layout, c);
        if (!a.at.empty()) {
          eye = parse_vec3(a.at, "--at");
        } else if (free_space.centre_enclosed) {
          if (!free_space.free_point)
            throw vislib::InputError(a.file,
                                     "every sample of cell " + std::to_string(c) +
                                         "'s view region is enclosed by the scene: give --at");
          eye = *free_space.free_point;
        }
        vislib::CellViewOptions views;
        views.vfov_degrees = a.fov;
        if (!a.look.empty()) {
          const vislib::Vec3 f = parse_vec3(a.look, "--look") - eye;
          if (!(std::hypot(f.x, f.z) > 1e-9 * (1 + std::fabs(f.y))))
            throw CLI::ValidationError("--look",
                                       "must differ from the eye horizontally (the "
                                       "camera's up is +y)");
          views.forwards = {f};
        }
        j["render"] = render_cell(scene, ids, g, eye, a.render_dir, fw, fh, views);
      }
    }
    if (a.json_out) {
      j["visible"] = ids;
      std::printf("%s\n", j.dump(1).c_str());
      return;
    }
    print_cell(j, ids, r.cell_count(), info, b, scene.triangle_count(), a.max_ids);
  });
}

void add_inspect(CLI::App& app) {
  auto a = std::make_shared<InspectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "inspect",
      "Check and summarise a PVS file (cells, bytes, compression mix, visible counts), or "
      "show one cell and export the scene reduced to its visible set as glTF");
  cmd->add_option("PVS", a->file, "PVS file")->required();
  auto* cell_opt = cmd->add_option("--cell", a->cell, "Show this cell")->check(non_negative());
  cmd->add_option("--at", a->at, "Show the cell containing the point x,y,z")->excludes(cell_opt);
  cmd->add_flag("--json", a->json_out, "Print JSON instead of text (all visible ids of a cell)");
  cmd->add_option("--scene", a->scene,
                  "The scene the PVS was baked for (checked by its fingerprint)");
  cmd->add_option("--states", a->states,
                  "With --scene: key states to sample animations into (as for the bake)")
      ->check(in_range(1, 100000));
  cmd->add_option(
      "--export-gltf", a->gltf,
      "With --scene and a cell: write the scene reduced to the cell's set (.glb), with the "
      "source's normals, UVs, materials, textures and copyright");
  cmd->add_option(
      "--render", a->render_dir,
      "With --scene and a cell: render from the --at point (else the centre of the cell's view "
      "region, or the free sample nearest it when the centre is enclosed by the scene), in 4 "
      "horizontal directions, the full-scene frame, the PVS frame and the error heat "
      "map into this folder, "
      "with epsilon/PSNR/SSIM");
  cmd->add_option("--frame", a->frame, "Frame size WxH for --render")->capture_default_str();
  cmd->add_option("--look", a->look,
                  "With --render: one view, from the eye towards the point x,y,z, instead of the "
                  "4 horizontal directions");
  cmd->add_option("--fov", a->fov, "With --render: vertical field of view in degrees")
      ->check(CLI::Range(1e-6, 179.999))
      ->capture_default_str();
  cmd->add_option("--max-ids", a->max_ids, "Text output: print at most this many ids of a cell")
      ->capture_default_str();
  cmd->callback([a] { run_inspect(*a); });
}

Registration inspect_registration("inspect", add_inspect);

}  // namespace
}  // namespace pvs_cli
