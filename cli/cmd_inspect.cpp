// pvs inspect: a PVS file's summary (cells, bytes, compression mix, visible counts, histogram),
// one cell's details (boundary segments, visible ids, share of the scene), and the scene reduced
// to one cell's set as glTF.
#include <algorithm>
#include <map>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/load_scene.h"
#include "pvs_format/pvs_format.h"
#include "vislib/eval/embree_scene.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/eval/image_io.h"
#include "vislib/eval/metrics.h"
#include "vislib/eval/render.h"
#include "vislib/scene/scene_fingerprint.h"
#include "vislib/bake/scene_subset.h"
#include "vislib/bake/view_cells.h"
#include "vislib/scene/write_gltf.h"

namespace pvs_cli {
namespace {

using nlohmann::json;

struct InspectArgs {
  std::string file, at, scene, gltf, render_dir;
  std::string frame = "640x480";
  int64_t cell = -1;
  bool json_out = false;
  int max_ids = 40;
  int states = 1;
};

json box_json(const pvs::Box& b) {
  return {{"min", {b.min[0], b.min[1], b.min[2]}}, {"max", {b.max[0], b.max[1], b.max[2]}}};
}

std::string box_text(const pvs::Box& b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "[%g, %g, %g] .. [%g, %g, %g]", b.min[0], b.min[1], b.min[2], b.max[0],
                b.max[1], b.max[2]);
  return buf;
}

std::string block_name(const pvs::BlockInfo& b) {
  std::string s = pvs::encoding_name(b.encoding);
  if (b.encoding == pvs::Encoding::Delta) s += std::string("/") + pvs::encoding_name(b.inner);
  return s;
}

// The summary of every cell: reads (and so checks) every block.
json summary(pvs::Reader& r) {
  const pvs::FileInfo& info = r.info();
  const uint32_t n = r.cell_count();
  json j;
  j["format_version"] = info.version;
  j["partial"] = info.partial;
  j["scene_fingerprint"] = [&] {
    char buf[19];
    std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(info.scene_fingerprint));
    return std::string(buf);
  }();
  j["granularity"] = info.granularity == pvs::Granularity::Object ? "object" : "triangle";
  j["universe"] = info.universe;
  j["cells"] = n;
  j["max_delta_depth"] = info.max_delta_depth;
  const pvs::CellLayout& L = info.layout;
  if (L.kind == pvs::LayoutKind::Grid)
    j["layout"] = {{"kind", "grid"}, {"box", box_json(L.grid_box)}, {"grid", {L.nx, L.ny, L.nz}}, {"eye_band", {L.eye_lo, L.eye_hi}}};
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
  std::map<std::string, std::pair<uint64_t, uint64_t>> mix;  // name -> (cells, bytes)
  uint64_t all_sorted = 0, all_runs = 0, best_plain = 0, present = 0;
  std::vector<uint32_t> counts(n, 0);
  std::vector<std::string> encodings(n);
  std::vector<uint32_t> sizes(n);
  for (uint32_t c = 0; c < n; ++c) {
    pvs::BlockInfo b = r.block_info(c);
    encodings[c] = block_name(b);
    sizes[c] = b.size;
    auto& m = mix[encodings[c]];
    ++m.first;
    m.second += b.size;
    if (b.encoding == pvs::Encoding::Absent) continue;
    std::vector<uint32_t> ids = r.read_cell(c);
    counts[c] = uint32_t(ids.size());
    std::string s, rl;
    pvs::append_sorted_delta(s, ids);
    pvs::append_run_length(rl, ids);
    all_sorted += s.size() + 5;
    all_runs += rl.size() + 5;
    best_plain += std::min(s.size(), rl.size()) + 5;
    ++present;
  }
  json mj = json::object();
  for (auto& [name, m] : mix) mj[name] = {{"cells", m.first}, {"bytes", m.second}};
  j["compression"] = mj;
  double pc = present ? double(present) : 1.0;
  uint64_t chosen = 0;
  for (uint32_t c = 0; c < n; ++c)
    if (encodings[c] != "absent") chosen += sizes[c];
  j["bytes_per_cell"] = {{"chosen", chosen / pc},
                         {"all_sorted_delta", all_sorted / pc},
                         {"all_run_length", all_runs / pc},
                         {"best_without_delta", best_plain / pc},
                         {"raw_bitset", std::ceil(info.universe / 8.0)},
                         {"raw_u32_list", 0.0}};
  uint64_t total_ids = 0;
  for (uint32_t c : counts) total_ids += c;
  j["bytes_per_cell"]["raw_u32_list"] = 4.0 * double(total_ids) / pc;

