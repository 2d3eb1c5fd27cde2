// Tests of file_util.h: AtomicFile / write_file_atomic never follow a planted symbolic link, use
// unpredictable exclusive temporaries, clean up stale temporaries of a killed writer, and FileLock
// refuses a second holder.
#include "vislib/base/file_util.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>
#include <utime.h>

#include <filesystem>

#include "tests/test_support.h"
#include "vislib/base/error.h"

using namespace vislib;
using vislib_test::temp_dir;
namespace fs = std::filesystem;

namespace {

// The pid of a process that has exited (reaped), so no process runs under it (until reuse).
pid_t dead_pid() {
  pid_t p = ::fork();
  if (p == 0) ::_exit(0);
  ::waitpid(p, nullptr, 0);
  return p;
}

void age(const std::string& path, int seconds) {
  struct timeval t[2];
  ::gettimeofday(&t[0], nullptr);
  t[0].tv_sec -= seconds;
  t[1] = t[0];
  ASSERT_EQ(::lutimes(path.c_str(), t), 0);
}

}  // namespace

// The attack: a symbolic link planted at a predictable temporary name (`path.tmp.<pid>`) makes a
// writer that uses that name overwrite the link's target.
TEST(AtomicFile, PlantedSymlinkAtThePredictableTempNameIsNotFollowed) {
  std::string dir = temp_dir("atomic_symlink");
  std::string victim = dir + "/victim", out = dir + "/out.pvs";
  write_file_atomic(victim, "precious");
  fs::create_symlink(victim, out + ".tmp." + std::to_string(::getpid()));
  write_file_atomic(out, "new bytes");
  EXPECT_EQ(read_file(victim), "precious");
  EXPECT_EQ(read_file(out), "new bytes");
  EXPECT_TRUE(fs::is_symlink(out + ".tmp." + std::to_string(::getpid())));  // not ours to remove
}

TEST(AtomicFile, SymlinkAtTheOutputIsReplacedNotWrittenThrough) {
  std::string dir = temp_dir("atomic_out_link");
  std::string victim = dir + "/victim", out = dir + "/out.pvs";
  write_file_atomic(victim, "precious");
  fs::create_symlink(victim, out);
  write_file_atomic(out, "new bytes");
  EXPECT_EQ(read_file(victim), "precious");
  EXPECT_FALSE(fs::is_symlink(out));
  EXPECT_EQ(read_file(out), "new bytes");
}

TEST(AtomicFile, TemporariesAreUnpredictableExclusiveAndRemovedOnError) {
  std::string dir = temp_dir("atomic_temp");
  std::string out = dir + "/o.bin", t1, t2;
  {
    AtomicFile a(out), b(out);
    t1 = a.temp_path();
    t2 = b.temp_path();
    EXPECT_NE(t1, t2);
    std::string prefix = dir + "/.o.bin." + std::to_string(::getpid()) + ".";
    EXPECT_EQ(t1.compare(0, prefix.size(), prefix), 0) << t1;
    struct stat st;
    ASSERT_EQ(::lstat(t1.c_str(), &st), 0);
    EXPECT_TRUE(S_ISREG(st.st_mode));
    a.write("abc");
    a.write_at(1, "X");
    EXPECT_EQ(a.size(), 3u);
    a.commit();
    // b is destroyed without commit (an error path): its temporary disappears.
  }
  EXPECT_EQ(read_file(out), "aXc");
  EXPECT_FALSE(fs::exists(t1));
  EXPECT_FALSE(fs::exists(t2));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicFile, StaleTemporariesOfAKilledWriterAreCleanedUp) {
  std::string dir = temp_dir("atomic_stale");
  std::string out = dir + "/o.pvs";
  const std::string dead = std::to_string(dead_pid());
  std::string stale = dir + "/.o.pvs." + dead + ".AbCdEfGh1234.tmp",
              old_style = out + ".tmp." + dead;
  std::string fresh = dir + "/.o.pvs." + dead + ".ZZZZZZZZZZZZ.tmp";
  std::string alive = dir + "/.o.pvs.1.AbCdEfGh1234.tmp";             // pid 1 runs
  std::string other = dir + "/.p.pvs." + dead + ".AbCdEfGh1234.tmp";  // another file's temporary
  for (const std::string& p : {stale, old_style, fresh, alive, other}) write_file_atomic(p, "x");
  for (const std::string& p : {stale, old_style, alive, other}) age(p, 3600);
  write_file_atomic(out, "y");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_FALSE(fs::exists(old_style));
  EXPECT_TRUE(fs::exists(fresh));  // touched recently: maybe a writer on another machine
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));
}

TEST(FileLock, SecondHolderIsRefusedAndTheLockFileGoesAway) {
  std::string dir = temp_dir("file_lock");
  std::string path = dir + "/o.pvs.lock";
  {
    FileLock first(path, "the output o.pvs");
    try {
      FileLock second(path, "the output o.pvs");
      FAIL() << "locked twice";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("locked by another process"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(path));
  FileLock again(path, "the output o.pvs");
  // A symbolic link at the lock path is not followed.
  std::string link = dir + "/l.lock";
  fs::create_symlink(dir + "/target", link);
  EXPECT_THROW(FileLock(link, "x"), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir + "/target"));
}

// error.h: a std::bad_alloc crossing a stage boundary becomes OutOfMemory naming the stage and the
// size of the failed request (recorded by the `pvs` executable's operator new); an inner stage's
// OutOfMemory passes through outer stages unchanged.
TEST(OutOfMemory, StageAndRequestSizeAreNamed) {
  record_failed_allocation(3u << 30);
  try {
    with_memory_stage("loading city.glb", []() -> int { throw std::bad_alloc(); });
    FAIL() << "no exception";
  } catch (const OutOfMemory& e) {
    std::string what = e.what();
    EXPECT_EQ(e.stage(), "loading city.glb");
    EXPECT_EQ(e.requested_bytes(), size_t(3) << 30);
    EXPECT_NE(what.find("out of memory while loading city.glb"), std::string::npos) << what;
    EXPECT_NE(what.find("3072.0 MiB"), std::string::npos) << what;
  }
  try {
    with_memory_stage("baking", [] {
      with_memory_stage("baking cell 7 of 9", []() -> int { throw std::bad_alloc(); });
    });
    FAIL() << "no exception";
  } catch (const OutOfMemory& e) {
    EXPECT_EQ(e.stage(), "baking cell 7 of 9");
  }
  EXPECT_EQ(with_memory_stage("a stage", [] { return 42; }), 42);
  record_failed_allocation(0);
}
