// pvs export SCENE -o flat.obj [--states K] [--time TAU]: the scene as a flat OBJ whose face i is
// triangle id i. With -o FILE.glb: the scene as binary glTF for the web client (web/), one node
// and mesh per object in object order, primitives in id order (scene_to_glb), so that reading the
// meshes in order gives the triangles in id order, with what a viewer needs besides the triangles
// when the scene is glTF (normals, UVs, materials with their base colour images: load_appearance;
// normals turned by --rotate); refused (exit 2) when the scene's triangle
// objects are not non-decreasing in id order, where that reading would not give vislib's ids. One
// `o <object name>` line each time the object changes along the id order, all vertices as `v` lines
// (%.17g, exact round trip) in vertex order, one `f` line per triangle. Positions are those at
// animation time TAU (Scene::position_at; default 0 = state 0).
// --id-map FILE.json: the runs of consecutive triangle ids of one object with their vertex blocks
// (vislib/scene/id_map.h), so an engine maps PVS ids to its draw calls.
// --scale S, --rotate DEG,AX,AY,AZ, --translate X,Y,Z: the scene moved by the similarity
// x' = S * (R x) + T first (R: DEG degrees about the axis, right-handed; scene_transform.h), to
// check that visible sets do not depend on placement, orientation and units
// (docs/visibility-math.md §6); with --rotate the rotation's matrix is printed for
// `pvs segment --orientation`.
// --centres FILE.json --pvs FILE.pvs (with a .glb): the near-far centre O of every cell of the
// PVS as `pvs view` chooses it without --centre (default_view_centres: the centre of the cell's
// view region, moved to the nearest free sample when the scene encloses it), for the web page
// (docs/web.md): {"format": "vislib-view-centres 1", "cell_count": N, "centres": [[x, y, z] or
// null (every sample enclosed), ...], "moved": [cells whose centre was moved]}. The PVS must have
// been baked for the scene (fingerprint and universe, else exit 2).
// Spheres, if any, go to OUT.spheres in the sphere text format (docs/sphere-format.md): all key
// states without --time, the single state at TAU with --time.
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/cell_set.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/render/view_setup.h"
#include "vislib/scene/appearance.h"
#include "vislib/scene/id_map.h"
#include "vislib/scene/scene_fingerprint.h"
#include "vislib/scene/scene_transform.h"
#include "vislib/scene/write_gltf.h"