  std::vector<uint32_t> sorted;
  for (uint32_t c = 0; c < n; ++c)
    if (encodings[c] != "absent") sorted.push_back(counts[c]);
  std::sort(sorted.begin(), sorted.end());
  if (!sorted.empty())
    j["visible"] = {{"min", sorted.front()},
                    {"median", sorted[sorted.size() / 2]},
                    {"mean", double(total_ids) / pc},
                    {"max", sorted.back()},
                    {"mean_share", info.universe ? double(total_ids) / pc / info.universe : 0.0}};
  // Histogram of the visible share in 10 bins of 10% of the universe (the last bin includes 100%).
  std::vector<uint32_t> hist(10, 0);
  for (uint32_t v : sorted) {
    double share = info.universe ? double(v) / info.universe : 0.0;
    hist[std::min(9, int(share * 10))]++;
  }
  j["histogram"] = {{"bin_width_share", 0.1}, {"cells", hist}};
  j["per_cell"] = {{"visible", counts}, {"encoding", encodings}, {"bytes", sizes}};
  return j;
}

void print_summary(const std::string& path, const json& j) {
  std::printf("%s: PVS format %d%s, %llu bytes (header %llu, layout %llu, index %llu, blocks %llu)\n", path.c_str(),
              j["format_version"].get<int>(), j["partial"].get<bool>() ? " (partial: a shard)" : "",
              j["bytes"]["file"].get<unsigned long long>(), j["bytes"]["header"].get<unsigned long long>(),
              j["bytes"]["layout"].get<unsigned long long>(), j["bytes"]["index"].get<unsigned long long>(),
              j["bytes"]["blocks"].get<unsigned long long>());
  std::printf("  scene fingerprint %s, %s granularity, universe %u ids\n",
              j["scene_fingerprint"].get<std::string>().c_str(), j["granularity"].get<std::string>().c_str(),
              j["universe"].get<unsigned>());
  const json& L = j["layout"];
  if (L["kind"] == "grid")
    std::printf("  %u cells: grid %s over %s, eye band %s above each cell's bottom\n", j["cells"].get<unsigned>(),
                L["grid"].dump().c_str(), L["box"].dump().c_str(), L["eye_band"].dump().c_str());
  else
    std::printf("  %u cells: box list\n", j["cells"].get<unsigned>());
  std::printf("  metadata %s\n", j["metadata"].dump().c_str());
  std::printf("  compression mix:\n");
  for (auto& [name, m] : j["compression"].items())
    std::printf("    %-26s %8llu cells %12llu bytes\n", name.c_str(), m["cells"].get<unsigned long long>(),
                m["bytes"].get<unsigned long long>());
  const json& b = j["bytes_per_cell"];
  std::printf("  bytes per cell (blocks: encoding byte, payload, CRC): %.1f chosen; if every cell were "
              "sorted-delta %.1f, run-length %.1f, best of the two %.1f; uncompressed payload: bitset %.0f, "
              "u32 list %.1f\n",
              b["chosen"].get<double>(), b["all_sorted_delta"].get<double>(), b["all_run_length"].get<double>(),
              b["best_without_delta"].get<double>(), b["raw_bitset"].get<double>(), b["raw_u32_list"].get<double>());
  if (j.contains("visible")) {
    const json& v = j["visible"];
    std::printf("  visible per cell: min %u, median %u, mean %.1f, max %u (mean share %.2f%%)\n", v["min"].get<unsigned>(),
                v["median"].get<unsigned>(), v["mean"].get<double>(), v["max"].get<unsigned>(),
                100 * v["mean_share"].get<double>());
  }
  std::printf("  histogram of the visible share:\n");
  const auto hist = j["histogram"]["cells"].get<std::vector<uint32_t>>();
  uint32_t most = std::max<uint32_t>(1, *std::max_element(hist.begin(), hist.end()));
  for (int i = 0; i < 10; ++i)
    std::printf("    %3d-%3d%% %8u %s\n", 10 * i, 10 * (i + 1), hist[i], std::string(size_t(40.0 * hist[i] / most + 0.5), '#').c_str());
}

