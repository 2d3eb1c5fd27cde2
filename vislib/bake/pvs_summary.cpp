// pvs_summary.cpp: statistics of a whole PVS file.
#include "vislib/bake/pvs_summary.h"

#include <algorithm>
#include <cmath>

namespace vislib {

std::string block_encoding_name(const pvs::BlockInfo& b) {
  std::string s = pvs::encoding_name(b.encoding);
  if (b.encoding == pvs::Encoding::Delta) s += std::string("/") + pvs::encoding_name(b.inner);
  return s;
}

PvsSummary summarize_pvs(pvs::Reader& r) {
  const pvs::FileInfo& info = r.info();
  const uint32_t n = r.cell_count();
  PvsSummary out;
  uint64_t all_sorted = 0, all_runs = 0, best_plain = 0, present = 0;
  out.cell_visible.assign(n, 0);
  out.cell_encoding.resize(n);
  out.cell_bytes.resize(n);
  for (uint32_t c = 0; c < n; ++c) {
    pvs::BlockInfo b = r.block_info(c);
    out.cell_encoding[c] = block_encoding_name(b);
    out.cell_bytes[c] = b.size;
    PvsSummary::Mix& m = out.compression[out.cell_encoding[c]];
    ++m.cells;
    m.bytes += b.size;
    if (b.encoding == pvs::Encoding::Absent) continue;
    std::vector<uint32_t> ids = r.read_cell(c);
    out.cell_visible[c] = uint32_t(ids.size());
    std::string s, rl;
    pvs::append_sorted_delta(s, ids);
    pvs::append_run_length(rl, ids);
    all_sorted += s.size() + 5;
    all_runs += rl.size() + 5;
    best_plain += std::min(s.size(), rl.size()) + 5;
    ++present;
  }
  const double pc = present ? double(present) : 1.0;
  uint64_t chosen = 0, total_ids = 0;
  std::vector<uint32_t> sorted;
  for (uint32_t c = 0; c < n; ++c)
    if (out.cell_encoding[c] != "absent") {
      chosen += out.cell_bytes[c];
      sorted.push_back(out.cell_visible[c]);
    }
  for (uint32_t v : out.cell_visible) total_ids += v;
  out.chosen = chosen / pc;
  out.all_sorted_delta = all_sorted / pc;
  out.all_run_length = all_runs / pc;
  out.best_without_delta = best_plain / pc;
  out.raw_bitset = std::ceil(info.universe / 8.0);
  out.raw_u32_list = 4.0 * double(total_ids) / pc;
  std::sort(sorted.begin(), sorted.end());
  if (!sorted.empty())
    out.visible = PvsSummary::Visible{sorted.front(), sorted[sorted.size() / 2], sorted.back(),
                                      double(total_ids) / pc,
                                      info.universe ? double(total_ids) / pc / info.universe : 0.0};
  out.histogram.assign(10, 0);
  for (uint32_t v : sorted) {
    const double share = info.universe ? double(v) / info.universe : 0.0;
    out.histogram[std::min(9, int(share * 10))]++;
  }
  return out;
}

}  // namespace vislib
