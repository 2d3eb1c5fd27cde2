// pvs_synthetic: large PVS files written directly by the format writer (synthetic random sets,
// no scene, no bake), and a check of what the byte-range reader asks for. Test tool of the web
// client's streaming test (scripts/web-range-test.sh); links the runtime only.
//
//   pvs_synthetic write OUT.pvs --grid NX,NZ --ids N [--gap-bytes B] [--seed S]
//       A grid of NX x 1 x NZ cells over [0, NX] x [0, 3] x [0, NZ] (1-unit cells, eye band
//       [1, 2]); each cell sees up to N ids drawn independently, with gaps between ids that take
//       B bytes (1 to 3, default 1) as varints, so the file is about NX * NZ * N * B bytes (ids
//       stay below 2^27: N * 128^(B-1) * 130 should too). Streamed to OUT cell by cell
//       (pvs::StreamWriter), so the file may exceed memory.
//   pvs_synthetic ranges FILE.pvs --cells C1,C2,...
//       Opens FILE through pvs_rt_open_ranges with a pread callback, reads the visible ids of
//       each cell in order, and prints JSON: every range asked for, the ranges allowed (header,
//       layout section, index, and for each cell its block and its Delta chain's, from
//       pvs::Reader), the bytes of each, and the cells' centres. Exit 0 when every range asked
//       for is an allowed one and the bytes read equal the allowed bytes, 1 otherwise, 2 on bad
//       arguments or a bad file.
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pvs_format/pvs_format.h"
#include "runtime/pvs_runtime_c.h"

namespace {

int usage() {
  std::fprintf(
      stderr,
      "usage: pvs_synthetic write OUT.pvs --grid NX,NZ --ids N [--gap-bytes B] [--seed S]\n"
      "       pvs_synthetic ranges FILE.pvs --cells C1,C2,...\n");
  return 2;
}

std::vector<uint64_t> numbers(const char* text) {
  std::vector<uint64_t> out;
  for (const char* p = text; *p;) {
    char* end = nullptr;
    out.push_back(std::strtoull(p, &end, 10));
    if (end == p) return {};
    p = *end == ',' ? end + 1 : end;
    if (*end && *end != ',') return {};
  }
  return out;
}

int write_file(const std::string& out, uint32_t nx, uint32_t nz, uint32_t ids, int gap_bytes,
               uint64_t seed) {
  const uint64_t gap_base = uint64_t(1) << (7 * (gap_bytes - 1));
  pvs::FileInfo info;
  info.scene_fingerprint = 0x5157a7e5ull;
  info.universe =
      uint32_t(std::min<uint64_t>(uint64_t(ids) * (gap_base + 129) + 1, uint64_t(1) << 27));
  info.layout.grid_box = {{0, 0, 0}, {double(nx), 3, double(nz)}};
  info.layout.nx = nx;
  info.layout.nz = nz;
  info.layout.eye_lo = 1;
  info.layout.eye_hi = 2;
  info.metadata = "{\"synthetic\": true}";
  const std::string tmp = out + ".tmp";
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    std::fprintf(stderr, "pvs_synthetic: cannot create %s: %s\n", tmp.c_str(),
                 std::strerror(errno));
    return 2;
  }
  bool ok = true;
  pvs::StreamWriter w(info, [&](uint64_t offset, std::string_view bytes) {
    size_t done = 0;
    while (ok && done < bytes.size()) {
      ssize_t n = pwrite(fd, bytes.data() + done, bytes.size() - done, off_t(offset + done));
      if (n <= 0) ok = false;
      done += size_t(n > 0 ? n : 0);
    }
  });
  std::vector<uint32_t> set;
  for (uint32_t c = 0; c < nx * nz; ++c) {
    uint64_t s = seed * 0x9E3779B97F4A7C15ull + c + 1;
    set.clear();
    uint64_t id = 0;
    for (;;) {
      s ^= s << 13, s ^= s >> 7, s ^= s << 17;  // xorshift64
      id += gap_base + (s >> 57);               // gap - 1 in [gap_base - 1, gap_base + 126]
      if (id >= info.universe || set.size() == ids) break;
      set.push_back(uint32_t(id));
    }
    w.add(set);
  }
  pvs::WriteStats st = w.finish();
  if (::close(fd) != 0) ok = false;
  if (!ok || std::rename(tmp.c_str(), out.c_str()) != 0) {
    std::fprintf(stderr, "pvs_synthetic: cannot write %s\n", out.c_str());
    std::remove(tmp.c_str());
    return 2;
  }
  std::printf("{\"file\": \"%s\", \"bytes\": %llu, \"cells\": %u, \"index_bytes\": %llu}\n",
              out.c_str(), (unsigned long long)st.file_bytes, nx * nz,
              (unsigned long long)st.index_bytes);
  return 0;
}

struct Log {
  int fd = -1;
  std::vector<std::pair<uint64_t, uint64_t>> ranges;
};

