// checkpoint.cpp: append-only, CRC-checked, fsync'd records of finished cells (checkpoint.h).
#include "vislib/bake/checkpoint.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "pvs_format/pvs_format.h"
#include "vislib/base/error.h"
#include "vislib/base/file_util.h"

namespace vislib {
namespace {

constexpr char kCheckpointMagic[8] = {'P', 'V', 'S', 'C', 'K', 'P', 'T', '\n'};
constexpr size_t kCheckpointHeader = 24;

using pvs::put_u32;  // the format's little-endian appender
uint32_t get_u32(const std::string& s, size_t at) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(s[at + i])) << (8 * i);
  return v;
}
uint64_t get_u64(const std::string& s, size_t at) {
  return uint64_t(get_u32(s, at)) | (uint64_t(get_u32(s, at + 4)) << 32);
}

std::string header_bytes(uint64_t key) {
  std::string h(kCheckpointMagic, 8);
  put_u32(h, 1);
  put_u32(h, uint32_t(key));
  put_u32(h, uint32_t(key >> 32));
  put_u32(h, pvs::crc32c(h.data(), h.size()));
  return h;
}

[[noreturn]] void io_error(const std::string& path, const char* what) {
  throw std::runtime_error(path + ": " + what + ": " + std::strerror(errno));
}

void write_all(int fd, const std::string& bytes, const std::string& path) {
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      io_error(path, "write failed");
    }
    done += size_t(n);
  }
  if (::fdatasync(fd) != 0) io_error(path, "fsync failed");
}

}  // namespace

Checkpoint::Checkpoint(const std::string& path, uint64_t key, uint32_t cell_count, bool resume,
                       std::vector<std::optional<std::vector<uint32_t>>>* recovered,
                       uint32_t universe)
    : path_(path) {
  if (recovered) recovered->assign(cell_count, std::nullopt);
  // Open without truncating and lock before reading or cutting anything: a second bake or resume
  // on the same checkpoint must not touch the records of the one that holds it.
  fd_ = open_locked(path, 0644, "the checkpoint",
                    "the checkpoint is locked by another process (another pvs bake or resume of "
                    "this bake is running); wait for it to finish or stop it");
  size_t keep = 0;  // bytes of the existing file to keep
  struct stat st;
  if (resume) {
    if (::fstat(fd_, &st) != 0) io_error(path, "cannot stat the checkpoint");
    std::string bytes(size_t(st.st_size), '\0');
    size_t got = 0;
    while (got < bytes.size()) {
      ssize_t n = ::pread(fd_, &bytes[got], bytes.size() - got, off_t(got));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) io_error(path, "cannot read the checkpoint");
      got += size_t(n);
    }
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), kCheckpointMagic, 8) != 0)
      throw InputError(path, "not a bake checkpoint (bad magic bytes)");
    if (bytes.size() >= kCheckpointHeader) {
      if (get_u32(bytes, 20) != pvs::crc32c(bytes.data(), 20))
        throw InputError(path, "byte 20: checkpoint header checksum mismatch");
      if (get_u32(bytes, 8) != 1)
        throw InputError(path, "byte 8: checkpoint version " + std::to_string(get_u32(bytes, 8)) +
                                   " (this bake reads 1)");
      if (get_u64(bytes, 12) != key)
        throw InputError(path,
                         "the checkpoint belongs to another bake (other scene, cells or settings); "
                         "delete it or bake without --resume");
      // A record at `at` is whole and intact if its size fits in the file and its CRC matches.
      auto intact = [&](size_t at) {
        if (bytes.size() - at < 12) return false;
        uint32_t size = get_u32(bytes, at);
        if (uint64_t(size) + 12 > bytes.size() - at) return false;
        return get_u32(bytes, at + 8 + size) == pvs::crc32c(bytes.data() + at, 8 + size);
      };
      size_t at = kCheckpointHeader;
      keep = at;
      while (bytes.size() - at >= 12) {
        if (!intact(at)) {
          // A damaged record (a flipped bit on disk) or a torn tail (a write cut by a kill). The
          // next record starts at the first offset after `at` where an intact record lies: where
          // the size field points when only the payload or CRC is damaged, elsewhere when the size
          // field itself is hit (searched byte by byte; an intact record has a matching CRC-32C,
          // so a false start has probability 2^-32 per offset). With none, the rest is a torn
          // tail and is cut off.
          size_t next = 0;
          for (size_t q = at + 1; q + 12 <= bytes.size(); ++q)
            if (intact(q)) {
              next = q;
              break;
            }
          if (next == 0) break;  // torn or damaged tail
          ++dropped_records_;
          discarded_bytes_ += next - at;
          at = next;
          continue;
        }
        uint32_t size = get_u32(bytes, at);
        uint32_t cell = get_u32(bytes, at + 4);
        if (cell >= cell_count)
          throw InputError(path, "byte " + std::to_string(at + 4) + ": record of cell " +
                                     std::to_string(cell) + ", the bake has " +
                                     std::to_string(cell_count));
        std::vector<uint32_t> ids;
        try {
          ids = pvs::decode_sorted_delta(std::string_view(bytes).substr(at + 8, size), universe,
                                         at + 8);
        } catch (const pvs::FormatError& e) {
          throw InputError(path,
                           std::string("record of cell ") + std::to_string(cell) + ": " + e.what());
        }
        if (recovered) (*recovered)[cell] = std::move(ids);
        ++recovered_records_;
        at += 12 + size;
        keep = at;
      }
      if (at < bytes.size()) {  // a torn (or damaged) tail: cut off below, counted as one record
        ++dropped_records_;
        discarded_bytes_ += bytes.size() - at;
      }
    }
  }
  if (keep == 0) {
    if (::ftruncate(fd_, 0) != 0) io_error(path, "cannot empty the checkpoint");
    write_all(fd_, header_bytes(key), path);
    // Make the new file's directory entry durable too (a power cut, not only a killed process).
    fsync_folder_of(path);
  } else {
    if (::ftruncate(fd_, off_t(keep)) != 0)
      io_error(path, "cannot cut the torn tail of the checkpoint");
    if (::fdatasync(fd_) != 0) io_error(path, "fsync failed");
  }
  if (::lseek(fd_, 0, SEEK_END) < 0) io_error(path, "seek failed");
}

Checkpoint::~Checkpoint() {
  if (fd_ >= 0) ::close(fd_);
}

void Checkpoint::append(uint32_t cell, const std::vector<uint32_t>& ids) {
  std::string payload;
  pvs::append_sorted_delta(payload, ids);
  std::string rec;
  put_u32(rec, uint32_t(payload.size()));
  put_u32(rec, cell);
  rec += payload;
  put_u32(rec, pvs::crc32c(rec.data(), rec.size()));
  std::lock_guard<std::mutex> lock(mutex_);
  write_all(fd_, rec, path_);
}

void Checkpoint::remove() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  ::unlink(path_.c_str());
}

}  // namespace vislib
