// checkpoint.h: the append-only checkpoint file of a bake, so that a bake killed at any instant
// (kill -9, a node lost from a cluster) resumes without losing a finished cell.
//
// File: a 24-byte header, "PVSCKPT\n" (8 bytes), u32 version 1, u64 bake key, u32 CRC32C of the
// 20 bytes before it; then one record per finished cell, in the order cells finished:
// u32 payload size, u32 cell id, payload (the cell's ids as a pvs SortedDelta payload), u32
// CRC32C of the record's bytes before it. All little-endian. A record is written with a single
// write() and fsync'd before the cell counts as done. On reopening, every intact record is kept: a
// record that fails its CRC (a damaged byte) is skipped up to the next intact record (where its
// size field points, or, if the size field itself is damaged, the first offset after it where a
// record with a matching CRC starts, searched byte by byte); its cell is baked again. A
// tail with no intact record (a write torn by the kill) is cut off and appending continues. The
// open checkpoint is locked (flock): a second bake or resume of the same file is refused.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace vislib {

class Checkpoint {
 public:
  // Opens the checkpoint `path` of the bake identified by `key` (any 64-bit digest of everything
  // the bake's result depends on) with `cell_count` cells.
  //  - resume = false: starts an empty checkpoint (replacing any file at `path`).
  //  - resume = true: if `path` exists, keeps its valid records and returns their cells in
  //    `recovered` (indexed by cell id); throws InputError if the file is not a checkpoint or
  //    belongs to another bake (other key), or if a record with a valid CRC names a cell out of
  //    range or holds a malformed set. A missing file or a torn header starts empty.
  // Throws InputError if another process holds the checkpoint's lock (a bake running on it),
  // std::runtime_error on I/O failure. A symbolic link at `path` is not followed.
  Checkpoint(const std::string& path, uint64_t key, uint32_t cell_count, bool resume,
             std::vector<std::optional<std::vector<uint32_t>>>* recovered = nullptr,
             uint32_t universe = 0xFFFFFFFFu);
  ~Checkpoint();
  Checkpoint(const Checkpoint&) = delete;
  Checkpoint& operator=(const Checkpoint&) = delete;

  // Appends the record of a finished cell and fsyncs it. Thread-safe.
  void append(uint32_t cell, const std::vector<uint32_t>& ids);
  // Closes and deletes the file (after the PVS file is safely in place).
  void remove();
  const std::string& path() const { return path_; }
  // Records kept from the previous run (resume); damaged records skipped plus a torn tail (each
  // counts one) and the bytes they spanned.
  size_t recovered_records() const { return recovered_records_; }
  size_t dropped_records() const { return dropped_records_; }
  uint64_t discarded_bytes() const { return discarded_bytes_; }

 private:
  std::string path_;
  int fd_ = -1;
  std::mutex mutex_;
  size_t recovered_records_ = 0;
  size_t dropped_records_ = 0;
  uint64_t discarded_bytes_ = 0;
};

}  // namespace vislib