// Renders, from the centre of a cell's view region, the full-scene frame, the frame of the
// cell's visible set and the error heat map in 4 horizontal directions; returns the metrics.
json render_cell(const vislib::Scene& scene, const std::vector<uint32_t>& ids, vislib::Granularity g,
                 vislib::Vec3 eye, const std::string& dir, int width, int height) {
  std::filesystem::create_directories(dir);
  std::vector<uint32_t> tris = ids;
  if (g == vislib::Granularity::Object) {
    std::vector<uint8_t> keep(scene.objects.size(), 0);
    for (uint32_t o : ids) keep[o] = 1;
    tris.clear();
    for (uint32_t t = 0; t < scene.triangle_count(); ++t)
      if (keep[scene.triangle_object[t]]) tris.push_back(t);
  }
  std::vector<uint8_t> mask = vislib::triangle_mask(scene.triangle_count(), tris);
  vislib::EmbreeScene rt(scene, 0.0, eye);
  json views = json::array();
  const vislib::Vec3 dirs[4] = {{1, 0, 0}, {0, 0, 1}, {-1, 0, 0}, {0, 0, -1}};
  for (int k = 0; k < 4; ++k) {
    vislib::Camera cam;
    cam.eye = eye;
    cam.forward = dirs[k];
    cam.width = width;
    cam.height = height;
    vislib::Frame truth = vislib::render_frame(scene, rt, cam);
    vislib::Frame test = vislib::render_frame(scene, rt, cam, mask.data());
    vislib::FrameQuality q = vislib::frame_quality(truth, test);
    std::string base = dir + "/view" + std::to_string(k);
    vislib::write_rgb8_image(base + "_full.png", width, height, truth.rgb);
    vislib::write_rgb8_image(base + "_pvs.png", width, height, test.rgb);
    vislib::write_rgb8_image(base + "_heat.png", width, height,
                             vislib::error_heat_map(test, vislib::missed_pixels(truth, test)));
    views.push_back({{"eye", {eye.x, eye.y, eye.z}},
                     {"forward", {dirs[k].x, dirs[k].y, dirs[k].z}},
                     {"epsilon", q.epsilon},
                     {"missed_pixels", q.missed_pixels},
                     {"psnr", std::isfinite(q.psnr) ? json(q.psnr) : json(nullptr)},
                     {"ssim", q.ssim},
                     {"full", base + "_full.png"},
                     {"pvs", base + "_pvs.png"},
                     {"heat_map", base + "_heat.png"}});
  }
  return {{"views", views}, {"width", width}, {"height", height}};
}

