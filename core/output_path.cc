#include "core/output_path.h"

#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace exotwin {

void CreateOutputFolder(const std::string& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) return;  // the current folder
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  if (fs::exists(dir, ec))
    throw InputError(dir + ": exists and is not a folder, expected an output folder (created when missing)");
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the output folder (" + ec.message() + ")");
}

void CreateParentFolders(const std::string& path) {
  const std::string parent = std::filesystem::path(path).parent_path().string();
  if (!parent.empty()) CreateOutputFolder(parent);
}

}  // namespace exotwin
