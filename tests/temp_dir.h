// Temporary folders of a test process: created fresh, removed with everything in them when the
// process that made them exits normally, so that tests leave nothing behind in the temp directory.
// EXOTWIN_KEEP_TMP=1 keeps them for inspection.
#pragma once
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <unistd.h>

namespace exotwin::testing {

namespace detail {
// Folders made by this process; removed at exit by the process that made them (a forked child that
// exits normally must not remove its parent's folders).
struct TempRegistry {
  std::mutex mu;
  std::vector<std::string> dirs;
  pid_t owner = getpid();
  ~TempRegistry() {
    if (getpid() != owner || std::getenv("EXOTWIN_KEEP_TMP")) return;
    std::error_code ec;
    for (const std::string& d : dirs) std::filesystem::remove_all(d, ec);
  }
};
inline TempRegistry& Registry() {
  static TempRegistry r;
  return r;
}
}  // namespace detail

// A fresh, empty folder <temp>/exotwin_<tag>_XXXXXX, removed when the test process exits.
inline std::string TempDir(const std::string& tag) {
  std::string tmpl = (std::filesystem::temp_directory_path() / ("exotwin_" + tag + "_XXXXXX")).string();
  if (!mkdtemp(tmpl.data())) std::abort();  // no temp folder: nothing a test could do
  detail::TempRegistry& r = detail::Registry();
  std::lock_guard<std::mutex> lock(r.mu);
  r.dirs.push_back(tmpl);
  return tmpl;
}

}  // namespace exotwin::testing
