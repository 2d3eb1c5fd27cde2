// pvs vis-compare MAP.bsp OURS.pvs [--json OUT] [--samples N]: our sets of a Quake map's BSP leaves
// against the map's own vis (vislib/eval/vis_compare.h; docs/quake.md). Parses, checks the two
// files belong together, prints.
#include <cmath>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/bsp_cells.h"
#include "vislib/bake/cell_set.h"
#include "vislib/bake/cell_visibility.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/vis_compare.h"
#include "vislib/kernel/triangle_bvh.h"
#include "vislib/scene/quake_bsp.h"
#include "vislib/scene/scene_fingerprint.h"

namespace pvs_cli {
namespace {

struct VisCompareArgs {
  std::string map, pvs, json, theirs_pvs;
  int samples = 4;
  int resolution = 0;
  int witness_eyes = 16, witness_targets = 8;
  uint64_t seed = 1;
  std::string kernel_witnesses = "auto";
  int threads = 0;
  ImportArgs import;
};

// The first value of `key` anywhere in `j` (depth first, object keys in order), or null.
nlohmann::json find_key(const nlohmann::json& j, const std::string& key) {
  if (j.is_object()) {
    if (j.contains(key)) return j[key];
    for (const auto& [k, v] : j.items()) {
      nlohmann::json r = find_key(v, key);
      if (!r.is_null()) return r;
    }
  } else if (j.is_array()) {
    for (const auto& v : j) {
      nlohmann::json r = find_key(v, key);
      if (!r.is_null()) return r;
    }
  }
  return nullptr;
}

// Import options recorded in the PVS metadata override the flags (the scene must be the one the
// bake used); a flag given with another value is warned about.
void import_from_metadata(const nlohmann::json& md, const std::string& key, std::string& value,
                          const CLI::App& cmd, const std::string& flag, const std::string& pvs) {
  const nlohmann::json v = find_key(md, key);
  if (!v.is_string()) return;
  const std::string recorded = v.get<std::string>();
  if (cmd.count(flag) && value != recorded)
    warn(flag + " " + value + " ignored: " + pvs + " was baked with " + recorded);
  value = recorded;
}

void run_vis_compare(VisCompareArgs a, const CLI::App& cmd) {
  if (!a.json.empty()) check_output_file(a.json, "--json", true);
  if (!a.theirs_pvs.empty()) check_output_file(a.theirs_pvs, "--theirs-pvs", false);
  pvs::Reader reader = vislib::reading_pvs(a.pvs, [&] { return pvs::Reader::from_file(a.pvs); });
  const pvs::FileInfo& info = reader.info();
  if (info.layout.kind != pvs::LayoutKind::BspTree)
    throw vislib::InputError(
        a.pvs, "its cells are not a BSP-tree layout (bake " + a.map + " with --cells bsp-leaves)");
  if (info.granularity != pvs::Granularity::Triangle)
    throw vislib::InputError(a.pvs, "its sets are objects; vis-compare needs triangle sets");
  if (info.partial)
    throw vislib::InputError(a.pvs, "a partial file (a shard): merge the shards first");
  const nlohmann::json md = nlohmann::json::parse(info.metadata, nullptr, false);
  if (!md.is_discarded()) {
    import_from_metadata(md, "bsp_liquids", a.import.bsp_liquids, cmd, "--bsp-liquids", a.pvs);
    import_from_metadata(md, "bsp_models", a.import.bsp_models, cmd, "--bsp-models", a.pvs);
  }
  vislib::VisCompareOptions opt;
  opt.samples = a.samples;
  opt.witness_eyes = a.witness_eyes;
  opt.witness_targets = a.witness_targets;
  opt.seed = a.seed;
  opt.resolution = 64;
  if (!md.is_discarded()) {
    if (md.contains("resolution") && md["resolution"].is_number_integer())
      opt.resolution = md["resolution"].get<int>();
    if (md.contains("near") && md["near"].is_number()) opt.z_near = md["near"].get<double>();
    if (md.contains("eps_z") && md["eps_z"].is_number()) opt.eps_z = md["eps_z"].get<double>();
  }
  if (a.resolution > 0) opt.resolution = a.resolution;
  if (!(opt.resolution >= 1 && opt.z_near > 0 && opt.eps_z >= 0))
    throw vislib::InputError(a.pvs, "metadata holds an invalid resolution, near or eps_z");

  vislib::Scene scene = load_scene_for_cli(a.map, 1, a.import);
  if (vislib::scene_fingerprint(scene) != info.scene_fingerprint)
    throw vislib::InputError(a.pvs, "was not baked from " + a.map + " imported with --bsp-models " +
                                        a.import.bsp_models + " --bsp-liquids " +
                                        a.import.bsp_liquids + " (scene fingerprints differ)");
  const vislib::QuakeBsp bsp = vislib::read_quake_bsp(a.map);
  vislib::LoadOptions lo;
  lo.bsp_models = a.import.bsp_models == "all" ? vislib::BspModels::all : vislib::BspModels::world;
  lo.bsp_liquids = a.import.bsp_liquids == "omit"          ? vislib::BspLiquids::omit
                   : a.import.bsp_liquids == "see-through" ? vislib::BspLiquids::see_through
                                                           : vislib::BspLiquids::opaque;
  const std::vector<vislib::BspFaceTriangles> faces = vislib::bsp_face_triangles(bsp, lo);
  const std::vector<uint32_t>& cell_leaf = info.layout.cell_leaf;
  for (uint32_t c = 0; c < cell_leaf.size(); ++c)
    if (cell_leaf[c] == 0 || cell_leaf[c] >= bsp.leaves.size())
      throw vislib::InputError(a.pvs, "cell " + std::to_string(c) + " is leaf " +
                                          std::to_string(cell_leaf[c]) +
                                          ", not a non-solid leaf of " + a.map);
  std::vector<std::vector<uint32_t>> ours(cell_leaf.size());
  vislib::reading_pvs(a.pvs, [&] {
    for (uint32_t c = 0; c < cell_leaf.size(); ++c) ours[c] = reader.read_cell(c);
  });

  // The map's own sets in our format: the same layout, cells and scene, the triangles the engine
  // draws from each cell's leaf.
  if (!a.theirs_pvs.empty()) {
    pvs::FileInfo ti = info;
    ti.partial = false;
    nlohmann::json tm = {{"generator", "vislib pvs vis-compare --theirs-pvs"},
                         {"sets",
                          "the triangles the engine draws from each cell's leaf (the "
                          "map's own vis)"},
                         {"map", a.map},
                         {"bsp_models", a.import.bsp_models},
                         {"bsp_liquids", a.import.bsp_liquids}};
    if (!md.is_discarded() && md.contains("cells")) tm["cells"] = md["cells"];
    ti.metadata = tm.dump(1);
    std::vector<pvs::CellSet> theirs;
    for (uint32_t leaf : cell_leaf)
      theirs.emplace_back(vislib::bsp_leaf_drawn_triangles(bsp, faces, leaf));
    vislib::write_file_atomic(a.theirs_pvs, pvs::write_pvs(ti, theirs));
  }

  // Kernel witnesses: the cells rebuilt and their runs re-made as the bake's metadata says.
  vislib::ViewCells cells;
  vislib::RegionOptions ro;
  vislib::TriangleBvh bvh;
  vislib::EdgeLines lines;
  std::once_flag scene_built;
  // What the re-run needs from the metadata; the first key missing, if any.
  std::string missing;
  const nlohmann::json spacing = md.is_discarded() ? nullptr : find_key(md, "face_spacing");
  if (!spacing.is_number()) missing = "face_spacing";
  for (const char* k : {"resolution", "near", "eps_len", "eps_z", "runs", "seed"})
    if (missing.empty() && (md.is_discarded() || !md.contains(k) || !md[k].is_number()))
      missing = k;
  if (a.kernel_witnesses == "on" && !missing.empty())
    throw vislib::InputError(a.pvs, "its metadata lacks '" + missing +
                                        "', needed to re-run its cells for kernel witnesses");
  const bool rerun = a.kernel_witnesses != "off" && missing.empty();
  if (rerun) {
    vislib::BspCellOptions co;
    co.face_spacing = spacing.get<double>();
    const nlohmann::json sweep = find_key(md, "face_sweep");
    if (sweep.is_string() && sweep.get<std::string>() == "adaptive") {
      const nlohmann::json coarse = find_key(md, "chord_coarse"),
                           floor = find_key(md, "chord_floor");
      if (!coarse.is_number() || !floor.is_number() || !(floor.get<double>() > 0) ||
          !(floor.get<double>() <= coarse.get<double>()))
        throw vislib::InputError(a.pvs, "metadata holds an invalid chord_coarse or chord_floor");
      co.adaptive = vislib::AdaptiveSpacing{coarse.get<double>(), floor.get<double>()};
    }
    co.leaves = cell_leaf;
    co.scene = lo;
    ro.segment.resolution = md["resolution"].get<int>();
    ro.segment.near = md["near"].get<double>();
    co.near = ro.segment.near;
    ro.segment.eps_len = md["eps_len"].get<double>();
    ro.segment.eps_z = md["eps_z"].get<double>();
    ro.runs = md["runs"].get<int>();
    ro.seed = md["seed"].get<uint64_t>();
    const nlohmann::json coplanar = find_key(md, "coplanar");
    ro.segment.coplanar = coplanar.is_string() && coplanar.get<std::string>() == "first"
                              ? vislib::CoplanarRule::First
                              : vislib::CoplanarRule::Both;
    if (!(co.face_spacing >= 0 && ro.segment.resolution >= 1 && ro.segment.near > 0 &&
          ro.segment.eps_len >= 0 && ro.segment.eps_z >= 0 && ro.runs >= 1))
      throw vislib::InputError(
          a.pvs,
          "metadata holds an invalid face_spacing, resolution, near, eps_len, eps_z or runs");
    try {
      cells = vislib::bsp_leaf_cells(bsp, co);
    } catch (const std::invalid_argument& e) {
      throw vislib::InputError(a.pvs,
                               std::string("its cells are not the map's leaf cells: ") + e.what());
    }
    opt.kernel_witnesses = [&](uint32_t cell, const std::vector<uint32_t>& extras) {
      // The tree and the edge lines the bake's runs used, built once the first leaf needs them.
      std::call_once(scene_built, [&] {
        bvh = vislib::build_triangle_bvh(scene);
        ro.segment.bvh = &bvh;
        lines = vislib::build_edge_lines(scene);
        ro.segment.edge_lines = &lines;
      });
      std::vector<vislib::VisWitness> out;
      for (const vislib::CellWitnessRay& w :
           vislib::cell_witness_rays(scene, cells, cell, ro, extras))
        out.push_back({w.tri, w.eye, w.dir, true});
      return out;
    };
  }

  vislib::VisCompareResult r;
  const bool bar = show_progress();
  run_with_threads(a.threads, [&] {
    r = vislib::vis_compare(bsp, scene, faces, cell_leaf, ours, opt, [&](size_t done, size_t all) {
      if (bar) std::fprintf(stderr, "\rvis-compare: %zu / %zu leaves", done, all);
    });
  });
  if (bar) std::fprintf(stderr, "\n");

  const std::string text = vislib::vis_compare_json(r);
  if (!a.json.empty()) {
    if (a.json == "-")
      std::printf("%s\n", text.c_str());
    else
      vislib::write_file_atomic(a.json, text + "\n");
  }
  if (a.json == "-") return;
  const nlohmann::json j = nlohmann::json::parse(text);
  const auto& t = j["totals"];
  auto num = [&](const char* k) { return t[k].get<uint64_t>(); };
  std::printf("%s against %s\n", a.pvs.c_str(), a.map.c_str());
  std::printf("  import                 --bsp-models %s --bsp-liquids %s\n",
              a.import.bsp_models.c_str(), a.import.bsp_liquids.c_str());
  std::printf("  leaves                 %zu\n", r.leaves.size());
  std::printf("  triangles              %zu (%zu degenerate, left out)\n", scene.triangle_count(),
              r.degenerate_triangles);
  std::printf("  never-drawn faces      %zu (%zu triangles); in our sets: %lu\n",
              r.never_drawn_faces, r.never_drawn_triangles, (unsigned long)num("never_drawn"));
  std::printf("  ours / theirs          %lu / %lu (common %lu), tightness %.4f\n",
              (unsigned long)num("ours"), (unsigned long)num("theirs"),
              (unsigned long)num("common"), t["tightness"].get<double>());
  std::printf("  tightness per leaf     mean %.4f, median %.4f\n",
              t["mean_tightness"].get<double>(), t["median_tightness"].get<double>());
  std::printf(
      "  extras                 %lu: confirmed %lu, unconfirmed (ours wrong?) %lu, coincident "
      "with a face of theirs %lu, seen at a tie %lu, false witnesses (ours wrong) %lu\n",
      (unsigned long)(num("extras_confirmed") + num("extras_unconfirmed") +
                      num("extras_coincident") + num("extras_tie") + num("extras_false_witness")),
      (unsigned long)num("extras_confirmed"), (unsigned long)num("extras_unconfirmed"),
      (unsigned long)num("extras_coincident"), (unsigned long)num("extras_tie"),
      (unsigned long)num("extras_false_witness"));
  if (rerun)
    std::printf("  kernel witnesses       %lu leaves re-run: %lu extras confirmed by them\n",
                (unsigned long)num("kernel_rerun_leaves"),
                (unsigned long)num("extras_confirmed_by_kernel"));
  else
    std::printf("  kernel witnesses       off%s\n",
                missing.empty() ? "" : (" (the metadata lacks " + missing + ")").c_str());
  std::printf("  ours lacks             %lu\n", (unsigned long)num("ours_lacks"));
  std::printf(
      "  sampling               %d eyes a leaf, N = %d, %lu rays (%lu no hit, %lu "
      "ambiguous)\n",
      opt.samples, opt.resolution, (unsigned long)num("sampled_rays"), (unsigned long)num("no_hit"),
      (unsigned long)num("ambiguous"));
  auto leaves_of = [&](const char* k) {
    std::string s;
    for (const auto& l : t[k]) s += (s.empty() ? "" : " ") + std::to_string(l.get<uint64_t>());
    return s.empty() ? std::string("none") : s;
  };
  std::printf("  sampled misses         ours %lu, theirs %lu (+%lu on never-drawn faces)\n",
              (unsigned long)num("our_misses"), (unsigned long)num("their_misses"),
              (unsigned long)num("their_never_drawn"));
  std::printf("  leaves with our misses   %s\n", leaves_of("our_miss_leaves").c_str());
  std::printf("  leaves with their misses %s\n", leaves_of("their_miss_leaves").c_str());
  std::printf("\n  %6s %6s %7s %7s %9s %9s %11s %4s %6s %6s %9s %9s\n", "cell", "leaf", "ours",
              "theirs", "tightness", "confirmed", "unconfirmed", "tie", "false", "lacks",
              "our-miss", "their-miss");
  for (const auto& l : r.leaves)
    std::printf("  %6u %6u %7zu %7zu %9.4f %9zu %11zu %4zu %6zu %6zu %9lu %9lu\n", l.cell, l.leaf,
                l.ours, l.theirs, l.tightness(), l.confirmed.size(), l.unconfirmed.size(),
                l.tie_witnesses.size(), l.false_witnesses.size(), l.lacks.size(),
                (unsigned long)l.our_misses, (unsigned long)l.their_misses);
}

const Registration reg("vis-compare", [](CLI::App& app) {
  auto a = std::make_shared<VisCompareArgs>();
  auto* cmd = app.add_subcommand(
      "vis-compare",
      "Hold a PVS baked over a Quake map's leaves (--cells bsp-leaves) against the map's own vis: "
      "sizes, tightness, extras with witnesses, sampled misses (docs/quake.md)");
  cmd->add_option("map", a->map, "The Quake map (.bsp)")->required();
  cmd->add_option("pvs", a->pvs, "Our PVS file of that map (BSP-tree cells)")->required();
  cmd->add_option("--json", a->json, "Write totals and per-leaf rows as JSON here ('-': stdout)");
  cmd->add_option("--theirs-pvs", a->theirs_pvs,
                  "Also write the map's own sets (the triangles the engine draws from each leaf) "
                  "as a PVS file of the same layout and cells, for pvs inspect and the web client");
  cmd->add_option("--samples", a->samples,
                  "Sampled eyes per leaf for the ground truth (0: none; default 4)")
      ->check(non_negative());
  cmd->add_option("--sample-res", a->resolution,
                  "Cubemap N of the sampling (default: the bake's resolution from the metadata, "
                  "else 64)")
      ->check(positive());
  cmd->add_option("--witness-eyes", a->witness_eyes, "Eyes tried per extra (default 16)")
      ->check(positive());
  cmd->add_option("--witness-targets", a->witness_targets,
                  "Points of an extra aimed at from each eye (default 8)")
      ->check(positive());
  cmd->add_option("--kernel-witnesses", a->kernel_witnesses,
                  "Re-run the cells whose extras the ray search leaves unconfirmed, as the bake "
                  "made them (from the file's metadata), and re-cast the kernel's witnesses: "
                  "auto (default: when the metadata records the bake), on (exit 2 if it does "
                  "not) or off")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_option("--seed", a->seed, "Seed of the witness and sampling eyes (default 1)");
  cmd->add_option("-j,--threads", a->threads, "Threads (default: one per core)")
      ->check(CLI::Range(0, 256));
  add_import_options(cmd, a->import);
  cmd->callback([a, cmd] { run_vis_compare(*a, *cmd); });
});

}  // namespace
}  // namespace pvs_cli
