#include "core/file_text.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "core/error.h"

namespace exotwin {

namespace {

std::string Hex(unsigned char c) {
  static const char* d = "0123456789ABCDEF";
  return std::string("0x") + d[c >> 4] + d[c & 15];
}

// Byte classes: what a byte may start (outside a sequence).
enum : unsigned char { kText, kNewline, kControl, kCont, kLead2, kLead3, kLead4, kBad };

struct ByteClasses {
  unsigned char c[256];
  constexpr ByteClasses() : c() {
    for (int b = 0; b < 256; ++b)
      c[b] = b == '\n'                          ? kNewline
             : b == '\t' || b == '\r'          ? kText
             : b < 0x20 || b == 0x7F            ? kControl
             : b < 0x80                         ? kText
             : b < 0xC0                         ? kCont
             : b < 0xC2                         ? kBad  // C0, C1: overlong 2-byte forms
             : b < 0xE0                         ? kLead2
             : b < 0xF0                         ? kLead3
             : b < 0xF5                         ? kLead4
                                                : kBad;
  }
};
constexpr ByteClasses kClass;

}  // namespace

std::string TextFault::Where() const {
  return what + " at line " + std::to_string(line) + ", byte " + std::to_string(byte);
}

bool TextCheck::Fail(size_t line, size_t byte, std::string what) {
  fault_ = TextFault{line, byte, std::move(what)};
  return false;
}

bool TextCheck::Feed(const char* p, size_t n) {
  if (fault_) return false;
  if (const void* z = std::memchr(p, '\0', n)) {  // binary data: said so, before the piece's other faults
    const auto k = static_cast<size_t>(static_cast<const char*>(z) - p);
    const void* nl = memrchr(p, '\n', k);
    return Fail(line_ + static_cast<size_t>(std::count(p, p + k, '\n')),
                nl ? static_cast<size_t>(static_cast<const char*>(z) - static_cast<const char*>(nl))
                   : offset_ + k - line_start_ + 1,
                "binary data (NUL byte)");
  }
  const auto* u = reinterpret_cast<const unsigned char*>(p);
  constexpr uint64_t k01 = 0x0101010101010101ULL, k80 = 0x8080808080808080ULL;
  for (size_t i = 0; i < n; ++i) {
    if (need_ == 0 && i + 8 <= n) {  // eight printable ASCII bytes at once (no line break among them)
      uint64_t w;
      std::memcpy(&w, u + i, 8);
      const uint64_t below_space = (w - k01 * 0x20) & ~w & k80;  // some byte < 0x20 (exact without high bits)
      const uint64_t x = w ^ (k01 * 0x7F);
      const uint64_t del = (x - k01) & ~x & k80;  // some byte 0x7F
      if (((w & k80) | below_space | del) == 0) {
        i += 7;
        continue;
      }
    }
    const unsigned char b = u[i];
    if (need_ > 0) {
      if (b < lo_ || b > hi_)
        return Fail(seq_line_, seq_byte_, "invalid UTF-8 (byte " + Hex(lead_) + " followed by " + Hex(b) + ")");
      if (lead_ == 0xC2 && b <= 0x9F)
        return Fail(seq_line_, seq_byte_, "control character U+00" + Hex(b).substr(2) + " (C1)");
      lo_ = 0x80;
      hi_ = 0xBF;
      --need_;
      continue;
    }
    switch (kClass.c[b]) {
      case kText:
        continue;
      case kNewline:
        ++line_;
        line_start_ = offset_ + i + 1;
        continue;
      case kControl:
        return Fail(line_, offset_ + i - line_start_ + 1,
                    b == 0 ? std::string("binary data (NUL byte)") : "control character " + Hex(b));
      case kCont:
      case kBad:
        return Fail(line_, offset_ + i - line_start_ + 1, "invalid UTF-8 (byte " + Hex(b) + ")");
      default:
        break;
    }
    lead_ = b;
    seq_line_ = line_;
    seq_byte_ = offset_ + i - line_start_ + 1;
    lo_ = 0x80;
    hi_ = 0xBF;
    if (kClass.c[b] == kLead2) {
      need_ = 1;
    } else if (kClass.c[b] == kLead3) {
      need_ = 2;
      if (b == 0xE0) lo_ = 0xA0;  // overlong
      if (b == 0xED) hi_ = 0x9F;  // surrogates U+D800..U+DFFF
    } else {
      need_ = 3;
      if (b == 0xF0) lo_ = 0x90;  // overlong
      if (b == 0xF4) hi_ = 0x8F;  // above U+10FFFF
    }
  }
  offset_ += n;
  return true;
}

bool TextCheck::End() {
  if (fault_) return false;
  if (need_ > 0) return Fail(seq_line_, seq_byte_, "invalid UTF-8 (sequence " + Hex(lead_) + " cut by the end of the text)");
  return true;
}

std::optional<TextFault> FindTextFault(std::string_view text) {
  TextCheck c;
  if (c.Feed(text.data(), text.size()) && c.End()) return std::nullopt;
  return c.fault();
}

void CheckText(std::string_view text, const std::string& source, const std::string& expected) {
  if (const auto f = FindTextFault(text)) throw InputError(source + ": " + f->Where() + ", expected " + expected);
}

void CheckCommandLine(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view a(argv[i]);
    if (const auto f = FindTextFault(a)) {
      // The byte counted in the whole argument (a value may hold newlines).
      size_t start = 0;
      for (size_t line = 1; line < f->line; ++line) start = a.find('\n', start) + 1;
      const size_t byte = start + f->byte;
      throw InputError("command line: argument " + std::to_string(i) + ": " + f->what + " at byte " +
                       std::to_string(byte) + ", expected UTF-8 text");
    }
  }
}

