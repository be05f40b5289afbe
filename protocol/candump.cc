#include "protocol/candump.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "core/error.h"
#include "core/output_path.h"

namespace exotwin {
namespace {

constexpr uint32_t kErrorFrameId = 0x20000080u;  // CAN_ERR_FLAG | CAN_ERR_PROT

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

namespace {

// Room for a line: time stamp "(-9223372036854.775808) ", the interface and " 20000080#" + 16 hex digits.
size_t LineCapacity(const std::string& interface) { return interface.size() + 72; }

// Writes the line of f followed by '\n' into out (LineCapacity(interface) chars); returns its
// length. No allocation: the writer calls it for every frame of a run.
size_t FormatLine(const CanFrame& f, const std::string& interface, int64_t epoch_s, char* out) {
  static const char* kHex = "0123456789ABCDEF";
  const int64_t us = epoch_s * 1000000 + std::llround(f.t * 1e6);
  const int64_t sec = us >= 0 ? us / 1000000 : -((-us + 999999) / 1000000);
  const int64_t frac = us - sec * 1000000;
  const size_t cap = LineCapacity(interface);
  size_t n = static_cast<size_t>(std::snprintf(out, cap, "(%lld.%06lld) %s ", static_cast<long long>(sec),
                                               static_cast<long long>(frac), interface.c_str()));
  if (f.error) {
    n += static_cast<size_t>(std::snprintf(out + n, cap - n, "%08X#0000000000000000\n", kErrorFrameId));
    return n;
  }
  n += static_cast<size_t>(std::snprintf(out + n, cap - n, "%03X#", static_cast<unsigned>(f.id & 0x7FF)));
  for (int i = 0; i < f.dlc && i < 8; ++i) {
    out[n++] = kHex[f.data[i] >> 4];
    out[n++] = kHex[f.data[i] & 0xF];
  }
  out[n++] = '\n';
  return n;
}

}  // namespace

std::string FormatCandumpLine(const CanFrame& f, const std::string& interface, int64_t epoch_s) {
  std::string line(LineCapacity(interface), '\0');
  line.resize(FormatLine(f, interface, epoch_s, line.data()) - 1);  // without the newline
  return line;
}

CandumpWriter::CandumpWriter(const std::string& path, std::string interface, int64_t epoch_s)
    : path_(path), interface_(std::move(interface)), epoch_s_(epoch_s), line_(LineCapacity(interface_), '\0') {
  CreateParentFolders(path);
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) throw InputError(path + ": cannot create CAN log: " + std::strerror(errno));
}

CandumpWriter::~CandumpWriter() {
  if (file_) std::fclose(file_);
}

void CandumpWriter::Write(const CanFrame& f) {
  const size_t n = FormatLine(f, interface_, epoch_s_, line_.data());
  if (std::fwrite(line_.data(), 1, n, file_) != n || std::fflush(file_) != 0)
    throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  ++lines_;
}

CandumpReader::CandumpReader(const std::string& path, int64_t epoch_s)
    : path_(path), in_(path), epoch_s_(epoch_s) {
  if (!in_) throw InputError(path + ": cannot open candump log");
}

bool CandumpReader::Next(CandumpRecord* out) {
  std::string line;
  while (std::getline(in_, line)) {
    ++line_;
    if (!text_.Feed(line.data(), line.size()) || (!in_.eof() && !text_.Feed("\n", 1)) || (in_.eof() && !text_.End()))
      throw InputError(path_ + ": " + text_.fault()->Where() + ", expected a candump log");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const std::string where = path_ + ":" + std::to_string(line_) + ": ";
    auto fail = [&](const std::string& what) {
      throw InputError(where + what + " (expected '(sec.usec) can0 ID#DATA', got '" + line + "')");
    };
    // (sec.usec)
    size_t p = line.find_first_not_of(" \t");
    if (line[p] != '(') fail("missing '(' time stamp");
    const size_t close = line.find(')', p);
    if (close == std::string::npos) fail("missing ')' after the time stamp");
    const std::string stamp = line.substr(p + 1, close - p - 1);
    const size_t dot = stamp.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == stamp.size()) fail("time stamp is not sec.usec");
    int64_t sec = 0, frac = 0;
    for (size_t i = 0; i < dot; ++i) {
      if (!std::isdigit(static_cast<unsigned char>(stamp[i]))) fail("time stamp is not sec.usec");
      sec = sec * 10 + (stamp[i] - '0');
      if (sec > 1000000000000LL) fail("time stamp out of range");
    }
    double denom = 1;
    for (size_t i = dot + 1; i < stamp.size(); ++i) {
      if (!std::isdigit(static_cast<unsigned char>(stamp[i]))) fail("time stamp is not sec.usec");
      if (i - dot > 9) fail("time stamp has more than 9 decimals");
      frac = frac * 10 + (stamp[i] - '0');
      denom *= 10;
    }
    // interface
    size_t q = line.find_first_not_of(" \t", close + 1);
    if (q == std::string::npos) fail("missing interface");
    size_t r = line.find_first_of(" \t", q);
    if (r == std::string::npos) fail("missing ID#DATA");
    CandumpRecord rec;
    rec.interface = line.substr(q, r - q);
    size_t s = line.find_first_not_of(" \t", r);
    if (s == std::string::npos) fail("missing ID#DATA");
    std::string frame = line.substr(s);
    const size_t tail = frame.find_first_of(" \t");  // candump may append flags after a space
    if (tail != std::string::npos) frame = frame.substr(0, tail);
    const size_t hash = frame.find('#');
    if (hash == std::string::npos) fail("missing '#' between ID and data");
    const std::string id_text = frame.substr(0, hash);
    std::string data_text = frame.substr(hash + 1);
    if (!data_text.empty() && data_text[0] == '#') fail("CAN FD frames are not supported");
    if (!data_text.empty() && (data_text[0] == 'R' || data_text[0] == 'r')) fail("remote frames are not supported");
    if (id_text.empty() || (id_text.size() != 3 && id_text.size() != 8)) fail("ID must have 3 (standard) or 8 hex digits");
    uint32_t id = 0;
    for (char c : id_text) {
      const int d = HexDigit(c);
      if (d < 0) fail("ID is not hexadecimal");
      id = id * 16 + static_cast<uint32_t>(d);
    }
    CanFrame& f = rec.frame;
    if (id_text.size() == 8) {
      if ((id & 0x20000000u) == 0) fail("extended (29-bit) IDs are not supported");
      f.error = true;
    } else {
      if (id > 0x7FF) fail("standard ID above 0x7FF");
      f.id = static_cast<uint16_t>(id);
    }
    std::string hex;
    for (char c : data_text)
      if (c != '.') hex += c;  // candump -l never writes separators, cansend accepts '.'
    if (hex.size() % 2 != 0) fail("odd number of data hex digits");
    if (hex.size() > 16) fail("more than 8 data bytes");
    for (size_t i = 0; i < hex.size(); i += 2) {
      const int hi = HexDigit(hex[i]), lo = HexDigit(hex[i + 1]);
      if (hi < 0 || lo < 0) fail("data is not hexadecimal");
      if (!f.error) f.data[i / 2] = static_cast<uint8_t>(hi * 16 + lo);
    }
    f.dlc = f.error ? 0 : static_cast<uint8_t>(hex.size() / 2);
    f.t = static_cast<double>(sec - epoch_s_) + static_cast<double>(frac) / denom;
    *out = rec;
    return true;
  }
  return false;
}

std::vector<CandumpRecord> CandumpReader::ReadAll(const std::string& path, int64_t epoch_s) {
  CandumpReader reader(path, epoch_s);
  std::vector<CandumpRecord> out;
  CandumpRecord rec;
  while (reader.Next(&rec)) out.push_back(rec);
  return out;
}

}  // namespace exotwin
