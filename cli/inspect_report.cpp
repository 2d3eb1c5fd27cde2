// inspect_report.cpp: the JSON and text output of `pvs inspect` (cmd_inspect.cpp).
#include "cli/inspect_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "vislib/bake/cell_set.h"
#include "vislib/bake/pvs_summary.h"
#include "vislib/eval/cell_views.h"

namespace pvs_cli {

using nlohmann::json;

json box_json(const pvs::Box& b) {
  return {{"min", {b.min[0], b.min[1], b.min[2]}}, {"max", {b.max[0], b.max[1], b.max[2]}}};
}

std::string box_text(const pvs::Box& b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "[%g, %g, %g] .. [%g, %g, %g]", b.min[0], b.min[1], b.min[2],
                b.max[0], b.max[1], b.max[2]);
  return buf;
}

// The summary of every cell: reads (and so checks) every block.
json summary(pvs::Reader& r) {
  const pvs::FileInfo& info = r.info();
  json j;
  j["format_version"] = info.version;
  j["partial"] = info.partial;
  j["scene_fingerprint"] = [&] {
    char buf[19];
    std::snprintf(buf, sizeof buf, "0x%016llx",
                  static_cast<unsigned long long>(info.scene_fingerprint));
    return std::string(buf);
  }();
  j["granularity"] = info.granularity == pvs::Granularity::Object ? "object" : "triangle";
  j["universe"] = info.universe;
  j["cells"] = r.cell_count();
  j["max_delta_depth"] = info.max_delta_depth;
  const pvs::CellLayout& L = info.layout;
  if (L.kind == pvs::LayoutKind::Grid)
    j["layout"] = {{"kind", "grid"},
                   {"box", box_json(L.grid_box)},
                   {"grid", {L.nx, L.ny, L.nz}},
                   {"eye_band", {L.eye_lo, L.eye_hi}}};
  else if (L.kind == pvs::LayoutKind::BspTree)
    j["layout"] = {{"kind", "bsp-tree"},
                   {"planes", L.planes.size()},
                   {"nodes", L.nodes.size()},
                   {"leaves", L.leaf_cell.size()}};
  else
    j["layout"] = {{"kind", "boxes"}};
  json md = json::parse(info.metadata, nullptr, false);
  j["metadata"] = md.is_discarded() ? json(info.metadata) : md;
  uint64_t blocks = r.file_size() - r.blocks_offset();
  j["bytes"] = {{"file", r.file_size()},
                {"header", pvs::kHeaderSize},
                {"layout", r.index_offset() - pvs::kHeaderSize},
                {"index", r.blocks_offset() - r.index_offset()},
                {"blocks", blocks}};

  // Compression mix, and what each single encoding would have cost (block bytes: encoding byte,
  // payload, CRC) for comparison.
  const vislib::PvsSummary sm = vislib::summarize_pvs(r);
  json mj = json::object();
  for (const auto& [name, m] : sm.compression) mj[name] = {{"cells", m.cells}, {"bytes", m.bytes}};
  j["compression"] = mj;
  j["bytes_per_cell"] = {{"chosen", sm.chosen},
                         {"all_sorted_delta", sm.all_sorted_delta},
                         {"all_run_length", sm.all_run_length},
                         {"best_without_delta", sm.best_without_delta},
                         {"raw_bitset", sm.raw_bitset},
                         {"raw_u32_list", sm.raw_u32_list}};
  if (sm.visible)
    j["visible"] = {{"min", sm.visible->min},
                    {"median", sm.visible->median},
                    {"mean", sm.visible->mean},
                    {"max", sm.visible->max},
                    {"mean_share", sm.visible->mean_share}};
  j["histogram"] = {{"bin_width_share", 0.1}, {"cells", sm.histogram}};
  j["per_cell"] = {
      {"visible", sm.cell_visible}, {"encoding", sm.cell_encoding}, {"bytes", sm.cell_bytes}};
  return j;
}