namespace pvs_cli {
namespace {

struct ExportOptions {
  std::string scene, out, id_map, centres, pvs;
  int states = 1;
  std::optional<double> time;
  ImportArgs import;
  TransformArgs transform;
};

void append_f(std::string& s, const char* fmt, double a, double b, double c) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  s += buf;
}

// --centres: every cell's default near-far centre (the one pvs view chooses), as JSON.
std::string centres_json(const vislib::Scene& scene, const std::string& pvs_path) {
  pvs::ReadOptions opt;
  opt.expected_fingerprint = vislib::scene_fingerprint(scene);
  const pvs::CellLayout layout = vislib::reading_pvs(pvs_path, [&] {
    pvs::Reader r = pvs::Reader::from_file(pvs_path, opt);
    vislib::check_universe(pvs_path, r.info(), scene);
    return r.info().layout;
  });
  const auto centres = vislib::default_view_centres(scene, layout);
  nlohmann::json list = nlohmann::json::array(), moved = nlohmann::json::array();
  for (uint32_t c = 0; c < centres.size(); ++c) {
    if (!centres[c]) {
      list.push_back(nullptr);
      continue;
    }
    const vislib::Vec3 p = centres[c]->point;
    list.push_back({p.x, p.y, p.z});
    if (centres[c]->moved) moved.push_back(c);
  }
  const nlohmann::json j = {{"format", "vislib-view-centres 1"},
                            {"pvs", std::filesystem::path(pvs_path).filename().string()},
                            {"cell_count", centres.size()},
                            {"centres", list},
                            {"moved", moved}};
  return j.dump() + "\n";
}

void run_export(const ExportOptions& o) {
  const bool glb = vislib::file_extension(o.out) == ".glb";
  if (glb && o.time)
    throw CLI::ValidationError("--time", "a .glb export keeps every key state (morph targets)");
  if (glb && !o.id_map.empty())
    throw CLI::ValidationError("--id-map", "goes with an .obj export (a .glb keeps the id order)");
  if (o.centres.empty() != o.pvs.empty())
    throw CLI::ValidationError("--centres", "--centres FILE.json and --pvs FILE.pvs go together");
  if (!o.centres.empty() && !glb)
    throw CLI::ValidationError("--centres", "goes with a .glb export (for the web client)");
  check_output_file(o.out, "--output");  // before any work
  if (!o.centres.empty()) check_output_file(o.centres, "--centres");
  if (!o.id_map.empty()) check_output_file(o.id_map, "--id-map");
  const vislib::Similarity sim = parse_transform(o.transform);
  vislib::Scene scene = load_scene_for_cli(o.scene, o.states, o.import);
  transform_scene_for_cli(scene, sim);
  if (!o.transform.rotate.empty() && show_progress())
    std::fprintf(stderr, "pvs: rotation (row-major, for --orientation): %s\n",
                 matrix_text(sim.rotation).c_str());
  if (glb) {
    for (size_t t = 1; t < scene.triangle_count(); ++t)
      if (scene.triangle_object[t] < scene.triangle_object[t - 1])
        throw vislib::InputError(o.scene, "triangle " + std::to_string(t) + " of object " +
                                              std::to_string(scene.triangle_object[t]) +
                                              " follows one of object " +
                                              std::to_string(scene.triangle_object[t - 1]) +
                                              ": the objects are not in id order, so a .glb export "
                                              "would not keep the triangle ids "
                                              "(export .obj instead)");
    // The centres first: a PVS that does not fit the scene leaves no output at all.
    const std::string centres = o.centres.empty() ? "" : centres_json(scene, o.pvs);
    // The page draws the scene's own materials (docs/web.md, "Shading").
    std::vector<std::string> warnings;
    vislib::SceneAppearance app =
        vislib::load_appearance(o.scene, load_options_of(o.import, o.states), &warnings);
    for (const auto& w : warnings) warn(w);
    for (vislib::Vec3& n : app.normals) n = sim.rotation * n;
    vislib::write_file_atomic(o.out, vislib::scene_to_glb(scene, &app));
    if (!o.centres.empty()) vislib::write_file_atomic(o.centres, centres);
    if (show_progress())
      std::fprintf(stderr, "pvs: wrote %s (%zu objects, %zu triangles in id order)\n",
                   o.out.c_str(), scene.objects.size(), scene.triangle_count());
    return;
  }
  double tau = o.time.value_or(0.0);
  std::string obj = "# pvs export of " + o.scene + ": face i is triangle id i\n";
  for (uint32_t v = 0; v < scene.vertex_count(); ++v) {
    vislib::Vec3 p = scene.position_at(v, tau);
    append_f(obj, "v %.17g %.17g %.17g\n", p.x, p.y, p.z);
  }
  int64_t last = -1;
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    uint32_t object = scene.triangle_object[t];
    if (int64_t(object) != last) {
      obj += "o " + scene.objects[object].name + "\n";
      last = object;
    }
    const auto& tri = scene.triangles[t];
    obj += "f " + std::to_string(tri[0] + 1) + " " + std::to_string(tri[1] + 1) + " " +
           std::to_string(tri[2] + 1) + "\n";
  }
  vislib::write_file_atomic(o.out, obj);
  if (show_progress())
    std::fprintf(stderr, "pvs: wrote %s (%zu vertices, %zu triangles)\n", o.out.c_str(),
                 scene.vertex_count(), scene.triangle_count());
  if (!o.id_map.empty()) {
    const vislib::IdMap map = vislib::id_map(scene);
    vislib::write_file_atomic(o.id_map, vislib::id_map_json(scene, map));
    if (show_progress())
      std::fprintf(stderr, "pvs: wrote %s (%zu runs, vertices %s)\n", o.id_map.c_str(),
                   map.runs.size(), map.vertices_tiled ? "tiled per run" : "shared between runs");
  }
  if (scene.sphere_count() == 0) return;
  size_t K = o.time ? 1 : scene.sphere_centers.size();
  std::string sp =
      "vislib-spheres 1\n# pvs export of " + o.scene + "\nstates " + std::to_string(K) + "\n";
  for (uint32_t i = 0; i < scene.sphere_count(); ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", scene.sphere_radius[i]);
    sp += buf;
    for (size_t k = 0; k < K; ++k) {
      vislib::Vec3 c = o.time ? scene.sphere_center_at(i, tau) : scene.sphere_centers[k][i];
      append_f(sp, " %.17g %.17g %.17g", c.x, c.y, c.z);
    }
    sp += "\n";
  }
  vislib::write_file_atomic(o.out + ".spheres", sp);
  if (show_progress())
    std::fprintf(stderr, "pvs: wrote %s.spheres (%zu spheres, %zu states)\n", o.out.c_str(),
                 scene.sphere_count(), K);
}

const Registration reg("export", [](CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  auto* cmd = app.add_subcommand(
      "export",
      "Write the scene as a flat OBJ (face i = triangle id i; spheres to OUT.spheres), or as .glb "
      "for the web client (meshes in object order, triangles in id order)");
  cmd->add_option("scene", o->scene, "Scene file")->required();
  cmd->add_option("-o,--output", o->out, "Output .obj, or .glb")->required();
  cmd->add_option("--states", o->states, "Key states to sample animations into (glTF)")
      ->check(positive());
  cmd->add_option("--time", o->time, "Animation time in [0,1] (default: state 0)")
      ->check(in_range(0.0, 1.0));
  add_import_options(cmd, o->import);
  cmd->add_option(
      "--id-map", o->id_map,
      "Also write FILE.json: runs of consecutive triangle ids of one object and their vertex "
      "blocks (PVS ids to draw calls; docs/runtime.md)");
  add_transform_options(cmd, o->transform, "the scene");
  cmd->add_option("--centres", o->centres,
                  "With a .glb: also write FILE.json, the near-far centre pvs view chooses for "
                  "each cell of --pvs (docs/web.md)");
  cmd->add_option("--pvs", o->pvs, "The PVS file whose cells --centres describes");
  cmd->callback([o] { run_export(*o); });
});

}  // namespace
}  // namespace pvs_cli