int pread_range(void* user, uint64_t offset, uint64_t size, void* out) {
  Log* log = static_cast<Log*>(user);
  log->ranges.emplace_back(offset, offset + size);
  uint64_t done = 0;
  while (done < size) {
    ssize_t n =
        pread(log->fd, static_cast<char*>(out) + done, size_t(size - done), off_t(offset + done));
    if (n <= 0) return 1;
    done += uint64_t(n);
  }
  return 0;
}

int check_ranges(const std::string& path, const std::vector<uint64_t>& cells) {
  try {
    pvs::Reader reader = pvs::Reader::from_file(path);
    Log log;
    log.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (log.fd < 0) throw pvs::FormatError(0, "cannot open " + path);
    pvs_rt* h = nullptr;
    if (pvs_rt_open_ranges(reader.file_size(), pread_range, &log, 0, 0, &h) != PVS_RT_OK)
      throw pvs::FormatError(0, pvs_rt_last_error());
    std::set<std::pair<uint64_t, uint64_t>> allowed = {
        {0, pvs::kHeaderSize},
        {pvs::kHeaderSize, reader.index_offset()},
        {reader.index_offset(), reader.blocks_offset()}};
    std::vector<uint32_t> ids;
    std::string centres;
    for (uint64_t c64 : cells) {
      if (c64 >= reader.cell_count()) throw pvs::FormatError(0, "no cell " + std::to_string(c64));
      uint32_t cell = uint32_t(c64);
      for (uint32_t c = cell;;) {
        const pvs::IndexEntry& e = reader.entry(c);
        allowed.insert({e.offset, e.offset + e.size});
        const pvs::BlockInfo bi = reader.block_info(c);
        if (bi.encoding != pvs::Encoding::Delta) break;
        c = bi.reference;
      }
      ids.resize(reader.entry(cell).count);
      size_t count = 0;
      if (pvs_rt_visible_ids(h, cell, ids.data(), ids.size(), &count) != PVS_RT_OK)
        throw pvs::FormatError(0, pvs_rt_last_error());
      const pvs::Box b = reader.info().layout.view_region(cell);
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s[%.17g, %.17g, %.17g]", centres.empty() ? "" : ", ",
                    0.5 * (b.min[0] + b.max[0]), 0.5 * (b.min[1] + b.max[1]),
                    0.5 * (b.min[2] + b.max[2]));
      centres += buf;
    }
    pvs_rt_close(h);
    ::close(log.fd);
    uint64_t read_bytes = 0, allowed_bytes = 0;
    bool ok = true;
    std::set<std::pair<uint64_t, uint64_t>> asked;
    for (const auto& r : log.ranges) {
      read_bytes += r.second - r.first;
      ok = ok && allowed.count(r) == 1;
      asked.insert(r);
    }
    for (const auto& r : allowed) allowed_bytes += r.second - r.first;
    ok = ok && asked == allowed && read_bytes == allowed_bytes;
    auto list = [](const auto& v) {
      std::string s;
      for (const auto& r : v)
        s += (s.empty() ? "" : ", ") +
             ("[" + std::to_string(r.first) + ", " + std::to_string(r.second) + "]");
      return "[" + s + "]";
    };
    std::printf(
        "{\"file_size\": %llu, \"header_layout_index_bytes\": %llu, \"bytes_read\": %llu, "
        "\"allowed_bytes\": %llu, \"ranges\": %s, \"allowed\": %s, \"centres\": [%s], "
        "\"ok\": %s}\n",
        (unsigned long long)reader.file_size(), (unsigned long long)reader.blocks_offset(),
        (unsigned long long)read_bytes, (unsigned long long)allowed_bytes, list(log.ranges).c_str(),
        list(allowed).c_str(), centres.c_str(), ok ? "true" : "false");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pvs_synthetic: %s: %s\n", path.c_str(), e.what());
    return 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::string mode = argv[1], file = argv[2];
  std::vector<uint64_t> grid, cells;
  uint64_t ids = 0, seed = 1, gap_bytes = 1;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    if (opt == "--grid")
      grid = numbers(argv[i + 1]);
    else if (opt == "--ids")
      ids = std::strtoull(argv[i + 1], nullptr, 10);
    else if (opt == "--gap-bytes")
      gap_bytes = std::strtoull(argv[i + 1], nullptr, 10);
    else if (opt == "--seed")
      seed = std::strtoull(argv[i + 1], nullptr, 10);
    else if (opt == "--cells")
      cells = numbers(argv[i + 1]);
    else
      return usage();
  }
  if (mode == "write") {
    if (grid.size() != 2 || grid[0] == 0 || grid[1] == 0 || grid[0] * grid[1] > (1u << 20) ||
        ids == 0 || ids > (1u << 20) || gap_bytes < 1 || gap_bytes > 3)
      return usage();
    return write_file(file, uint32_t(grid[0]), uint32_t(grid[1]), uint32_t(ids), int(gap_bytes),
                      seed);
  }
  if (mode == "ranges" && !cells.empty()) return check_ranges(file, cells);
  return usage();
}
