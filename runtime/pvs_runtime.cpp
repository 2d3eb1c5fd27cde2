// pvs_runtime.cpp: the runtime loader (runtime/pvs_runtime.h): a memory-mapped pvs::Reader plus
// cell lookup and neighbour queries. POSIX mmap/madvise; no dependency beyond pvs_format.
#include "runtime/pvs_runtime.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <string_view>

namespace pvs_runtime {

namespace {

std::string hex64(uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// Read-only mapping of a whole file; unmapped on destruction.
struct Mapping {
  void* data = nullptr;
  size_t size = 0;

  Mapping() = default;
  Mapping(const Mapping&) = delete;
  Mapping& operator=(const Mapping&) = delete;
  ~Mapping() {
    if (data) munmap(data, size);
  }

  void map(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
      int e = errno;
      throw OpenError("cannot open " + path + ": " + std::strerror(e), e);
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
      int e = errno;
      ::close(fd);
      throw OpenError("cannot stat " + path + ": " + std::strerror(e), e);
    }
    if (!S_ISREG(st.st_mode)) {
      ::close(fd);
      throw OpenError("cannot memory-map " + path + ": not a regular file", EINVAL);
    }
    size = size_t(st.st_size);
    if (size > 0) {  // mmap of length 0 fails; an empty file is left to the reader ("truncated")
      void* p = mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
      if (p == MAP_FAILED) {
        int e = errno;
        ::close(fd);
        throw OpenError("cannot memory-map " + path + ": " + std::strerror(e), e);
      }
      data = p;
      // Cells are read in the order the viewer walks, not the file order.
      madvise(data, size, MADV_RANDOM);
    }
    ::close(fd);  // the mapping keeps the file referenced
  }

  std::string_view view() const { return {static_cast<const char*>(data), size}; }
};

bool boxes_overlap(const pvs::Box& a, const pvs::Box& b, double margin) {
  for (int k = 0; k < 3; ++k)
    if (a.min[k] - margin > b.max[k] || b.min[k] > a.max[k] + margin) return false;
  return true;
}

bool box_contains(const pvs::Box& b, const double p[3]) {
  for (int k = 0; k < 3; ++k)
    if (!(p[k] >= b.min[k] && p[k] <= b.max[k])) return false;
  return true;
}

// A 2D bucket grid over x and z for box-list layouts: each box is listed in every bucket its
// x-z footprint overlaps.
struct BucketGrid {
  double min_x = 0, min_z = 0, cell_x = 1, cell_z = 1;
  int nx = 1, nz = 1;
  std::vector<std::vector<uint32_t>> buckets;

  // The bucket of a coordinate, clamped in double before the conversion to int (a far, infinite
  // or NaN coordinate must not overflow the conversion: undefined behaviour). NaN maps to 0.
  static int bucket(double x, double min, double width, int n) {
    double f = std::floor((x - min) / width);
    if (!(f > 0)) return 0;
    if (f >= double(n - 1)) return n - 1;
    return int(f);
  }
  int bx(double x) const { return bucket(x, min_x, cell_x, nx); }
  int bz(double z) const { return bucket(z, min_z, cell_z, nz); }

  void build(const std::vector<pvs::Box>& boxes) {
    if (boxes.empty()) return;
    double max_x = boxes[0].max[0], max_z = boxes[0].max[2];
    min_x = boxes[0].min[0];
    min_z = boxes[0].min[2];
    for (const pvs::Box& b : boxes) {
      min_x = std::min(min_x, b.min[0]);
      min_z = std::min(min_z, b.min[2]);
      max_x = std::max(max_x, b.max[0]);
      max_z = std::max(max_z, b.max[2]);
    }
    // About one box per bucket on a square-ish layout, at most 1024 x 1024 buckets.
    int side = std::clamp(int(std::ceil(std::sqrt(double(boxes.size())))), 1, 1024);
    nx = nz = side;
    cell_x = (max_x - min_x) / nx;
    cell_z = (max_z - min_z) / nz;
    if (!(cell_x > 0)) {
      cell_x = 1;
      nx = 1;
    }
    if (!(cell_z > 0)) {
      cell_z = 1;
      nz = 1;
    }
    buckets.assign(size_t(nx) * size_t(nz), {});
    for (uint32_t c = 0; c < boxes.size(); ++c) {
      const pvs::Box& b = boxes[c];
      for (int j = bz(b.min[2]); j <= bz(b.max[2]); ++j)
        for (int i = bx(b.min[0]); i <= bx(b.max[0]); ++i) buckets[size_t(j) * nx + i].push_back(c);
    }
  }

