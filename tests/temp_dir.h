// The one temporary-folder helper of the tests, benchmarks and fuzz targets: an RAII folder, so that
// they leave nothing behind in the temp directory.
//
// ScopedTempDir: a fresh, empty folder <temp>/exotwin_<tag>_XXXXXX (<temp> as
// std::filesystem::temp_directory_path(): TMPDIR or /tmp), removed with everything in it by the
// destructor of the object that made it. A test owns one as a local, a fixture member, or (for a
// folder shared by a whole suite) a function-local static, removed at normal process exit. No
// fallback: when the folder cannot be made the process aborts (no test could do anything sensible).
// A forked child that exits normally never removes its parent's folder. EXOTWIN_KEEP_TMP=1 keeps the
// folders for inspection.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include <unistd.h>

namespace exotwin::testing {

class ScopedTempDir {
 public:
  // tag: letters, digits and '_' (part of the folder's name).
  explicit ScopedTempDir(const std::string& tag) {
    std::string tmpl = (std::filesystem::temp_directory_path() / ("exotwin_" + tag + "_XXXXXX")).string();
    if (!mkdtemp(tmpl.data())) {
      std::perror(("ScopedTempDir: mkdtemp " + tmpl).c_str());
      std::abort();
    }
    path_ = std::move(tmpl);
  }
  ~ScopedTempDir() {
    if (path_.empty() || getpid() != owner_ || std::getenv("EXOTWIN_KEEP_TMP")) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScopedTempDir(ScopedTempDir&& o) noexcept : path_(std::exchange(o.path_, {})), owner_(o.owner_) {}
  ScopedTempDir& operator=(ScopedTempDir&&) = delete;
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  // The folder's absolute path, without a trailing '/'.
  const std::string& path() const { return path_; }
  // path() + "/" + name.
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
  pid_t owner_ = getpid();
};

}  // namespace exotwin::testing
