// The output folder of `exotwin run` / `render`, held by one process at a time.
#pragma once
#include <string>

namespace exotwin {

// Name of the lock file inside a held output folder.
inline constexpr const char* kOutFolderLockName = ".exotwin.lock";

// Creates `dir` (and its parents) when missing and holds an exclusive flock(2) on dir/.exotwin.lock
// (which records the holder's pid) for the object's lifetime. The kernel releases the lock when the
// process ends however it ends (a crash or SIGKILL included), so a lock left by a killed run never
// blocks. Throws InputError naming `dir` when it exists but is not a folder, cannot be created, or
// is held by another process.
class OutFolderLock {
 public:
  explicit OutFolderLock(const std::string& dir);
  ~OutFolderLock();
  OutFolderLock(const OutFolderLock&) = delete;
  OutFolderLock& operator=(const OutFolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace exotwin
