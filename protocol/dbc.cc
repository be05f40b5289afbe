#include "protocol/dbc.h"

#include <cmath>
#include <cstdlib>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "core/file_text.h"

namespace exotwin {
namespace {

// Frame bit positions of the signal's bits, least significant signal bit first.
std::vector<int> BitPositions(const DbcSignal& s) {
  std::vector<int> pos(s.length);
  if (s.little_endian) {
    for (int i = 0; i < s.length; ++i) pos[i] = s.start_bit + i;
  } else {  // Motorola: start bit is the MSB; walk down within a byte, then to the next byte's bit 7
    int p = s.start_bit;
    for (int i = s.length - 1; i >= 0; --i) {
      pos[i] = p;
      p = (p % 8 == 0) ? p + 15 : p - 1;
    }
  }
  return pos;
}

[[noreturn]] void Fail(const std::string& source, int line, const std::string& what) {
  throw InputError(source + ":" + std::to_string(line) + ": " + what);
}

double Number(const std::string& text, const std::string& source, int line, const char* field) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    Fail(source, line, std::string("expected a number for ") + field + ", got '" + text + "'");
  return v;
}

int Quotes(const std::string& s) {
  int n = 0;
  for (size_t i = 0; i < s.size(); ++i)
    if (s[i] == '"' && (i == 0 || s[i - 1] != '\\')) ++n;
  return n;
}

std::vector<std::string> SplitReceivers(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (c == ',' || c == ' ' || c == '\t' || c == '\r') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

}  // namespace

int64_t DbcSignal::RawValue(const CanFrame& f) const {
  const std::vector<int> pos = BitPositions(*this);
  uint64_t raw = 0;
  for (int i = 0; i < length; ++i) {
    const int p = pos[i];
    if (p < 0 || p >= 64) continue;
    if ((f.data[p / 8] >> (p % 8)) & 1) raw |= uint64_t{1} << i;
  }
  if (is_signed && length < 64 && ((raw >> (length - 1)) & 1)) raw |= ~uint64_t{0} << length;
  return static_cast<int64_t>(raw);
}

double DbcSignal::Decode(const CanFrame& f) const {
  if (!is_signed && length == 64) return static_cast<double>(static_cast<uint64_t>(RawValue(f))) * factor + offset;
  return static_cast<double>(RawValue(f)) * factor + offset;
}

void DbcSignal::Encode(double phys, CanFrame* f) const {
  const uint64_t raw = static_cast<uint64_t>(static_cast<int64_t>(std::llround((phys - offset) / factor)));
  const std::vector<int> pos = BitPositions(*this);
  for (int i = 0; i < length; ++i) {
    const int p = pos[i];
    if (p < 0 || p >= 64) continue;
    const uint8_t mask = static_cast<uint8_t>(1u << (p % 8));
    if ((raw >> i) & 1) f->data[p / 8] |= mask;
    else f->data[p / 8] &= static_cast<uint8_t>(~mask);
  }
}

const DbcSignal* DbcMessage::Find(const std::string& signal) const {
  for (const DbcSignal& s : signals)
    if (s.name == signal) return &s;
  return nullptr;
}

const DbcMessage* DbcDatabase::FindById(uint32_t id) const {
  for (const DbcMessage& m : messages)
    if (m.id == id) return &m;
  return nullptr;
}

const DbcMessage* DbcDatabase::FindByName(const std::string& name) const {
  for (const DbcMessage& m : messages)
    if (m.name == name) return &m;
  return nullptr;
}

DbcDatabase ParseDbc(std::istream& in, const std::string& source) {
  static const std::regex kBo(R"re(^BO_\s+(\S+)\s+(\w+)\s*:\s*(\S+)\s+(\w+)\s*$)re");
  static const std::regex kSg(
      R"re(^\s*SG_\s+(\w+)\s*(M|m\d+M?)?\s*:\s*(\d+)\|(\d+)@([01])([+-])\s*\(\s*([^,\s]+)\s*,\s*([^)\s]+)\s*\)\s*)re"
      R"re(\[\s*([^|\s]+)\s*\|\s*([^\]\s]+)\s*\]\s*"([^"]*)"\s*(.*)$)re");
  DbcDatabase db;
  std::string line;
  int lineno = 0;
  bool in_string = false;  // inside a quoted string spanning lines (CM_ comments)
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool was_in_string = in_string;
    if (Quotes(line) % 2 == 1) in_string = !in_string;
    if (was_in_string) continue;
    size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    const std::string body = line.substr(first);
    const std::string keyword = body.substr(0, body.find_first_of(" \t:"));
    std::smatch m;
    if (keyword == "BO_") {
      if (!std::regex_match(body, m, kBo))
        Fail(source, lineno, "expected 'BO_ <id> <name>: <dlc> <sender>', got '" + line + "'");
      DbcMessage msg;
      const double id = Number(m[1], source, lineno, "message id");
      if (id < 0 || id > 0x7FF || id != std::floor(id))
        Fail(source, lineno, "expected an 11-bit message id 0..2047 (classic CAN 2.0A), got " + m[1].str());
      msg.id = static_cast<uint32_t>(id);
      msg.name = m[2];
      const double dlc = Number(m[3], source, lineno, "message length");
      if (dlc < 0 || dlc > 8 || dlc != std::floor(dlc))
        Fail(source, lineno, "expected a message length 0..8 bytes, got " + m[3].str());
      msg.dlc = static_cast<int>(dlc);
      msg.sender = m[4];
      if (db.FindById(msg.id)) Fail(source, lineno, "duplicate message id " + m[1].str());
      db.messages.push_back(msg);
    } else if (keyword == "SG_") {
      if (db.messages.empty()) Fail(source, lineno, "SG_ line before any BO_ message");
      if (!std::regex_match(line, m, kSg))
        Fail(source, lineno,
             "expected 'SG_ <name> : <start>|<length>@<0|1><+|-> (<factor>,<offset>) [<min>|<max>] \"<unit>\" "
             "<receivers>', got '" + line + "'");
      DbcSignal s;
      s.name = m[1];
      s.start_bit = std::atoi(m[3].str().c_str());
      s.length = std::atoi(m[4].str().c_str());
      s.little_endian = m[5] == "1";
      s.is_signed = m[6] == "-";
      s.factor = Number(m[7], source, lineno, "factor");
      s.offset = Number(m[8], source, lineno, "offset");
      s.minimum = Number(m[9], source, lineno, "minimum");
      s.maximum = Number(m[10], source, lineno, "maximum");
      s.unit = m[11];
      s.receivers = SplitReceivers(m[12]);
      DbcMessage& msg = db.messages.back();
      if (s.length < 1 || s.length > 64) Fail(source, lineno, "signal " + s.name + ": expected a length 1..64 bits");
      if (s.factor == 0) Fail(source, lineno, "signal " + s.name + ": factor must not be 0");
      for (int p : BitPositions(s))
        if (p < 0 || p >= 8 * msg.dlc)
          Fail(source, lineno, "signal " + s.name + ": bits outside the " + std::to_string(msg.dlc) +
                                   "-byte payload of " + msg.name);
      if (msg.Find(s.name)) Fail(source, lineno, "duplicate signal " + s.name + " in " + msg.name);
      msg.signals.push_back(s);
    }
  }
  if (in_string) Fail(source, lineno, "unterminated quoted string at end of file");
  return db;
}

DbcDatabase LoadDbc(const std::string& path) {
  std::istringstream in(ReadTextFile(path, "DBC", "a text DBC file"));
  return ParseDbc(in, path);
}

}  // namespace exotwin