TextFileChunks::TextFileChunks(const std::string& path, const std::string& what, const std::string& expected)
    : path_(path), role_(what.empty() ? "file" : what + " file"), expected_(expected) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) Fail(std::strerror(errno));
  if (S_ISDIR(st.st_mode)) Fail("is a directory");
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) Fail(std::strerror(errno));
  if (S_ISREG(st.st_mode)) size_ = static_cast<size_t>(st.st_size);
}

TextFileChunks TextFileChunks::Binary(const std::string& path, const std::string& what) {
  TextFileChunks f(path, what, "");
  f.text_ = false;
  return f;
}

TextFileChunks::TextFileChunks(TextFileChunks&& o) noexcept
    : path_(std::move(o.path_)), role_(std::move(o.role_)), expected_(std::move(o.expected_)),
      check_(o.check_), fd_(std::exchange(o.fd_, -1)), size_(o.size_), text_(o.text_) {}

TextFileChunks::~TextFileChunks() {
  if (fd_ >= 0) ::close(fd_);
}

void TextFileChunks::Fail(const std::string& reason) const {
  throw InputError(path_ + ": cannot open " + role_ + " (" + reason + ")");
}

void TextFileChunks::FailText() const {
  throw InputError(path_ + ": " + check_.fault()->Where() + ", expected " + expected_);
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
  if (text_ && (!check_.Feed(buf, got) || (got < n && !check_.End()))) FailText();
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

namespace {

std::string ReadWhole(TextFileChunks& in) {
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

}  // namespace

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

std::string ShownText(std::string_view s) {
  if (!FindTextFault(s)) return std::string(s);
  return "<" + std::to_string(s.size()) + " bytes, not text>";
}

std::string ReadTextFile(const std::string& path, const std::string& what, const std::string& expected) {
  TextFileChunks in(path, what, expected);
  return ReadWhole(in);
}

std::string ReadBinaryFile(const std::string& path, const std::string& what) {
  TextFileChunks in = TextFileChunks::Binary(path, what);
  return ReadWhole(in);
}

}  // namespace exotwin
