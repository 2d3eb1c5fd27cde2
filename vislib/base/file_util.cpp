// file_util.cpp: whole-file reads, AtomicFile (exclusive non-following temporaries, fsync of file
// and folder, stale-temp cleanup) and FileLock (file_util.h).
#include "vislib/base/file_util.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "vislib/base/error.h"

namespace vislib {

std::string read_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot open file: ") + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path, "read error");
  return ss.str();
}

namespace {

[[noreturn]] void io_fail(const std::string& path, const std::string& what, int err) {
  throw std::runtime_error(path + ": " + what + ": " + std::strerror(err));
}

// Folder of `path` ("." if none) and its file name.
void split_path(const std::string& path, std::string& dir, std::string& name) {
  size_t slash = path.rfind('/');
  dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  name = slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string random_suffix() {
  static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  unsigned char raw[12];
  size_t got = 0;
  while (got < sizeof raw) {
    ssize_t n = ::getrandom(raw + got, sizeof raw - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      // No getrandom: fall back to the clock and the address space layout (still not guessable
      // in advance by another user, and O_EXCL keeps it safe anyway).
      uint64_t x = uint64_t(std::clock()) ^ uint64_t(reinterpret_cast<uintptr_t>(&n)) ^
                   uint64_t(time(nullptr)) << 20;
      for (auto& b : raw)
        b = (unsigned char)((x = x * 6364136223846793005ull + 1442695040888963407ull) >> 56);
      break;
    }
    got += size_t(n);
  }
  std::string s;
  for (unsigned char b : raw) s += alphabet[b % 62];
  return s;
}

// Parses the pid of a temporary of our naming for `name`, or returns 0 if `entry` is not one:
// ".NAME.<pid>.<12 alnum>.tmp" or the older "NAME.tmp.<pid>".
long temp_owner(const std::string& entry, const std::string& name) {
  auto digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 10 && s.find_first_not_of("0123456789") == std::string::npos;
  };
  const std::string old_prefix = name + ".tmp.";
  if (entry.compare(0, old_prefix.size(), old_prefix) == 0) {
    std::string pid = entry.substr(old_prefix.size());
    return digits(pid) ? std::atol(pid.c_str()) : 0;
  }
  const std::string prefix = "." + name + ".";
  if (entry.size() < prefix.size() + 1 + 1 + 12 + 4 ||
      entry.compare(0, prefix.size(), prefix) != 0 ||
      entry.compare(entry.size() - 4, 4, ".tmp") != 0)
    return 0;
  std::string rest = entry.substr(prefix.size(), entry.size() - prefix.size() - 4);  // <pid>.<12>
  if (rest.size() < 14 || rest[rest.size() - 13] != '.') return 0;
  std::string pid = rest.substr(0, rest.size() - 13), rnd = rest.substr(rest.size() - 12);
  for (char c : rnd)
    if (!std::isalnum(static_cast<unsigned char>(c))) return 0;
  return digits(pid) ? std::atol(pid.c_str()) : 0;
}

// A temporary whose writer may still be running is kept for this long after its last change
// (seconds): a pid that does not run here now may belong to another machine sharing the folder.
constexpr time_t kStaleTempAge = 600;

// Removes the regular files among the temporaries of `name` in `dir` (temp_owner) that another
// process left: with `writers_may_live`, only those whose writer no longer runs here and which
// have not been touched for kStaleTempAge; without, all of them (the caller holds the lock every
// writer holds, so none of their writers is alive). This process's own are kept. Best effort:
// errors are ignored.
void remove_others_temps(const std::string& dir, const std::string& name, bool writers_may_live) {
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  const time_t now = ::time(nullptr);
  while (dirent* e = ::readdir(d)) {
    std::string entry = e->d_name;
    long pid = temp_owner(entry, name);
    if (pid <= 0 || pid == ::getpid()) continue;
    if (writers_may_live && (::kill(pid_t(pid), 0) == 0 || errno != ESRCH))
      continue;  // alive (or unknown)
    std::string full = dir + "/" + entry;
    struct stat st;
    if (::lstat(full.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
      continue;  // never a link or folder
    if (writers_may_live && now - st.st_mtime < kStaleTempAge) continue;
    ::unlink(full.c_str());
  }
  ::closedir(d);
}

void fsync_folder(const std::string& dir) {
  int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) return;
  ::fsync(dfd);  // some file systems refuse fsync on a folder (EINVAL): nothing more to do then
  ::close(dfd);
}

}  // namespace

AtomicFile::AtomicFile(const std::string& path) : path_(path) {
  std::string dir, name;
  split_path(path, dir, name);
  remove_others_temps(dir, name, true);
  for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
    tmp_ = (dir == "/" ? "" : dir) + "/." + name + "." + std::to_string(::getpid()) + "." +
           random_suffix() + ".tmp";
    fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd_ < 0 && errno != EEXIST)
      io_fail(path_, "cannot create a temporary file in " + dir, errno);
  }
  if (fd_ < 0) io_fail(path_, "cannot create a temporary file in " + dir, EEXIST);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) ::unlink(tmp_.c_str());
}

