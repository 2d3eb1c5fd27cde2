// pvs_reader_fuzz.cpp: libFuzzer target for the PVS reader (pvs_format/). Any input must either
// be rejected with pvs::FormatError or read completely; no crash, no out-of-bounds access, no
// other exception, no leak (AddressSanitizer + UndefinedBehaviorSanitizer). Each input is read
// twice: with checksums checked (the reader as shipped) and with them skipped, so that the fuzzer
// reaches the parsing behind the CRCs. A file read completely is written again and read back: the
// sets must survive (the writer's own round trip).
//
// Build and run: scripts/fuzz.sh (clang++ -fsanitize=fuzzer,address,undefined).
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "pvs_format/pvs_format.h"

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void exercise(std::string_view bytes, bool checksums) {
  pvs::ReadOptions opt;
  opt.verify_checksums = checksums;
  opt.max_universe = 1u << 16;  // bounds the work per input; the default is 2^27
  try {
    pvs::Reader r = pvs::Reader::from_memory(bytes, opt);
    const pvs::FileInfo& info = r.info();
    const pvs::CellLayout& L = info.layout;
    check(L.cell_count() == r.cell_count());
    std::vector<pvs::CellSet> cells(r.cell_count());
    bool complete = true;
    for (uint32_t c = 0; c < r.cell_count(); ++c) {
      // A cell's min corner lies in its box: the lookup must find a cell there (maybe an earlier
      // one sharing the corner).
      pvs::Box b = L.cell_box(c);
      auto found = L.find_cell(b.min);
      if (L.kind == pvs::LayoutKind::BspTree) {
        // A BSP cell's box only bounds its volume: the walk ends in some leaf, whose cell (if
        // any) is in range.
        auto leaf = L.find_leaf(b.min);
        check(leaf.has_value() && *leaf < L.leaf_cell.size());
        check(!found || *found < r.cell_count());
      } else {
        check(found.has_value() && *found <= c);
      }
      (void)L.view_region(c);
      try {
        (void)r.block_info(c);
        if (r.is_absent(c)) continue;
        cells[c] = r.read_cell(c);
        const auto& ids = *cells[c];
        check(ids.size() == r.entry(c).count);
        for (size_t i = 0; i < ids.size(); ++i)
          check(ids[i] < info.universe && (i == 0 || ids[i - 1] < ids[i]));
      } catch (const pvs::FormatError&) {
        complete = false;
      }
    }
    if (complete) {
      pvs::Reader again = pvs::Reader::from_memory(pvs::write_pvs(info, cells));
      for (uint32_t c = 0; c < again.cell_count(); ++c)
        if (cells[c]) check(again.read_cell(c) == *cells[c]);
    }
  } catch (const pvs::FormatError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  exercise(bytes, true);
  exercise(bytes, false);
  return 0;
}
