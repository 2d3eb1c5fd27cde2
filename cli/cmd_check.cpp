// pvs check OUT.pvs SCENE [--samples K] [--json OUT] [--fail-on-miss]: the sampled ground truth of
// any bake (vislib/eval/pvs_check.h; docs/check.md). Reads the file and its scene, hands the
// cells' view regions and sets to the library, prints the summary.
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli/bake_metadata.h"
#include "cli/commands.h"
#include "cli/load_scene.h"
#include "cli/options.h"
#include "cli/threads.h"
#include "pvs_format/pvs_format.h"
#include "vislib/bake/cell_set.h"
#include "vislib/bake/free_space.h"
#include "vislib/bake/view_cells.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/pvs_check.h"
#include "vislib/kernel/region_visibility.h"

namespace pvs_cli {
namespace {

struct CheckArgs {
  std::string pvs, scene, json;
  int samples = 4;
  int resolution = 0, runs = 0;
  uint64_t seed = 1;
  bool fail_on_miss = false;
  int max_rows = 20;
  int threads = 0;
  ImportArgs import;
};

// The regions eyes are drawn from: each cell's view region; a BSP leaf's own convex region
// (as vis-compare samples it) when the cells are a map's leaves.
std::vector<vislib::EyeRegion> eye_regions(const CheckArgs& a, const pvs::FileInfo& info,
                                           double near) {
  const pvs::CellLayout& layout = info.layout;
  if (layout.kind == pvs::LayoutKind::BspTree) {
    const vislib::QuakeBsp bsp = vislib::read_quake_bsp(a.scene);
    check_leaf_cells(info, bsp, a.scene, a.pvs);
    return vislib::bsp_leaf_eye_regions(bsp, layout.cell_leaf, near);
  }
  std::vector<vislib::EyeRegion> regions;
  for (uint32_t c = 0; c < layout.cell_count(); ++c)
    regions.push_back(vislib::box_eye_region(vislib::to_box3(layout.view_region(c))));
  return regions;
}

void run_check(CheckArgs a, const CLI::App& cmd) {
  if (!a.json.empty()) check_output_file(a.json, "--json", true);
  pvs::Reader reader = vislib::reading_pvs(a.pvs, [&] { return pvs::Reader::from_file(a.pvs); });
  const pvs::FileInfo& info = reader.info();
  if (info.partial)
    throw vislib::InputError(a.pvs, "a partial file (a shard): merge the shards first");
  const nlohmann::json md = nlohmann::json::parse(info.metadata, nullptr, false);
  const BakeSampling bake = bake_sampling(md, a.pvs, a.resolution);
  const vislib::Scene scene = load_baked_scene(a.scene, info, md, a.import, cmd, a.pvs);
  vislib::check_universe(a.pvs, info, scene);
  const std::vector<vislib::EyeRegion> regions = eye_regions(a, info, bake.near);
  std::vector<std::vector<uint32_t>> sets(regions.size());
  vislib::reading_pvs(a.pvs, [&] {
    for (uint32_t c = 0; c < sets.size(); ++c)
      sets[c] = vislib::visible_triangles(scene, reader.read_cell(c), vislib::granularity_of(info));
  });

  vislib::PvsCheckOptions opt;
  opt.samples = a.samples;
  opt.seed = a.seed;
  opt.sample.resolution = bake.resolution;
  opt.sample.z_near = bake.near;
  opt.sample.eps_z = bake.eps_z;
  const int runs = a.runs > 0 ? a.runs : bake.runs;
  opt.sample.orientations.clear();
  for (int k = 0; k < runs; ++k)
    opt.sample.orientations.push_back(vislib::run_orientation(bake.seed, 0, k));
  opt.in_solid = [&scene](vislib::Vec3 p) { return vislib::point_enclosed(scene, p); };
  vislib::PvsCheckResult r;
  const bool bar = show_progress();
  run_with_threads(a.threads, [&] {
    r = vislib::pvs_check(scene, regions, sets, opt, [&](size_t done, size_t all) {
      if (bar) std::fprintf(stderr, "\rcheck: %zu / %zu cells", done, all);
    });
  });
  if (bar) std::fprintf(stderr, "\n");

  const nlohmann::json header = {{"file", a.pvs},        {"scene", a.scene},
                                 {"samples", a.samples}, {"resolution", bake.resolution},
                                 {"orientations", runs}, {"near", bake.near},
                                 {"eps_z", bake.eps_z},  {"seed", a.seed}};
  const std::string text = vislib::pvs_check_json(r, header.dump());
  if (a.json == "-")
    std::printf("%s\n", text.c_str());
  else if (!a.json.empty())
    vislib::write_file_atomic(a.json, text + "\n");
  const vislib::PvsCheckTotals t = vislib::pvs_check_totals(r);
  if (a.json != "-") {
    std::printf("%s against %s\n", a.pvs.c_str(), a.scene.c_str());
    std::printf("  cells                %zu\n", r.cells.size());
    std::printf("  sampling             %d eyes a cell, N = %d, %d orientation%s, seed %llu\n",
                a.samples, bake.resolution, runs, plural_s(runs), (unsigned long long)a.seed);
    std::printf(
        "  eyes                 %llu sampled; %llu draws inside solids redrawn, %llu eyes "
        "given up\n",
        (unsigned long long)t.eyes, (unsigned long long)t.eyes_redrawn,
        (unsigned long long)t.eyes_given_up);
    std::printf("  rays                 %llu (%llu no hit, %llu ambiguous)\n",
                (unsigned long long)t.rays, (unsigned long long)t.no_hit,
                (unsigned long long)t.ambiguous);
    std::printf(
        "  misses               %llu rays: %zu triangles, %zu (cell, triangle) pairs, in "
        "%zu cell%s\n",
        (unsigned long long)t.miss_rays, t.missed_triangles, t.missed_pairs, t.cells_with_misses,
        plural_s(t.cells_with_misses));
    std::vector<const vislib::PvsCheckCell*> worst;
    for (const vislib::PvsCheckCell& c : r.cells)
      if (!c.missed.empty()) worst.push_back(&c);
    std::stable_sort(worst.begin(), worst.end(),
                     [](const auto* x, const auto* y) { return x->miss_rays > y->miss_rays; });
    if (!worst.empty())
      std::printf("\n  %6s %8s %10s %10s  missed triangles (rays)\n", "cell", "set", "rays",
                  "miss-rays");
    for (size_t i = 0; i < worst.size() && int(i) < a.max_rows; ++i) {
      const vislib::PvsCheckCell& c = *worst[i];
      std::string ids;
      for (size_t k = 0; k < c.missed.size() && k < 8; ++k)
        ids += " " + std::to_string(c.missed[k].first) + " (" + std::to_string(c.missed[k].second) +
               ")";
      if (c.missed.size() > 8) ids += " ...";
      std::printf("  %6u %8zu %10llu %10llu %s\n", c.cell, c.set_size,
                  (unsigned long long)c.tally.rays, (unsigned long long)c.miss_rays, ids.c_str());
    }
    if (int(worst.size()) > a.max_rows)
      std::printf("  ... %zu more cells with misses (--json lists all)\n",
                  worst.size() - size_t(a.max_rows));
  }
  if (a.fail_on_miss && t.miss_rays > 0) {
    std::fprintf(stderr, "pvs: check failed: %llu sampled miss rays (%zu triangles) in %s\n",
                 (unsigned long long)t.miss_rays, t.missed_triangles, a.pvs.c_str());
    throw Exit{1};
  }
}

const Registration reg("check", [](CLI::App& app) {
  auto a = std::make_shared<CheckArgs>();
  auto* cmd = app.add_subcommand(
      "check",
      "The sampled ground truth of a bake: random eyes in each cell's view region (free space), "
      "cubemaps at the bake's resolution and orientations, every hit missing from the cell's "
      "set re-cast in double; misses by cell and triangle (docs/check.md)");
  cmd->add_option("pvs", a->pvs, "The PVS file")->required();
  cmd->add_option("scene", a->scene, "The scene it was baked from")->required();
  cmd->add_option("--samples", a->samples, "Eyes per cell (default 4)")->check(positive());
  cmd->add_option("--json", a->json,
                  "Write totals, per-cell and per-triangle rows as JSON here ('-': stdout)");
  cmd->add_flag("--fail-on-miss", a->fail_on_miss,
                "Exit 1 when a confirmed miss is found (for CI)");
  cmd->add_option("--sample-res", a->resolution,
                  "Cubemap N (default: the bake's resolution from the metadata, else 64)")
      ->check(positive());
  cmd->add_option("--runs", a->runs,
                  "Cubemap orientations per eye (default: the bake's runs from the metadata, "
                  "else 1)")
      ->check(positive());
  cmd->add_option("--seed", a->seed, "Seed of the eyes (default 1)");
  cmd->add_option("--max-rows", a->max_rows,
                  "Text output: list at most this many cells with misses (default 20)")
      ->check(non_negative());
  cmd->add_option("-j,--threads", a->threads, "Threads (default: one per core)")
      ->check(CLI::Range(0, kMaxThreads));
  add_import_options(cmd, a->import);
  cmd->callback([a, cmd] { run_check(*a, *cmd); });
});

}  // namespace
}  // namespace pvs_cli
