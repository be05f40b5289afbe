#include "analysis/csv_table.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/file_text.h"

namespace exotwin {

int CsvTable::Find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {

std::string Trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

std::string Where(const std::string& path, int line) { return path + ":" + std::to_string(line) + ": "; }

}  // namespace

CsvTable ReadCsv(const std::string& path) {
  std::string content = ReadTextFile(path, "", "a text CSV file");
  if (content.empty()) throw InputError(path + ": file is empty, expected a CSV header row");

  CsvTable t;
  if (content.rfind(kStreamMarker, 0) == 0 && content.back() != '\n') {
    const size_t cut = content.rfind('\n') + 1;  // npos + 1 == 0: the marker line itself was cut
    t.dropped_cut_line = static_cast<int>(std::count(content.begin(), content.begin() + cut, '\n')) + 1;
    std::fprintf(stderr, "warning: %s:%d: last line has no newline in a streamed exotwin log: dropped "
                 "(the run was killed while writing it)\n", path.c_str(), t.dropped_cut_line);
    content.resize(cut);
  }
  bool have_header = false;
  size_t pos = 0;
  int line_no = 0;
  std::vector<double> row;
  while (pos < content.size()) {
    size_t end = content.find('\n', pos);
    if (end == std::string::npos) end = content.size();
    const std::string line = content.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    if (!have_header) {
      std::stringstream ss(trimmed);
      std::string name;
      std::set<std::string> seen;
      while (std::getline(ss, name, ',')) {
        name = Trim(name);
        if (name.empty())
          throw InputError(Where(path, line_no) + "empty column name in the header row");
        if (!seen.insert(name).second)
          throw InputError(Where(path, line_no) + "duplicated column '" + name + "' in the header");
        t.names.push_back(name);
      }
      if (trimmed.back() == ',') throw InputError(Where(path, line_no) + "header ends with ','");
      t.columns.assign(t.names.size(), {});
      have_header = true;
      continue;
    }
    row.clear();
    const char* p = trimmed.c_str();
    const char* const stop = p + trimmed.size();
    size_t field = 0;
    while (true) {
      while (p < stop && (*p == ' ' || *p == '\t')) ++p;
      char* q = nullptr;
      errno = 0;
      const double v = std::strtod(p, &q);
      const char* after = q;
      while (after < stop && (*after == ' ' || *after == '\t')) ++after;
      if (q == p || (after < stop && *after != ',')) {
        const char* fe = p;
        while (fe < stop && *fe != ',') ++fe;
        const std::string col = field < t.names.size() ? t.names[field] : "#" + std::to_string(field + 1);
        throw InputError(Where(path, line_no) + "column '" + col + "': '" + std::string(p, fe) +
                         "' is not a number");
      }
      row.push_back(v);
      ++field;
      p = after;
      if (p >= stop) break;
      ++p;  // skip ','
      if (p >= stop) throw InputError(Where(path, line_no) + "row ends with ','");
    }
    if (row.size() != t.names.size())
      throw InputError(Where(path, line_no) + "expected " + std::to_string(t.names.size()) +
                       " fields (as in the header), found " + std::to_string(row.size()));
    for (size_t i = 0; i < row.size(); ++i) t.columns[i].push_back(row[i]);
    t.line_of_row.push_back(line_no);
  }
  if (!have_header) throw InputError(path + ": no header row (only comments or blank lines)");
  return t;
}

void WriteFileAtomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
    out << text;
    out.flush();
    if (!out) throw InputError(path + ": write failed (" + std::strerror(errno) + ")");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw InputError(path + ": cannot rename temporary file (" + std::strerror(errno) + ")");
}

void WriteCsv(const std::string& path, const std::vector<std::string>& names,
              const std::vector<const std::vector<double>*>& columns,
              const std::vector<std::string>& comments) {
  std::string out;
  for (const auto& c : comments) out += "# " + c + "\n";
  for (size_t i = 0; i < names.size(); ++i) out += (i ? "," : "") + names[i];
  out += "\n";
  const size_t n = columns.empty() ? 0 : columns[0]->size();
  out.reserve(out.size() + n * columns.size() * 24);
  char buf[32];
  for (size_t r = 0; r < n; ++r) {
    for (size_t c = 0; c < columns.size(); ++c) {
      const int len = std::snprintf(buf, sizeof(buf), "%.17g", (*columns[c])[r]);
      if (c) out += ',';
      out.append(buf, len);
    }
    out += '\n';
  }
  WriteFileAtomic(path, out);
}

}  // namespace exotwin

#include <fcntl.h>
#include <unistd.h>

namespace exotwin {

CsvStreamWriter::CsvStreamWriter(const std::string& path, const std::vector<std::string>& names,
                                 const std::vector<std::string>& comments, size_t flush_rows)
    : path_(path), columns_(names.size()), flush_rows_(flush_rows ? flush_rows : 1) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd_ < 0) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  buffer_ += std::string(kStreamMarker) + "\n";
  for (const auto& c : comments) buffer_ += "# " + c + "\n";
  for (size_t i = 0; i < names.size(); ++i) buffer_ += (i ? "," : "") + names[i];
  buffer_ += "\n";
  Flush();
}

CsvStreamWriter::~CsvStreamWriter() {
  Flush();
  if (fd_ >= 0) ::close(fd_);
}

void CsvStreamWriter::Row(const double* values, size_t n) {
  char buf[32];
  for (size_t c = 0; c < columns_; ++c) {
    // Shortest text that reads back to the same double (std::to_chars, no locale, no printf cost).
    const auto res = std::to_chars(buf, buf + sizeof(buf), c < n ? values[c] : 0.0);
    if (c) buffer_ += ',';
    buffer_.append(buf, res.ptr);
  }
  buffer_ += '\n';
  ++rows_;
  if (++pending_ >= flush_rows_) Flush();
}

void CsvStreamWriter::Flush() {
  size_t off = 0;
  while (off < buffer_.size() && fd_ >= 0) {
    const ssize_t w = ::write(fd_, buffer_.data() + off, buffer_.size() - off);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw InputError(path_ + ": write failed (" + std::strerror(errno) + ")");
    }
    off += static_cast<size_t>(w);
  }
  buffer_.clear();
  pending_ = 0;
}

}  // namespace exotwin
