#include "runner/out_folder_lock.h"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include "core/error.h"
#include "core/output_path.h"

namespace exotwin {

OutFolderLock::OutFolderLock(const std::string& dir) {
  try {
    CreateOutputFolder(dir);
  } catch (const InputError& e) {
    throw InputError(std::string("--out ") + e.what());
  }
  const std::string path = dir + "/" + kOutFolderLockName;
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw InputError("--out " + dir + ": cannot create " + path + " (" + std::strerror(errno) + ")");
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    char pid[32] = {0};
    const ssize_t n = ::pread(fd_, pid, sizeof(pid) - 1, 0);
    ::close(fd_);
    fd_ = -1;
    if (err != EWOULDBLOCK)
      throw InputError("--out " + dir + ": cannot lock " + path + " (" + std::strerror(err) + ")");
    std::string holder = n > 0 ? std::string(pid, static_cast<size_t>(n)) : std::string("?");
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
    throw InputError("--out " + dir + ": another exotwin run (pid " + holder + ") is writing to this folder, "
                     "expected a folder no running exotwin uses (wait for it to end, or choose another --out)");
  }
  // The holder's pid, for the message of a second run; the lock holds without it.
  const std::string me = std::to_string(::getpid()) + "\n";
  const bool recorded = ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, me.data(), me.size(), 0) == static_cast<ssize_t>(me.size());
  (void)recorded;
}

OutFolderLock::~OutFolderLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

}  // namespace exotwin
