// pvs vis-compare MAP.bsp OURS.pvs [--json OUT] [--samples N]: our sets of a Quake map's BSP leaves
// against the map's own vis (vislib/eval/vis_compare.h; docs/quake.md). Parses, checks the two
// files belong together, prints.
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli/bake_metadata.h"
#include "cli/commands.h"
#include "cli/kernel_rerun.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/cell_set.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/vis_compare.h"
#include "vislib/scene/quake_bsp.h"

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
  vislib::VisCompareOptions opt;
  opt.samples = a.samples;
  opt.witness_eyes = a.witness_eyes;
  opt.witness_targets = a.witness_targets;
  opt.seed = a.seed;
  const BakeSampling sampling = bake_sampling(md, a.pvs, a.resolution);
  opt.resolution = sampling.resolution;
  opt.z_near = sampling.near;
  opt.eps_z = sampling.eps_z;

  const vislib::Scene scene = load_baked_scene(a.map, info, md, a.import, cmd, a.pvs);
  const vislib::QuakeBsp bsp = vislib::read_quake_bsp(a.map);
  const vislib::LoadOptions lo = load_options_of(a.import);
  const std::vector<vislib::BspFaceTriangles> faces = vislib::bsp_face_triangles(bsp, lo);
  const std::vector<uint32_t>& cell_leaf = info.layout.cell_leaf;
  check_leaf_cells(info, bsp, a.map, a.pvs);
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
  KernelRerun rerun(md, a.pvs, a.kernel_witnesses, bsp, scene, cell_leaf, lo);
  opt.kernel_witnesses = rerun.witnesses();

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
  if (rerun.enabled())
    std::printf("  kernel witnesses       %lu leaves re-run: %lu extras confirmed by them\n",
                (unsigned long)num("kernel_rerun_leaves"),
                (unsigned long)num("extras_confirmed_by_kernel"));
  else
    std::printf(
        "  kernel witnesses       off%s\n",
        rerun.missing().empty() ? "" : (" (the metadata lacks " + rerun.missing() + ")").c_str());
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
