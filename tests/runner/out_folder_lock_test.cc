// OutFolderLock: one holder at a time (a second lock on the same folder fails naming the holder's
// pid, even in the same process: flock(2) locks belong to open files); released when the holder goes
// away, by destruction or by the death of its process; a path that is a file is refused.
#include "runner/out_folder_lock.h"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <optional>

#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

std::string MessageOfLock(const std::string& dir) {
  try {
    OutFolderLock lock(dir);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OutFolderLock, OneHolderAtATimeAndReleasedByDestruction) {
  const testing::ScopedTempDir dir_tmp("out_lock");
  const std::string dir = dir_tmp.path() + "/a/b";  // parents created
  std::optional<OutFolderLock> first(std::in_place, dir);
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  const std::string e = MessageOfLock(dir);
  EXPECT_NE(e.find("--out " + dir + ": another exotwin run (pid " + std::to_string(getpid()) + ")"),
            std::string::npos) << e;
  first.reset();
  EXPECT_EQ(MessageOfLock(dir), "");
}

TEST(OutFolderLock, ReleasedWhenTheHolderIsKilled) {
  const testing::ScopedTempDir dir_tmp("out_lock_killed");
  const std::string dir = dir_tmp.path();
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    OutFolderLock lock(dir);
    const char c = 1;
    if (write(ready[1], &c, 1) != 1) _exit(1);
    pause();
    _exit(0);
  }
  char c = 0;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  EXPECT_NE(MessageOfLock(dir).find("(pid " + std::to_string(child) + ")"), std::string::npos);
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  EXPECT_EQ(MessageOfLock(dir), "");
  close(ready[0]);
  close(ready[1]);
}

TEST(OutFolderLock, AFileIsNotAFolder) {
  const testing::ScopedTempDir file_tmp("out_lock_file");
  const std::string file = file_tmp.path() + "/f";
  std::ofstream(file) << "x";
  const std::string e = MessageOfLock(file);
  EXPECT_NE(e.find("--out " + file + ": exists and is not a folder"), std::string::npos) << e;
}

}  // namespace
}  // namespace exotwin
