#include "core/data_dir.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace exotwin {

namespace fs = std::filesystem;

std::string ExecutablePath() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.string();
}

std::string DataDir() {
  const char* env = std::getenv("EXOTWIN_DATA_DIR");
  std::string dir, source;
  if (env && *env) {
    dir = env;
    while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
    source = "the environment variable EXOTWIN_DATA_DIR";
  } else {
    const fs::path exe = ExecutablePath();
    if (exe.empty())
      throw InputError("exotwin data folder: cannot read /proc/self/exe to find <bin>/../share/exotwin; set EXOTWIN_DATA_DIR to the folder holding mjcf/, "
                       "data/, scenarios/");
    dir = (exe.parent_path().parent_path() / "share" / "exotwin").string();
    source = "the executable " + exe.string() + " (<bin>/../share/exotwin)";
  }
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError("exotwin data folder not found: looked for " + dir + " (from " + source +
                     "); install exotwin (cmake --install) or set EXOTWIN_DATA_DIR to the folder holding "
                     "mjcf/, data/, scenarios/");
  return dir;
}

std::string DataPath(const std::string& rel) { return DataDir() + "/" + rel; }

}  // namespace exotwin