void print_summary(const std::string& path, const json& j) {
  std::printf(
      "%s: PVS format %d%s, %llu bytes (header %llu, layout %llu, index %llu, blocks %llu)\n",
      path.c_str(), j["format_version"].get<int>(),
      j["partial"].get<bool>() ? " (partial: a shard)" : "",
      j["bytes"]["file"].get<unsigned long long>(), j["bytes"]["header"].get<unsigned long long>(),
      j["bytes"]["layout"].get<unsigned long long>(), j["bytes"]["index"].get<unsigned long long>(),
      j["bytes"]["blocks"].get<unsigned long long>());
  std::printf("  scene fingerprint %s, %s granularity, universe %u ids\n",
              j["scene_fingerprint"].get<std::string>().c_str(),
              j["granularity"].get<std::string>().c_str(), j["universe"].get<unsigned>());
  const json& L = j["layout"];
  if (L["kind"] == "grid")
    std::printf("  %u cells: grid %s over %s, eye band %s above each cell's bottom\n",
                j["cells"].get<unsigned>(), L["grid"].dump().c_str(), L["box"].dump().c_str(),
                L["eye_band"].dump().c_str());
  else if (L["kind"] == "bsp-tree")
    std::printf("  %u cells: BSP tree of %s nodes, %s planes, %s leaves\n",
                j["cells"].get<unsigned>(), L["nodes"].dump().c_str(), L["planes"].dump().c_str(),
                L["leaves"].dump().c_str());
  else
    std::printf("  %u cells: box list\n", j["cells"].get<unsigned>());
  std::printf("  metadata %s\n", j["metadata"].dump().c_str());
  std::printf("  compression mix:\n");
  for (auto& [name, m] : j["compression"].items())
    std::printf("    %-26s %8llu cells %12llu bytes\n", name.c_str(),
                m["cells"].get<unsigned long long>(), m["bytes"].get<unsigned long long>());
  const json& b = j["bytes_per_cell"];
  std::printf(
      "  bytes per cell (blocks: encoding byte, payload, CRC): %.1f chosen; if every cell were "
      "sorted-delta %.1f, run-length %.1f, best of the two %.1f; uncompressed payload: bitset "
      "%.0f, "
      "u32 list %.1f\n",
      b["chosen"].get<double>(), b["all_sorted_delta"].get<double>(),
      b["all_run_length"].get<double>(), b["best_without_delta"].get<double>(),
      b["raw_bitset"].get<double>(), b["raw_u32_list"].get<double>());
  if (j.contains("visible")) {
    const json& v = j["visible"];
    std::printf("  visible per cell: min %u, median %u, mean %.1f, max %u (mean share %.2f%%)\n",
                v["min"].get<unsigned>(), v["median"].get<unsigned>(), v["mean"].get<double>(),
                v["max"].get<unsigned>(), 100 * v["mean_share"].get<double>());
  }
  std::printf("  histogram of the visible share:\n");
  const auto hist = j["histogram"]["cells"].get<std::vector<uint32_t>>();
  uint32_t most = std::max<uint32_t>(1, *std::max_element(hist.begin(), hist.end()));
  for (int i = 0; i < 10; ++i)
    std::printf("    %3d-%3d%% %8u %s\n", 10 * i, 10 * (i + 1), hist[i],
                std::string(size_t(40.0 * hist[i] / most + 0.5), '#').c_str());
}

