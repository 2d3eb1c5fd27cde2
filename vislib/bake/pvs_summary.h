// pvs_summary.h: the statistics of a whole PVS file (what `pvs inspect FILE` prints): the
// compression mix, what each single encoding would have cost, visible counts and their histogram.
// Reading every block also checks every block (pvs::FormatError on a bad one).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pvs_format/pvs_format.h"

namespace vislib {

// "sorted-delta", "run-length", ..., "delta/<inner>" for delta blocks.
std::string block_encoding_name(const pvs::BlockInfo& b);

struct PvsSummary {
  struct Mix {
    uint64_t cells = 0, bytes = 0;
  };
  std::map<std::string, Mix> compression;  // by block_encoding_name
  // Mean block bytes per present cell (encoding byte, payload, CRC): as chosen, if every cell were
  // sorted-delta / run-length / the better of the two; the uncompressed payloads.
  double chosen = 0, all_sorted_delta = 0, all_run_length = 0, best_without_delta = 0;
  double raw_bitset = 0, raw_u32_list = 0;
  struct Visible {
    uint32_t min = 0, median = 0, max = 0;
    double mean = 0, mean_share = 0;  // share of the universe
  };
  std::optional<Visible> visible;   // none when every cell is absent
  std::vector<uint32_t> histogram;  // 10 bins of 10% of the universe (the last includes 100%)
  // Per cell: visible count (0 when absent), encoding name, block bytes.
  std::vector<uint32_t> cell_visible;
  std::vector<std::string> cell_encoding;
  std::vector<uint32_t> cell_bytes;
};

// Reads every block of `r`. Deterministic.
PvsSummary summarize_pvs(pvs::Reader& r);

}  // namespace vislib
