// bake_report.cpp: the JSON report of a bake.
#include "vislib/bake/bake_report.h"

#include <nlohmann/json.hpp>
#include <utility>

namespace vislib {

using nlohmann::json;

double kernel_seconds(const BakeReport& r) {
  double kernel = 0;
  for (double x : r.cell_seconds) kernel += x;
  return kernel;
}

namespace {

// The L the bake ran and, with --long-segments auto, its pilot (long_segments.h).
json long_segments_json(const BakeReport& r) {
  json j = {{"parts", r.long_segments}};
  const LongSegmentChoice& c = r.long_segment_choice;
  if (c.candidates.empty()) return j;
  json candidates = json::array();
  for (const LongSegmentCandidate& k : c.candidates)
    candidates.push_back({{"parts", k.parts},
                          {"runs", k.runs},
                          {"estimated_work", k.cost},
                          {"measured_seconds", k.seconds},
                          {"covered_pairs", k.stats.covered_pairs},
                          {"triangle_tiles", k.stats.triangle_tiles},
                          {"bvh_nodes_opened", k.stats.bvh_nodes_opened},
                          {"primitives_bounded", k.stats.primitives_bounded},
                          {"final_pieces", k.stats.final_pieces}});
  j["pilot"] = {{"resolution", c.resolution},
                {"stretches", c.stretches_sampled},
                {"seconds", c.seconds},
                {"candidates", candidates}};
  return j;
}

// Each phase's wall and CPU seconds, summed over threads (BakePhases).
json phases_json(const BakePhases& p) {
  const std::pair<const char*, const PhaseSeconds*> phases[] = {
      {"bvh", &p.bvh},           {"pilot", &p.pilot},
      {"runs", &p.runs},         {"shared_waits", &p.shared_waits},
      {"merge", &p.merge},       {"cell", &p.cell},
      {"progress", &p.progress}, {"checkpoint", &p.checkpoint},
      {"encode", &p.encode},     {"write", &p.write},
      {"helping", &p.helping},   {"bound_trees", &p.bound_trees},
      {"idle", &p.idle}};
  json j = json::object();
  for (const auto& [name, s] : phases)
    j[name] = {{"wall_seconds", s->wall}, {"cpu_seconds", s->cpu}};
  return j;
}

}  // namespace

std::string bake_report_json(const BakeRunInfo& info, const BakeReport& r) {
  const json preset = {{"name", info.preset},
                       {"res", info.resolution},
                       {"runs", info.runs},
                       {"cell_size", info.cell_size ? json(*info.cell_size) : json(nullptr)}};
  const json j = {
      {"scene", info.scene},
      {"output", info.output},
      {"preset", preset},
      {"cells", r.cells},
      {"shard", {info.shard.index, info.shard.count}},
      {"shard_cells", r.shard_cells},
      {"baked", r.baked},
      {"resumed", r.resumed},
      {"threads", r.threads},
      {"segment_runs", {{"computed", r.segment_runs_computed}, {"shared", r.segment_runs_shared}}},
      {"long_segments", long_segments_json(r)},
      {"timings",
       {{"setup_seconds", info.setup_seconds},
        {"bake_seconds", r.seconds},
        {"bvh_seconds", r.bvh_seconds},
        {"kernel_seconds", kernel_seconds(r)},
        {"process_cpu_seconds", r.times.process_cpu},
        {"cells_seconds", r.times.cells},
        {"cells_cpu_seconds", r.times.cells_cpu},
        {"shared_wait_seconds", r.times.shared_wait},
        // Wall seconds of phases, under names of their own (docs/bake.md).
        {"progress_seconds", r.times.phases.progress.wall},
        {"checkpoint_seconds", r.times.phases.checkpoint.wall},
        {"writing_seconds", r.times.phases.encode.wall + r.times.phases.write.wall},
        {"phases", phases_json(r.times.phases)}}},
      {"cell_seconds", r.cell_seconds},
      {"cell_cpu_seconds", r.cell_cpu_seconds},
      {"bytes",
       {{"file", r.stats.file_bytes},
        {"header", r.stats.header_bytes},
        {"layout", r.stats.layout_bytes},
        {"index", r.stats.index_bytes},
        {"blocks", r.stats.block_bytes}}}};
  return j.dump(1) + "\n";
}

}  // namespace vislib