// Renders, from the centre of a cell's view region, the full-scene frame, the frame of the
// cell's visible set and the error heat map in 4 horizontal directions; returns the metrics.
json render_cell(const vislib::Scene& scene, const std::vector<uint32_t>& ids,
                 vislib::Granularity g, vislib::Vec3 eye, const std::string& dir, int width,
                 int height, const vislib::CellViewOptions& options) {
  json views = json::array();
  for (const vislib::CellView& v : vislib::render_cell_views(
           scene, vislib::visible_triangles(scene, ids, g), eye, dir, width, height, options)) {
    const vislib::FrameQuality& q = v.quality;
    views.push_back({{"eye", {v.eye.x, v.eye.y, v.eye.z}},
                     {"forward", {v.forward.x, v.forward.y, v.forward.z}},
                     {"epsilon", q.epsilon},
                     {"missed_pixels", q.missed_pixels},
                     {"psnr", std::isfinite(q.psnr) ? json(q.psnr) : json(nullptr)},
                     {"ssim", q.ssim},
                     {"full", v.full},
                     {"pvs", v.pvs},
                     {"heat_map", v.heat_map}});
  }
  return {{"views", views},
          {"width", width},
          {"height", height},
          {"vfov_degrees", options.vfov_degrees}};
}

// The text output of one cell (the JSON `j` built by the command).
nlohmann::json free_space_json(const vislib::CellFreeSpace& f) {
  nlohmann::json j = {
      {"samples", f.samples}, {"enclosed", f.enclosed}, {"centre_enclosed", f.centre_enclosed}};
  if (f.free_point) j["free_point"] = {f.free_point->x, f.free_point->y, f.free_point->z};
  return j;
}

void print_cell(const json& j, const std::vector<uint32_t>& ids, uint32_t cell_count,
                const pvs::FileInfo& info, const pvs::BlockInfo& b, size_t scene_triangles,
                int max_ids) {
  const uint32_t c = j["cell"].get<uint32_t>();
  const json& segs = j["boundary_segments"];
  std::printf("%s: cell %u of %u\n", j["file"].get<std::string>().c_str(), c, cell_count);
  std::printf("  box %s\n  view region %s\n", box_text(info.layout.cell_box(c)).c_str(),
              box_text(info.layout.view_region(c)).c_str());
  std::printf("  block: %s, %u bytes", vislib::block_encoding_name(b).c_str(), b.size);
  if (b.encoding == pvs::Encoding::Delta) std::printf(" (against cell %u)", b.reference);
  if (j.contains("leaf"))
    std::printf("\n  BSP leaf %u (segments sweeping its faces: see the metadata)\n",
                j["leaf"].get<uint32_t>());
  else
    std::printf("\n  boundary segments (%zu):\n", segs.size());
  for (const auto& s : segs)
    std::printf("    %s -> %s\n", s["from"].dump().c_str(), s["to"].dump().c_str());
  if (b.encoding == pvs::Encoding::Absent) {
    std::printf("  absent: this file is a shard; the cell is in another shard\n");
    return;
  }
  // One line; object sets add the triangles they hold.
  std::printf("  visible: %zu of %u %ss (%.2f%%)", ids.size(), info.universe,
              j["granularity"].get<std::string>().c_str(), 100 * j["share"].get<double>());
  if (j.contains("visible_triangles") && info.granularity == pvs::Granularity::Object)
    std::printf(", %zu of %zu triangles (%.2f%%)", j["visible_triangles"].get<size_t>(),
                scene_triangles, 100 * j["triangle_share"].get<double>());
  std::printf("\n");
  std::printf("  ids:");
  for (size_t i = 0; i < ids.size() && int(i) < max_ids; ++i) std::printf(" %u", ids[i]);
  if (int(ids.size()) > max_ids)
    std::printf(" ... (%zu more; --json lists all)", ids.size() - max_ids);
  std::printf("\n");
  if (j.contains("export_gltf"))
    std::printf("  wrote %s\n", j["export_gltf"].get<std::string>().c_str());
  if (j.contains("render"))
    for (const auto& v : j["render"]["views"])
      std::printf("  view %s: epsilon %.3g, PSNR %s dB, SSIM %.6f -> %s\n",
                  v["forward"].dump().c_str(), v["epsilon"].get<double>(),
                  v["psnr"].is_null() ? "inf" : std::to_string(v["psnr"].get<double>()).c_str(),
                  v["ssim"].get<double>(), v["heat_map"].get<std::string>().c_str());
}

}  // namespace pvs_cli