  // Candidate boxes for the x-z rectangle [x0, x1] x [z0, z1] (a superset; sorted, unique).
  std::vector<uint32_t> candidates(double x0, double x1, double z0, double z1) const {
    std::vector<uint32_t> out;
    if (buckets.empty()) return out;
    for (int j = bz(z0); j <= bz(z1); ++j)
      for (int i = bx(x0); i <= bx(x1); ++i) {
        const auto& b = buckets[size_t(j) * nx + i];
        out.insert(out.end(), b.begin(), b.end());
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
};

}  // namespace

FingerprintMismatch::FingerprintMismatch(uint64_t expected, uint64_t found)
    : pvs::FormatError(24, "scene fingerprint " + hex64(found) + " does not match the scene's " +
                               hex64(expected) + " (this PVS was baked for another scene)"),
      expected_(expected),
      found_(found) {}

struct Pvs::Impl {
  Mapping mapping;  // declared before the reader, so it outlives it
  std::optional<pvs::Reader> reader;
  BucketGrid buckets;  // box-list layouts only
};

Pvs::Pvs(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Pvs::Pvs(Pvs&&) noexcept = default;
Pvs& Pvs::operator=(Pvs&&) noexcept = default;
Pvs::~Pvs() = default;

namespace {

// The checks and tables of open() and open_ranges() once impl->reader is open.
void finish_open(Pvs::Impl& impl, const OpenOptions& options);

}  // namespace

Pvs Pvs::open(const std::string& path, const OpenOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->mapping.map(path);
  pvs::ReadOptions ro;
  ro.max_universe = options.max_universe;
  impl->reader.emplace(pvs::Reader::from_view(impl->mapping.view(), ro));
  finish_open(*impl, options);
  return Pvs(std::move(impl));
}

Pvs Pvs::open_ranges(uint64_t size, pvs::Reader::RangeRead read, const OpenOptions& options) {
  auto impl = std::make_unique<Impl>();
  pvs::ReadOptions ro;
  ro.max_universe = options.max_universe;
  impl->reader.emplace(pvs::Reader::from_ranges(size, std::move(read), ro));
  finish_open(*impl, options);
  return Pvs(std::move(impl));
}

namespace {

void finish_open(Pvs::Impl& impl_ref, const OpenOptions& options) {
  Pvs::Impl* impl = &impl_ref;
  // The fingerprint is compared here rather than by the reader so that a mismatch has its own
  // type (and C error code); the header CRC has been checked by then.
  const pvs::FileInfo& info = impl->reader->info();
  if (options.expected_fingerprint && *options.expected_fingerprint != info.scene_fingerprint)
    throw FingerprintMismatch(*options.expected_fingerprint, info.scene_fingerprint);
  if (options.verify_all_blocks) impl->reader->verify();
  if (info.layout.kind != pvs::LayoutKind::Grid) impl->buckets.build(info.layout.boxes);
}

}  // namespace

const pvs::FileInfo& Pvs::info() const {
  return impl_->reader->info();
}
uint32_t Pvs::cell_count() const {
  return impl_->reader->cell_count();
}
uint64_t Pvs::file_size() const {
  return impl_->reader->file_size();
}

std::optional<uint32_t> Pvs::find_cell(const double position[3]) const {
  // NaN or infinite coordinates lie in no (finite) cell; checked before any arithmetic on them.
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(position[k])) return std::nullopt;
  const pvs::CellLayout& layout = info().layout;
  if (layout.kind != pvs::LayoutKind::Boxes) return layout.find_cell(position);
  for (uint32_t c : impl_->buckets.candidates(position[0], position[0], position[2], position[2]))
    if (box_contains(layout.boxes[c], position))
      return c;  // candidates are sorted: lowest id first
  return std::nullopt;
}

std::vector<uint32_t> Pvs::neighbours(uint32_t cell, double margin) const {
  assert(cell < cell_count());
  assert(margin >= 0);
  const pvs::CellLayout& layout = info().layout;
  const pvs::Box me = layout.cell_box(cell);
  std::vector<uint32_t> out;
  if (layout.kind == pvs::LayoutKind::Grid) {
    const uint32_t n[3] = {layout.nx, layout.ny, layout.nz};
    uint32_t idx[3] = {cell % layout.nx, (cell / layout.nx) % layout.ny,
                       cell / (layout.nx * layout.ny)};
    int64_t lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      double w = (layout.grid_box.max[k] - layout.grid_box.min[k]) / n[k];
      // In double first: an infinite or huge margin reaches every cell (no overflowing cast).
      double r = w > 0 ? std::ceil(margin / w) + 1 : double(n[k]);
      int64_t reach = r >= double(n[k]) ? int64_t(n[k]) : int64_t(r);
      lo[k] = std::max<int64_t>(0, int64_t(idx[k]) - reach);
      hi[k] = std::min<int64_t>(int64_t(n[k]) - 1, int64_t(idx[k]) + reach);
    }
    for (int64_t z = lo[2]; z <= hi[2]; ++z)
      for (int64_t y = lo[1]; y <= hi[1]; ++y)
        for (int64_t x = lo[0]; x <= hi[0]; ++x) {
          uint32_t c = uint32_t(x + int64_t(layout.nx) * (y + int64_t(layout.ny) * z));
          if (c != cell && boxes_overlap(me, layout.cell_box(c), margin)) out.push_back(c);
        }
    std::sort(out.begin(), out.end());
    return out;
  }
  // BSP tree: the stored neighbours (leaves sharing a portal), and with a margin > 0 also the
  // cells whose bounding boxes come within it.
  const bool bsp = layout.kind == pvs::LayoutKind::BspTree;
  if (bsp && !(margin > 0)) return layout.neighbours[cell];
  for (uint32_t c : impl_->buckets.candidates(me.min[0] - margin, me.max[0] + margin,
                                              me.min[2] - margin, me.max[2] + margin))
    if (c != cell && boxes_overlap(me, layout.boxes[c], margin)) out.push_back(c);
  if (bsp) {
    std::vector<uint32_t> both;
    std::set_union(out.begin(), out.end(), layout.neighbours[cell].begin(),
                   layout.neighbours[cell].end(), std::back_inserter(both));
    return both;
  }
  return out;
}

uint32_t Pvs::visible_count(uint32_t cell) const {
  assert(cell < cell_count());
  return impl_->reader->entry(cell).count;
}

bool Pvs::is_absent(uint32_t cell) {
  assert(cell < cell_count());
  return impl_->reader->is_absent(cell);
}

std::vector<uint32_t> Pvs::visible_ids(uint32_t cell) {
  assert(cell < cell_count());
  return impl_->reader->read_cell(cell);
}

std::pair<uint64_t, uint32_t> Pvs::block_range(uint32_t cell) const {
  assert(cell < cell_count());
  const pvs::IndexEntry& e = impl_->reader->entry(cell);
  return {e.offset, e.size};
}

std::vector<uint32_t> Pvs::delta_chain(uint32_t cell) {
  assert(cell < cell_count());
  std::vector<uint32_t> chain{cell};
  for (;;) {
    const pvs::BlockInfo bi = impl_->reader->block_info(chain.back());
    if (bi.encoding != pvs::Encoding::Delta) return chain;
    if (chain.size() > size_t(impl_->reader->info().max_delta_depth))
      throw pvs::FormatError(impl_->reader->entry(chain.back()).offset,
                             "cell " + std::to_string(cell) + ": Delta chain longer than " +
                                 std::to_string(impl_->reader->info().max_delta_depth));
    chain.push_back(bi.reference);
  }
}

void Pvs::prefetch(uint32_t cell) {
  assert(cell < cell_count());
  const pvs::IndexEntry& e = impl_->reader->entry(cell);
  if (!impl_->mapping.data || e.size == 0) return;
  const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
  uintptr_t begin = reinterpret_cast<uintptr_t>(impl_->mapping.data) + uintptr_t(e.offset);
  uintptr_t end = begin + e.size;
  begin &= ~(page - 1);
  madvise(reinterpret_cast<void*>(begin), end - begin,
          MADV_WILLNEED);  // advice only: errors ignored
}

}  // namespace pvs_runtime
