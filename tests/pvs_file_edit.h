// pvs_file_edit.h: for tests that edit a PVS file's bytes on purpose: recompute every CRC so that
// the edited field reaches the reader's parsing instead of failing a checksum.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

#include "pvs_format/pvs_format.h"

namespace vislib_test {

// Re-computes every CRC of a file so that a deliberately edited field reaches the parser.
inline void fix_crcs(std::string& f) {
  auto get32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, f.data() + at, 4);
    return v;
  };
  auto set32 = [&](size_t at, uint32_t v) { std::memcpy(&f[at], &v, 4); };
  uint32_t n = get32(36), layout_size = get32(44);
  set32(60, pvs::crc32c(f.data(), 60));
  set32(64 + layout_size - 4, pvs::crc32c(f.data() + 64, layout_size - 4));
  size_t index = 64 + layout_size;
  for (uint32_t c = 0; c < n; ++c) {
    uint64_t off;
    std::memcpy(&off, f.data() + index + 16 * c, 8);
    uint32_t size = get32(index + 16 * c + 8);
    if (off + size <= f.size() && size >= 5)
      set32(off + size - 4, pvs::crc32c(f.data() + off, size - 4));
  }
  set32(index + 16 * n, pvs::crc32c(f.data() + index, 16 * n));
}

}  // namespace vislib_test