void add_inspect(CLI::App& app) {
  auto a = std::make_shared<InspectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "inspect", "Check and summarise a PVS file (cells, bytes, compression mix, visible counts), or "
                 "show one cell and export the scene reduced to its visible set as glTF");
  cmd->add_option("PVS", a->file, "PVS file")->required();
  auto* cell_opt = cmd->add_option("--cell", a->cell, "Show this cell")->check(CLI::NonNegativeNumber);
  cmd->add_option("--at", a->at, "Show the cell containing the point x,y,z")->excludes(cell_opt);
  cmd->add_flag("--json", a->json_out, "Print JSON instead of text (all visible ids of a cell)");
  cmd->add_option("--scene", a->scene, "The scene the PVS was baked for (checked by its fingerprint)");
  cmd->add_option("--states", a->states, "With --scene: key states to sample animations into (as for the bake)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option(
      "--export-gltf", a->gltf,
      "With --scene and a cell: write the scene reduced to the cell's set (.glb), with the "
      "source's normals, UVs, materials, textures and copyright");
  cmd->add_option(
      "--render", a->render_dir,
      "With --scene and a cell: render from the --at point (else the centre of the cell's view "
      "region, or when that is enclosed by the scene the free sample nearest it), in 4 horizontal "
      "directions, the full-scene frame, the PVS frame and the error heat map into this folder, "
      "with epsilon/PSNR/SSIM");
  cmd->add_option("--frame", a->frame, "Frame size WxH for --render")->capture_default_str();
  cmd->add_option("--max-ids", a->max_ids, "Text output: print at most this many ids of a cell")->capture_default_str();
  cmd->callback([a] {
    pvs::ReadOptions opt;
    vislib::Scene scene;
    if (!a->scene.empty()) {
      scene = load_scene_for_cli(a->scene, a->states);
      opt.expected_fingerprint = vislib::scene_fingerprint(scene);
    }
    if (!a->gltf.empty()) {
      if (a->scene.empty()) throw CLI::ValidationError("--export-gltf", "needs --scene");
      if (a->cell < 0 && a->at.empty()) throw CLI::ValidationError("--export-gltf", "needs --cell or --at");
    }
    if (!a->render_dir.empty()) {
      if (a->scene.empty()) throw CLI::ValidationError("--render", "needs --scene");
      if (a->cell < 0 && a->at.empty()) throw CLI::ValidationError("--render", "needs --cell or --at");
    }
    int fw = 0, fh = 0;
    if (std::sscanf(a->frame.c_str(), "%dx%d", &fw, &fh) != 2 || fw < 11 || fh < 11 || fw > 8192 || fh > 8192)
      throw CLI::ValidationError("--frame", "expected WxH with 11 <= W, H <= 8192, got '" + a->frame + "'");
    try {
      pvs::Reader r = pvs::Reader::from_file(a->file, opt);
      const pvs::FileInfo& info = r.info();
      if (!a->scene.empty()) {
        size_t expect = info.granularity == pvs::Granularity::Object ? scene.objects.size() : scene.triangle_count();
        if (expect != info.universe)
          throw vislib::InputError(a->file, "universe " + std::to_string(info.universe) + " differs from the scene's " + std::to_string(expect));
      }
      std::optional<uint32_t> cell;
      if (a->cell >= 0) {
        if (a->cell >= int64_t(r.cell_count()))
          throw CLI::ValidationError("--cell", "the file has " + std::to_string(r.cell_count()) + " cells (0.." + std::to_string(r.cell_count() - 1) + ")");
        cell = uint32_t(a->cell);
      } else if (!a->at.empty()) {
        vislib::Vec3 p = parse_vec3(a->at, "--at");
        double q[3] = {p.x, p.y, p.z};
        cell = info.layout.find_cell(q);
        if (!cell) {
          std::fprintf(stderr, "pvs: error: no cell contains %s\n", a->at.c_str());
          throw Exit{2};
        }
      }
      if (!cell) {
        json j = summary(r);
        j["file"] = a->file;
        std::vector<uint32_t> enclosed;
        if (!a->scene.empty()) {
          // Cells whose view-region centre is enclosed by the scene (issue 17 item 6).
          for (uint32_t k = 0; k < r.cell_count(); ++k) {
            pvs::Box b = info.layout.view_region(k);
            vislib::Vec3 p{(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2,
                           (b.min[2] + b.max[2]) / 2};
            if (vislib::point_enclosed(scene, p)) enclosed.push_back(k);
          }
          j["enclosed_centre_cells"] = enclosed;
        }
        if (a->json_out) {
          std::printf("%s\n", j.dump(1).c_str());
        } else {
          print_summary(a->file, j);
          if (!a->scene.empty()) {
            std::printf("  cells whose view-region centre is enclosed by the scene: %zu",
                        enclosed.size());
            for (size_t i = 0; i < enclosed.size() && int(i) < a->max_ids; ++i)
              std::printf(" %u", enclosed[i]);
            std::printf("\n");
          }
        }
        return;
      }
      // One cell.
      const uint32_t c = *cell;
      pvs::BlockInfo b = r.block_info(c);
      json j = {{"file", a->file}, {"cell", c}, {"box", box_json(info.layout.cell_box(c))},
                {"view_region", box_json(info.layout.view_region(c))}, {"encoding", block_name(b)}, {"bytes", b.size}};
      if (b.encoding == pvs::Encoding::Delta) j["reference"] = b.reference;
      json segs = json::array();
      for (const auto& s : vislib::cell_boundary_segments(vislib::to_box3(info.layout.view_region(c))))
        segs.push_back({{"from", {s.from.x, s.from.y, s.from.z}}, {"to", {s.to.x, s.to.y, s.to.z}}});
      j["boundary_segments"] = segs;
      std::vector<uint32_t> ids;
      if (b.encoding != pvs::Encoding::Absent) ids = r.read_cell(c);
      j["absent"] = b.encoding == pvs::Encoding::Absent;
      j["granularity"] = info.granularity == pvs::Granularity::Object ? "object" : "triangle";
      j["visible_count"] = ids.size();
      j["share"] = info.universe ? double(ids.size()) / info.universe : 0.0;
      vislib::Granularity g = info.granularity == pvs::Granularity::Object ? vislib::Granularity::Object : vislib::Granularity::Triangle;
      vislib::CellFreeSpace free_space;
      if (!a->scene.empty()) {
        free_space = vislib::cell_free_space(scene, vislib::to_box3(info.layout.view_region(c)));
        j["free_space"] = {{"samples", free_space.samples},
                           {"enclosed", free_space.enclosed},
                           {"centre_enclosed", free_space.centre_enclosed}};
        if (free_space.free_point)
          j["free_space"]["free_point"] = {free_space.free_point->x, free_space.free_point->y,
                                           free_space.free_point->z};
        vislib::Scene sub = vislib::scene_subset(scene, ids, g);
        j["visible_triangles"] = sub.triangle_count();
        j["triangle_share"] = scene.triangle_count() ? double(sub.triangle_count()) / scene.triangle_count() : 0.0;
        if (!a->gltf.empty()) {
          // What a viewer needs besides the triangles: normals, UVs, materials, copyright.
          vislib::LoadOptions lo;
          lo.states = a->states;
          std::vector<std::string> warnings;
          vislib::SceneAppearance app = vislib::load_appearance(a->scene, lo, &warnings);
          for (const auto& w : warnings) warn(w);
          vislib::SceneAppearance sub_app = vislib::appearance_subset(scene, app, ids, g);
          vislib::write_file_atomic(a->gltf, vislib::scene_to_glb(sub, &sub_app));
          j["export_gltf"] = a->gltf;
        }
        if (!a->render_dir.empty()) {
          // The viewpoint: the --at point, else the centre of the cell's view region.
          pvs::Box region = info.layout.view_region(c);
          vislib::Vec3 eye{(region.min[0] + region.max[0]) / 2, (region.min[1] + region.max[1]) / 2,
                           (region.min[2] + region.max[2]) / 2};
          if (!a->at.empty()) {
            eye = parse_vec3(a->at, "--at");
          } else if (free_space.centre_enclosed) {
            // Never an enclosed point as the default eye (issue 17 item 6).
            if (!free_space.free_point)
              throw vislib::InputError(a->file,
                                       "every sample of cell " + std::to_string(c) +
                                           "'s view region is enclosed by the scene: give --at");
            eye = *free_space.free_point;
          }
          j["render"] = render_cell(scene, ids, g, eye, a->render_dir, fw, fh);
        }
      }
      if (a->json_out) {
        j["visible"] = ids;
        std::printf("%s\n", j.dump(1).c_str());
        return;
      }
      std::printf("%s: cell %u of %u\n", a->file.c_str(), c, r.cell_count());
      std::printf("  box %s\n  view region %s\n", box_text(info.layout.cell_box(c)).c_str(), box_text(info.layout.view_region(c)).c_str());
      std::printf("  block: %s, %u bytes", block_name(b).c_str(), b.size);
      if (b.encoding == pvs::Encoding::Delta) std::printf(" (against cell %u)", b.reference);
      std::printf("\n  boundary segments (%zu):\n", segs.size());
      for (const auto& s : segs) std::printf("    %s -> %s\n", s["from"].dump().c_str(), s["to"].dump().c_str());
      if (b.encoding == pvs::Encoding::Absent) {
        std::printf("  absent: this file is a shard; the cell is in another shard\n");
        return;
      }
      std::printf("  visible: %zu of %u %ss (%.2f%%)\n", ids.size(), info.universe, j["granularity"].get<std::string>().c_str(),
                  100 * j["share"].get<double>());
      if (j.contains("free_space")) {
        std::printf(
            "  free space: %d of %d samples of the view region enclosed by the scene%s\n",
            free_space.enclosed, free_space.samples,
            free_space.centre_enclosed ? " (the centre is: the cell straddles a solid)" : "");
        if (free_space.enclosed > 0)
          warn("cell " + std::to_string(c) +
               " holds points enclosed by the scene: its boundary segments run through solids");
      }
      if (j.contains("visible_triangles"))
        std::printf("  visible triangles: %zu of %zu (%.2f%%)\n", j["visible_triangles"].get<size_t>(), scene.triangle_count(),
                    100 * j["triangle_share"].get<double>());
      std::printf("  ids:");
      for (size_t i = 0; i < ids.size() && int(i) < a->max_ids; ++i) std::printf(" %u", ids[i]);
      if (int(ids.size()) > a->max_ids) std::printf(" ... (%zu more; --json lists all)", ids.size() - a->max_ids);
      std::printf("\n");
      if (!a->gltf.empty()) std::printf("  wrote %s\n", a->gltf.c_str());
      if (j.contains("render"))
        for (const auto& v : j["render"]["views"])
          std::printf("  view %s: epsilon %.3g, PSNR %s dB, SSIM %.6f -> %s\n", v["forward"].dump().c_str(),
                      v["epsilon"].get<double>(), v["psnr"].is_null() ? "inf" : std::to_string(v["psnr"].get<double>()).c_str(),
                      v["ssim"].get<double>(), v["heat_map"].get<std::string>().c_str());
    } catch (const pvs::FormatError& e) {
      throw vislib::InputError(a->file, e.what());
    }
  });
}

Registration inspect_registration("inspect", add_inspect);

}  // namespace
}  // namespace pvs_cli
