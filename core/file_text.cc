#include "core/file_text.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "core/error.h"

namespace exotwin {

TextFileChunks::TextFileChunks(const std::string& path, const std::string& what, const std::string& expected)
    : path_(path), role_(what.empty() ? "file" : what + " file"), expected_(expected) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) Fail(std::strerror(errno));
  if (S_ISDIR(st.st_mode)) Fail("is a directory");
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) Fail(std::strerror(errno));
  if (S_ISREG(st.st_mode)) size_ = static_cast<size_t>(st.st_size);
}

TextFileChunks::~TextFileChunks() {
  if (fd_ >= 0) ::close(fd_);
}

void TextFileChunks::Fail(const std::string& reason) const {
  throw InputError(path_ + ": cannot open " + role_ + " (" + reason + ")");
}

size_t TextFileChunks::Read(char* buf, size_t n) {
  size_t got = 0;
  while (got < n) {
    const ssize_t r = ::read(fd_, buf + got, n - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) Fail("read error");
    if (r == 0) break;
    got += static_cast<size_t>(r);
  }
  if (std::memchr(buf, '\0', got))
    throw InputError(path_ + ": binary data (NUL byte), expected " + expected_);
  return got;
}

size_t TextFileChunks::DrainCountingNewlines(bool* ends_with_newline) {
  std::vector<char> buf(1 << 20);
  size_t newlines = 0;
  for (size_t got; (got = Read(buf.data(), buf.size())) > 0;) {
    newlines += static_cast<size_t>(std::count(buf.data(), buf.data() + got, '\n'));
    *ends_with_newline = buf[got - 1] == '\n';
  }
  return newlines;
}

std::string ReadTextFile(const std::string& path, const std::string& what, const std::string& expected) {
  TextFileChunks in(path, what, expected);
  std::string text;
  // One read of a regular file's size (no stream buffer copies); a pipe or a growing file in chunks.
  size_t chunk = std::max<size_t>(in.size() + 1, 1 << 16);
  for (size_t got = 0;;) {
    text.resize(got + chunk);
    const size_t r = in.Read(text.data() + got, chunk);
    got += r;
    if (r < chunk) {
      text.resize(got);
      return text;
    }
    chunk = std::max<size_t>(chunk, 1 << 20);
  }
}

}  // namespace exotwin