void AtomicFile::write_at(uint64_t offset, std::string_view bytes) {
  if (fd_ < 0) throw std::logic_error("AtomicFile: write after commit");
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::pwrite(fd_, bytes.data() + done, bytes.size() - done, off_t(offset + done));
    if (n < 0) {
      if (errno == EINTR) continue;
      io_fail(path_, "write failed", errno);
    }
    done += size_t(n);
  }
  size_ = std::max<uint64_t>(size_, offset + bytes.size());
}

void AtomicFile::write(std::string_view bytes) {
  write_at(size_, bytes);
}

void AtomicFile::commit() {
  if (fd_ < 0) throw std::logic_error("AtomicFile: commit twice");
  if (::fsync(fd_) != 0 && errno != EINVAL) io_fail(path_, "fsync failed", errno);
  int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) io_fail(path_, "write failed (close)", errno);
  if (::rename(tmp_.c_str(), path_.c_str()) != 0)
    io_fail(path_, "cannot rename " + tmp_ + " into place", errno);
  committed_ = true;
  fsync_folder_of(path_);
}

void remove_dead_writers_temps(const std::string& path) {
  std::string dir, name;
  split_path(path, dir, name);
  remove_others_temps(dir, name, false);
}

void write_file_atomic(const std::string& path, const std::string& bytes) {
  AtomicFile f(path);
  f.write(bytes);
  f.commit();
}

void fsync_folder_of(const std::string& path) {
  std::string dir, name;
  split_path(path, dir, name);
  fsync_folder(dir);
}

int open_locked(const std::string& path, unsigned mode, const std::string& noun,
                const std::string& held_message) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, mode_t(mode));
  if (fd < 0) io_fail(path, "cannot open " + noun, errno);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    int err = errno;
    ::close(fd);
    if (err == EWOULDBLOCK) throw InputError(path, held_message);
    io_fail(path, "cannot lock " + noun, err);
  }
  return fd;
}

FileLock::FileLock(const std::string& path, const std::string& what) : path_(path) {
  // Lock, then check that the file we locked is still the one at `path` (not unlinked and
  // replaced meanwhile); retry otherwise.
  for (int attempt = 0; attempt < 100; ++attempt) {
    fd_ = open_locked(path, 0666, "the lock file",
                      "is locked by another process: " + what +
                          " is in use (another pvs bake or resume is running); wait for it to "
                          "finish or stop it");
    struct stat a, b;
    if (::fstat(fd_, &a) == 0 && ::stat(path.c_str(), &b) == 0 && a.st_ino == b.st_ino &&
        a.st_dev == b.st_dev)
      return;
    ::close(fd_);
    fd_ = -1;
  }
  throw std::runtime_error(path + ": cannot lock: the lock file keeps being replaced");
}

FileLock::~FileLock() {
  // Unlinked while still locked: a process that opened the old file meanwhile sees, once it gets
  // the lock, that the path no longer names its file, and starts over (constructor).
  if (fd_ >= 0) {
    ::unlink(path_.c_str());
    ::close(fd_);
  }
}

std::string file_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace vislib
