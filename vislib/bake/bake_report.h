// bake_report.h: the JSON report of a bake (pvs bake --json, docs/bake.md): what was asked for,
// what was baked, timings and the sizes of the written file.
#pragma once

#include <optional>
#include <string>

#include "vislib/bake/bake.h"

namespace vislib {

// What the report records besides the BakeReport: the run as asked for.
struct BakeRunInfo {
  std::string scene, output;        // paths as given
  std::string preset;               // quality preset name (draft, default, final)
  int resolution = 0, runs = 0;     // cube face resolution and orientations as used
  std::optional<double> cell_size;  // as used; none for a grid given by its counts
  Shard shard;
  double setup_seconds = 0;  // loading the scene and placing the cells
};

// The summed kernel seconds of the cells baked in this run (BakeReport::cell_seconds).
double kernel_seconds(const BakeReport& r);

// The report's text: one JSON object, pretty-printed with one space per level, ending in a
// newline. Deterministic except for the seconds it reports.
std::string bake_report_json(const BakeRunInfo& info, const BakeReport& r);

}  // namespace vislib
