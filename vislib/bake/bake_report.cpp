// bake_report.cpp: the JSON report of a bake.
#include "vislib/bake/bake_report.h"

#include <nlohmann/json.hpp>

namespace vislib {

using nlohmann::json;

double kernel_seconds(const BakeReport& r) {
  double kernel = 0;
  for (double x : r.cell_seconds) kernel += x;
  return kernel;
}

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
      {"segment_runs", {{"computed", r.segment_runs_computed}, {"shared", r.segment_runs_shared}}},
      {"timings",
       {{"setup_seconds", info.setup_seconds},
        {"bake_seconds", r.seconds},
        {"bvh_seconds", r.bvh_seconds},
        {"kernel_seconds", kernel_seconds(r)}}},
      {"cell_seconds", r.cell_seconds},
      {"bytes",
       {{"file", r.stats.file_bytes},
        {"header", r.stats.header_bytes},
        {"layout", r.stats.layout_bytes},
        {"index", r.stats.index_bytes},
        {"blocks", r.stats.block_bytes}}}};
  return j.dump(1) + "\n";
}

}  // namespace vislib
