// checkpoint.cpp: append-only, CRC-checked, fsync'd records of finished cells (checkpoint.h).
#include "vislib/bake/checkpoint.h"

#include <fcntl.h>
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

void put_u32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}
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
                       std::vector<std::optional<std::vector<uint32_t>>>* recovered, uint32_t universe)
    : path_(path) {
  if (recovered) recovered->assign(cell_count, std::nullopt);
  size_t keep = 0;  // bytes of the existing file to keep
  struct stat st;
  if (resume && ::stat(path.c_str(), &st) == 0) {
    std::string bytes = read_file(path);
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), kCheckpointMagic, 8) != 0)
      throw InputError(path, "not a bake checkpoint (bad magic bytes)");
    if (bytes.size() >= kCheckpointHeader) {
      if (get_u32(bytes, 20) != pvs::crc32c(bytes.data(), 20))
        throw InputError(path, "byte 20: checkpoint header checksum mismatch");
      if (get_u32(bytes, 8) != 1)
        throw InputError(path, "byte 8: checkpoint version " + std::to_string(get_u32(bytes, 8)) + " (this bake reads 1)");
      if (get_u64(bytes, 12) != key)
        throw InputError(path, "the checkpoint belongs to another bake (other scene, cells or settings); delete it or bake without --resume");
      keep = kCheckpointHeader;
      while (bytes.size() - keep >= 12) {
        uint32_t size = get_u32(bytes, keep);
        if (uint64_t(size) + 12 > bytes.size() - keep) break;  // torn record
        uint32_t crc = get_u32(bytes, keep + 8 + size);
        if (crc != pvs::crc32c(bytes.data() + keep, 8 + size)) break;  // torn or damaged
        uint32_t cell = get_u32(bytes, keep + 4);
        if (cell >= cell_count)
          throw InputError(path, "byte " + std::to_string(keep + 4) + ": record of cell " + std::to_string(cell) + ", the bake has " + std::to_string(cell_count));
        std::vector<uint32_t> ids;
        try {
          ids = pvs::decode_sorted_delta(std::string_view(bytes).substr(keep + 8, size), universe, keep + 8);
        } catch (const pvs::FormatError& e) {
          throw InputError(path, std::string("record of cell ") + std::to_string(cell) + ": " + e.what());
        }
        if (recovered) (*recovered)[cell] = std::move(ids);
        ++recovered_records_;
        keep += 12 + size;
      }
      discarded_bytes_ = bytes.size() - keep;
    }
  }
  int flags = O_WRONLY | O_CREAT | O_CLOEXEC | (keep == 0 ? O_TRUNC : 0);
  fd_ = ::open(path.c_str(), flags, 0644);
  if (fd_ < 0) io_error(path, "cannot open the checkpoint");
  if (keep == 0) {
    write_all(fd_, header_bytes(key), path);
    // Make the new file's directory entry durable too (a power cut, not only a killed process).
    std::string dir = path.find('/') == std::string::npos ? "." : path.substr(0, path.rfind('/') + 1);
    int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      ::fsync(dfd);
      ::close(dfd);
    }
  } else {
    if (::ftruncate(fd_, off_t(keep)) != 0) io_error(path, "cannot cut the torn tail of the checkpoint");
    if (::lseek(fd_, 0, SEEK_END) < 0) io_error(path, "seek failed");
    if (::fdatasync(fd_) != 0) io_error(path, "fsync failed");
  }
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
