#include "core/file_text.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace exotwin {

std::string ReadTextFile(const std::string& path, const std::string& what, const std::string& expected) {
  const std::string role = what.empty() ? "file" : what + " file";
  auto fail = [&](const std::string& reason) {
    throw InputError(path + ": cannot open " + role + " (" + reason + ")");
  };
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) fail(std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail("is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail("read error");
  std::string text = ss.str();
  if (text.find('\0') != std::string::npos) throw InputError(path + ": binary data (NUL byte), expected " + expected);
  return text;
}

}  // namespace exotwin
