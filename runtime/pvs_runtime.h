// pvs_runtime.h: what an engine embeds to apply a PVS at run time.
//
// Opens a PVS file (docs/pvs-format.md) memory-mapped, checks that it was baked for the engine's
// scene (the 64-bit scene fingerprint), finds the view cell of the eye position and the cells
// around it to prefetch, and returns a cell's visible triangle or object ids.
//
// Depends on pvs_format/ and the C++ standard library (plus POSIX mmap) only, never on vislib/,
// Embree, TBB or OpenImageIO (house style, "Which way the arrows point"). A plain C API with the
// same functions is in runtime/pvs_runtime_c.h; docs/runtime.md documents both.
//
// Errors (house style, three tiers): a caller bug (a cell id >= cell_count()) is an assert; a file
// that cannot be opened or mapped throws OpenError; a malformed, truncated or corrupt file throws
// pvs::FormatError carrying the byte offset; a PVS of another scene throws FingerprintMismatch
// (a pvs::FormatError at byte 24, the header field).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pvs_format/pvs_format.h"

namespace pvs_runtime {

// The file could not be opened, sized or memory-mapped. `error_number()` is the errno of the
// failing system call, what() names the path and the call.
class OpenError : public std::runtime_error {
 public:
  OpenError(const std::string& message, int error_number)
      : std::runtime_error(message), errno_(error_number) {}
  int error_number() const { return errno_; }

 private:
  int errno_;
};

// The file is a valid PVS header-wise but was baked for another scene.
class FingerprintMismatch : public pvs::FormatError {
 public:
  FingerprintMismatch(uint64_t expected, uint64_t found);
  uint64_t expected() const { return expected_; }
  uint64_t found() const { return found_; }

 private:
  uint64_t expected_, found_;
};

struct OpenOptions {
  // The fingerprint of the scene the engine renders (vislib's scene_fingerprint(), whose byte
  // stream docs/pvs-format.md specifies so an engine can recompute it). If set, a PVS of another
  // scene is rejected with FingerprintMismatch. Leaving it unset is only for tools.
  std::optional<uint64_t> expected_fingerprint;
  // True: read and CRC-check every block at open (touches the whole file). False (default): only
  // the header, layout section and index are read at open, each block is checked when first read.
  bool verify_all_blocks = false;
  // Passed to pvs::ReadOptions::max_universe (bounds the memory one decoded set can take).
  uint32_t max_universe = 1u << 27;
};

// An open, memory-mapped PVS file. Move-only. Not thread-safe: use one Pvs per thread (opening
// the same file several times shares the pages through the OS page cache).
// The file must not be truncated or rewritten in place while open (a mapped page that vanishes
// raises SIGBUS); `pvs bake` writes a temporary file and renames it, which is safe.
class Pvs {
 public:
  // Maps `path` read-only and checks its header, layout section and index (and every block if
  // options.verify_all_blocks). Throws OpenError, pvs::FormatError or FingerprintMismatch.
  static Pvs open(const std::string& path, const OpenOptions& options = {});
  // Reads a file of `size` bytes through `read` (byte ranges, pvs::Reader::from_ranges) instead
  // of a mapping: for a file served over HTTP range requests (the web client) or kept in an
  // archive. Opening asks for the header, the layout section and the index; visible_ids() for the
  // cell's block and those of its Delta chain; prefetch() does nothing. An exception `read`
  // throws reaches the caller (the C API reports it as PVS_RT_IO).
  static Pvs open_ranges(uint64_t size, pvs::Reader::RangeRead read,
                         const OpenOptions& options = {});

  Pvs(Pvs&&) noexcept;
  Pvs& operator=(Pvs&&) noexcept;
  ~Pvs();

  const pvs::FileInfo& info() const;
  uint32_t cell_count() const;
  uint64_t file_size() const;

  // The cell whose lookup box contains `position` (x, y, z in scene units, y up; boundaries
  // inclusive, the lowest cell id wins on shared faces), or nullopt if none does (the eye is
  // outside every cell: an engine typically keeps the last cell). BSP tree: the cell of the leaf
  // the walk down the stored planes reaches, nullopt for a leaf without a cell (solid, sky, not
  // baked). Same answer as pvs::CellLayout::find_cell. A NaN or infinite coordinate gives
  // nullopt. Grid: O(1); box list: O(boxes in one bucket) through a 2D bucket grid over x and z
  // built at open; BSP tree: O(tree depth).
  std::optional<uint32_t> find_cell(const double position[3]) const;

  // The cells to prefetch around `cell` (< cell_count()): every other cell whose lookup box comes
  // within `margin` scene units (margin >= 0) of this cell's box on every axis, i.e. the boxes
  // overlap once this one is grown by `margin`. margin = 0: the cells that touch it (for a grid,
  // the up to 26 around it); margin = +infinity: every other cell. BSP tree: the neighbours the
  // file stores (leaves sharing a portal), plus for margin > 0 the cells whose bounding boxes
  // come within `margin` of this cell's. Sorted by id, without `cell`.
  std::vector<uint32_t> neighbours(uint32_t cell, double margin = 0.0) const;

  // Number of visible ids of `cell`, from the index (no block is read). 0 for an absent cell.
  uint32_t visible_count(uint32_t cell) const;
  // True if the cell has no data in this file (a shard of a bake).
  bool is_absent(uint32_t cell);

  // The visible ids of `cell`, sorted ascending, each < info().universe: triangle ids or object
  // ids as info().granularity says. Decodes the cell's block (and the blocks of its Delta chain,
  // at most info().max_delta_depth more) from the mapping. Throws pvs::FormatError on a corrupt
  // block or an absent cell.
  std::vector<uint32_t> visible_ids(uint32_t cell);

  // The byte range of the cell's block in the file (from the index; offset, bytes): what a
  // streaming client fetches ahead for a cell (its Delta chain's blocks are known only once the
  // block is read).
  std::pair<uint64_t, uint32_t> block_range(uint32_t cell) const;

  // The cells whose blocks visible_ids(cell) reads: `cell` first, then the cell each Delta block
  // refers to, until a block that is not a Delta (at most info().max_delta_depth references).
  // Reads those blocks (each once; no ids are decoded): a streaming client calls it for a
  // neighbour and so fetches the neighbour's whole chain ahead. Throws pvs::FormatError on a
  // corrupt block or a chain longer than max_delta_depth.
  std::vector<uint32_t> delta_chain(uint32_t cell);

  // Asks the OS to page in the block of `cell` (madvise MADV_WILLNEED on its byte range, from the
  // index; returns immediately, reads nothing). The blocks of its Delta chain are not known
  // without reading the block, so they are paged in when visible_ids() decodes it. Call it for the
  // neighbours of the current cell so that crossing into one of them does not wait for the disk.
  void prefetch(uint32_t cell);

  struct Impl;

 private:
  explicit Pvs(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace pvs_runtime
