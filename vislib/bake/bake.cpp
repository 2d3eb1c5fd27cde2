// bake.cpp: parallel bake over view cells with checkpoint and shards (bake.h, docs/bake.md).
#include "vislib/bake/bake.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <atomic>
#include <cassert>
#include <chrono>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "vislib/bake/checkpoint.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"
#include "vislib/scene/scene_fingerprint.h"

namespace vislib {

pvs::FileInfo bake_file_info(const Scene& scene, const ViewCells& cells, const BakeSettings& settings) {
  assert(scene.triangle_count() < 0xFFFFFFFFull && scene.objects.size() < 0xFFFFFFFFull);
  pvs::FileInfo info;
  info.scene_fingerprint = scene_fingerprint(scene);
  info.granularity = settings.granularity == Granularity::Object ? pvs::Granularity::Object : pvs::Granularity::Triangle;
  // Triangle granularity: triangle ids, then sphere s as triangle_count + s.
  info.universe = uint32_t(settings.granularity == Granularity::Object ? scene.objects.size()
                                                                        : scene.triangle_count() + scene.sphere_count());
  info.layout = cells.layout;
  const SegmentOptions& s = settings.region.segment;
  nlohmann::json m = {{"generator", "vislib pvs bake"},
                      {"cells", nlohmann::json::parse(cells.description)},
                      {"granularity", settings.granularity == Granularity::Object ? "object" : "triangle"},
                      {"resolution", s.resolution},
                      {"near", s.near},
                      {"eps_len", s.eps_len},
                      {"runs", settings.region.runs},
                      {"seed", settings.region.seed},
                      {"state", s.state},
                      {"states", scene.state_count()},
                      {"mode", s.mode == DynamicMode::Decoupled ? "decoupled" : "diagonal"},
                      {"boundary", "perimeter of the eye band's bottom and top rectangles"}};
  info.metadata = m.dump();
  return info;
}

uint64_t bake_key(const pvs::FileInfo& info, Shard shard) {
  // The bytes of a file with every cell absent hold exactly the info (header, layout, metadata).
  pvs::FileInfo empty = info;
  empty.partial = true;
  std::string bytes = pvs::write_pvs(empty, std::vector<pvs::CellSet>(info.layout.cell_count()));
  uint64_t h = pvs::fnv1a64(bytes.data(), bytes.size());
  uint32_t s[2] = {shard.index, shard.count};
  return pvs::fnv1a64(s, sizeof s, h);
}

std::vector<uint32_t> bake_cell(const Scene& scene, const pvs::CellLayout& layout, uint32_t cell,
                                const BakeSettings& settings, double* seconds,
                                const std::function<void(double)>& progress) {
  CellVisibility v = cell_visibility(scene, layout, cell, settings.region, progress);
  if (seconds) *seconds = v.seconds;
  if (settings.granularity == Granularity::Object) return objects_of(scene, v.triangles, v.spheres);
  std::vector<uint32_t> ids = std::move(v.triangles);
  for (uint32_t s : v.spheres) ids.push_back(uint32_t(scene.triangle_count() + s));
  return ids;
}

BakeReport bake(const Scene& scene, const ViewCells& cells, const BakeSettings& settings, Shard shard,
                const BakeFiles& files, const BakeProgressFn& progress) {
  assert(shard.count >= 1 && shard.index < shard.count);
  pvs::FileInfo info = bake_file_info(scene, cells, settings);
  info.partial = shard.count > 1;
  const uint32_t n = info.layout.cell_count();
  BakeReport report;
  report.cells = n;
  report.cell_seconds.assign(n, 0.0);

  std::vector<pvs::CellSet> sets(n);
  std::unique_ptr<Checkpoint> checkpoint;
  if (!files.checkpoint.empty()) {
    std::vector<std::optional<std::vector<uint32_t>>> recovered;
    checkpoint = std::make_unique<Checkpoint>(files.checkpoint, bake_key(info, shard), n, files.resume,
                                              &recovered, info.universe);
    for (uint32_t c = 0; c < n; ++c)
      if (recovered[c]) {
        if (!in_shard(c, shard))
          throw InputError(files.checkpoint, "holds cell " + std::to_string(c) + ", which is not in this shard");
        sets[c] = std::move(recovered[c]);
      }
  }
  std::vector<uint32_t> pending;
  for (uint32_t c = 0; c < n; ++c) {
    if (!in_shard(c, shard)) continue;
    ++report.shard_cells;
    if (sets[c])
      ++report.resumed;
    else
      pending.push_back(c);
  }

  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  std::mutex progress_mutex;
  uint32_t done = report.resumed;
  std::vector<double> partial(n, 0.0);  // fraction of each running cell's runs done
  double running = 0;                   // their sum
  if (progress) progress({done, report.shard_cells, report.resumed, 0.0, 0.0});
  try {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, pending.size(), 1),
        [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i != r.end(); ++i) {
            uint32_t c = pending[i];
            double seconds = 0;
            std::function<void(double)> in_cell;
            if (progress)
              in_cell = [&, c](double fraction) {
                std::lock_guard<std::mutex> lock(progress_mutex);
                running += fraction - partial[c];
                partial[c] = fraction;
                progress(
                    {done, report.shard_cells, report.resumed, elapsed(), std::max(0.0, running)});
              };
            std::vector<uint32_t> ids =
                bake_cell(scene, info.layout, c, settings, &seconds, in_cell);
            if (checkpoint) checkpoint->append(c, ids);
            sets[c] = std::move(ids);
            report.cell_seconds[c] = seconds;
            std::lock_guard<std::mutex> lock(progress_mutex);
            ++done;
            running -= partial[c];
            partial[c] = 0;
            if (progress)
              progress(
                  {done, report.shard_cells, report.resumed, elapsed(), std::max(0.0, running)});
          }
        },
        tbb::simple_partitioner());
  } catch (...) {
    // A bake that recorded nothing leaves no checkpoint behind (issue 17 item 1).
    if (checkpoint && done == 0) checkpoint->remove();
    throw;
  }
  report.baked = uint32_t(pending.size());
  report.seconds = elapsed();

  std::string bytes = pvs::write_pvs(info, sets, &report.stats);
  write_file_atomic(files.output, bytes);
  if (checkpoint) checkpoint->remove();
  return report;
}

}  // namespace vislib
