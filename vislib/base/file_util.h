// file_util.h: whole-file reads and crash-safe writes, shared by importers, writers and the CLI.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace vislib {

// Reads a whole file. Throws InputError(path, "cannot open ...") if it is missing or unreadable.
std::string read_file(const std::string& path);

// A file written through a temporary in the same folder and renamed into place by commit(), so
// that a crash or an error never leaves a half-written `path`, and a symbolic link planted by
// someone else is never followed:
//  - the temporary is created with O_CREAT | O_EXCL | O_NOFOLLOW under an unpredictable name
//    `.NAME.<pid>.<12 random characters>.tmp` (NAME = the file name of `path`), mode 0666 & ~umask;
//  - commit() fsyncs the file, renames it over `path` (a symbolic link at `path` is replaced, its
//    target untouched) and fsyncs the folder, so the new name survives a power cut;
//  - a temporary not committed is removed by the destructor; temporaries of this naming (and of
//    the older `path.tmp.<pid>`) left for `path` by a process that no longer runs on this machine
//    and untouched for 10 minutes are removed when the file is opened (stale temps of a kill).
// Throws std::runtime_error (naming `path`) on I/O failure. Not thread-safe (one writer per
// object).
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Appends bytes at the end.
  void write(std::string_view bytes);
  // Overwrites bytes at `offset` (must lie within what was written).
  void write_at(uint64_t offset, std::string_view bytes);
  uint64_t size() const { return size_; }
  // Flushes, renames into place and makes the rename durable. At most once.
  void commit();
  const std::string& temp_path() const { return tmp_; }

 private:
  std::string path_, tmp_;
  int fd_ = -1;
  uint64_t size_ = 0;
  bool committed_ = false;
};

// Removes every temporary of AtomicFile's naming left for `path` by another process, whatever its
// age and whether or not its pid runs now (a pid may have been reused), and keeps this process's
// own. Only for a caller that holds the lock every writer of `path` takes (pvs bake's
// OUTPUT.lock, FileLock below): holding it proves that no other writer of `path` is alive, so a
// killed bake's temporaries go at once instead of after AtomicFile's ten minutes. Best effort.
void remove_dead_writers_temps(const std::string& path);

// Writes `bytes` to `path` through an AtomicFile (see above).
void write_file_atomic(const std::string& path, const std::string& bytes);

// Makes the directory entry of `path` durable (a power cut, not only a killed process): fsyncs
// the folder holding it. Best effort: a folder that cannot be opened or synced is left as it is.
void fsync_folder_of(const std::string& path);

// Opens `path` for reading and writing (created with permission bits `mode` if missing, never
// through a symbolic link, close-on-exec) and takes an exclusive advisory lock (flock) on it
// without waiting. Returns the descriptor; closing it releases the lock. Throws
// InputError(path, held_message) if another process holds the lock, std::runtime_error
// ("cannot open <noun>", "cannot lock <noun>") on I/O failure.
int open_locked(const std::string& path, unsigned mode, const std::string& noun,
                const std::string& held_message);

// An exclusive advisory lock (flock) on the file `path` (created if missing, never through a
// symbolic link), held until the object is destroyed. Used by pvs bake on OUTPUT.lock so that two
// bakes of one output cannot run at once. The lock file is removed when the lock is released
// (while still held; a process that opened it meanwhile notices and retries, so removal is safe).
// Throws InputError(path, "... is held by another process ...") if another process holds it
// (`what` says what it protects), std::runtime_error on I/O failure.
class FileLock {
 public:
  FileLock(const std::string& path, const std::string& what);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  std::string path_;
  int fd_ = -1;
};

// Lower-case extension including the dot (".glb"), or "" if none.
std::string file_extension(const std::string& path);

}  // namespace vislib
