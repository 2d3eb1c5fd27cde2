// pvs info SCENE [--json] [--states K]: scene statistics and hygiene report
// (vislib/scene/scene_info.h).
#include <cstdio>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/scene_info.h"

namespace pvs_cli {
namespace {

struct InfoOptions {
  std::string scene;
  bool json = false;
  int states = 1;
  ImportArgs import;
};

void run_info(const InfoOptions& o) {
  vislib::Scene scene = load_scene_for_cli(o.scene, o.states, o.import);
  vislib::SceneInfo info = vislib::scene_info(scene);
  if (o.json) {
    std::printf("%s\n", vislib::to_json(info).c_str());
    return;
  }
  auto row = [](const char* key, const std::string& value) {
    std::printf("  %-22s %s\n", key, value.c_str());
  };
  auto num = [](size_t v) { return std::to_string(v); };
  std::printf("%s\n", o.scene.c_str());
  row("triangles", num(info.triangles));
  row("vertices", num(info.vertices));
  row("objects", num(info.objects));
  row("see-through", num(info.see_through_triangles) + " triangles in " +
                         num(info.see_through_objects) + " objects");
  row("states", num(info.states) + (info.dynamic ? " (dynamic)" : " (static)"));
  row("spheres", num(info.spheres));
  if (info.bbox.empty()) {
    row("bounding box", "(empty)");
  } else {
    char buf[256];
    std::snprintf(buf, sizeof buf, "[%g, %g, %g] .. [%g, %g, %g]", info.bbox.min.x, info.bbox.min.y,
                  info.bbox.min.z, info.bbox.max.x, info.bbox.max.y, info.bbox.max.z);
    row("bounding box", buf);
    std::snprintf(buf, sizeof buf, "%g", info.diagonal);
    row("diagonal", buf);
  }
  if (!info.bbox.empty()) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "centre %g from the origin (%g diagonals)%s", info.origin_offset,
                  info.diagonal > 0 ? info.origin_offset / info.diagonal : 0.0,
                  info.far_from_origin ? ": far (float32 consumers lose precision)" : "");
    row("placement", buf);
  }
  if (vislib::file_extension(o.scene) == ".bsp")
    row("units",
        "Quake units (1 unit is about 2.5 cm), kept; z-up converted to y-up: (x, y, z) -> "
        "(x, z, -y)");
  else
    row("units", "not recorded by mesh formats (glTF: metres); vislib makes no guess");
  row("degenerate triangles", num(info.degenerate_triangles));
  row("non-finite vertices", num(info.nonfinite_vertices));
  row("duplicate vertices", num(info.duplicate_vertices));
  row("out-of-range indices", num(info.out_of_range_indices));
}

const Registration reg("info", [](CLI::App& app) {
  auto o = std::make_shared<InfoOptions>();
  auto* cmd = app.add_subcommand("info", "Print scene statistics and a hygiene report");
  cmd->add_option("scene", o->scene, "Scene file (.gltf .glb .obj .ply .off .stl .spheres .bsp)")
      ->required();
  cmd->add_flag("--json", o->json, "Machine-readable JSON on stdout");
  cmd->add_option("--states", o->states, "Key states to sample animations into (glTF)")
      ->check(positive());
  add_import_options(cmd, o->import);
  cmd->callback([o] { run_info(*o); });
});

}  // namespace
}  // namespace pvs_cli
