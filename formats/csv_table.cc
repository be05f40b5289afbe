#include "formats/csv_table.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "formats/number_rows.h"
#include "core/error.h"
#include "core/file_text.h"
#include "core/parallel_for.h"
#include "core/output_path.h"
#include "core/realtime.h"

namespace exotwin {

int CsvTable::Find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

namespace {

bool Blank(char c) { return c == ' ' || c == '\t'; }

}  // namespace

void AppendNumber(std::string* out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  out->append(buf, r.ptr);
}

CsvReader::CsvReader(const std::string& text, std::string source)
    : CsvReader(text.data(), text.data() + text.size(), std::move(source)) {}

CsvReader::CsvReader(const char* begin, const char* end, std::string source)
    : next_(begin), end_(end), source_(std::move(source)) {
  if (end - begin >= 3 && std::memcmp(begin, "\xEF\xBB\xBF", 3) == 0) next_ += 3;  // UTF-8 byte-order mark
}

void CsvReader::Continue(const char* begin, const char* end) {
  next_ = begin;
  end_ = end;
}

void CsvReader::ContinueAfterLine(const char* begin, const char* end, int line_before) {
  Continue(begin, end);
  line_ = line_before;
}

std::string CsvReader::Where() const { return source_ + ":" + std::to_string(line_) + ": "; }

bool CsvReader::NextLine() {
  while (next_ < end_) {
    const char* nl = static_cast<const char*>(std::memchr(next_, '\n', end_ - next_));
    line_begin_ = next_;
    line_end_ = nl ? nl : end_;
    next_ = nl ? nl + 1 : end_;
    ++line_;
    if (line_end_ > line_begin_ && line_end_[-1] == '\r') --line_end_;  // CRLF
    while (line_begin_ < line_end_ && Blank(*line_begin_)) ++line_begin_;
    while (line_end_ > line_begin_ && Blank(line_end_[-1])) --line_end_;
    if (line_begin_ < line_end_ && *line_begin_ != '#') return true;
  }
  return false;
}

void CsvReader::Split() {
  fields_.clear();
  unquoted_.clear();
  // Unquoted text is no longer than the line, plus a NUL per field: the views never move.
  unquoted_.reserve(2 * static_cast<size_t>(line_end_ - line_begin_) + 2);
  const char* s = line_begin_;
  while (true) {
    while (s < line_end_ && Blank(*s)) ++s;
    if (s < line_end_ && *s == '"') {
      const size_t start = unquoted_.size();
      for (++s;; ++s) {
        if (s >= line_end_)
          throw InputError(Where() + "field " + std::to_string(fields_.size() + 1) +
                           ": a quoted field is not closed on its line, expected a closing '\"' (a field "
                           "may not span lines)");
        if (*s != '"') {
          unquoted_ += *s;
        } else if (s + 1 < line_end_ && s[1] == '"') {
          unquoted_ += '"';
          ++s;
        } else {
          ++s;
          break;
        }
      }
      fields_.emplace_back(unquoted_.data() + start, unquoted_.size() - start);
      unquoted_ += '\0';
      while (s < line_end_ && Blank(*s)) ++s;
      if (s < line_end_ && *s != ',')
        throw InputError(Where() + "field " + std::to_string(fields_.size()) +
                         ": text after the closing quote, expected ',' or the end of the line");
    } else {
      const char* b = s;
      while (s < line_end_ && *s != ',') {
        if (*s == '"')
          throw InputError(Where() + "field " + std::to_string(fields_.size() + 1) +
                           ": a '\"' inside an unquoted field, expected the whole field quoted (\"...\") "
                           "with inner quotes doubled");
        ++s;
      }
      const char* e = s;
      while (e > b && Blank(e[-1])) --e;
      fields_.emplace_back(b, static_cast<size_t>(e - b));
    }
    if (s >= line_end_) break;
    ++s;  // ','
  }
}

bool CsvReader::ReadHeader() {
  if (!NextLine()) return false;
  if (std::memchr(line_begin_, '\r', static_cast<size_t>(line_end_ - line_begin_)))
    throw InputError(Where() + "a carriage return inside the header line (old Mac line ends?), expected lines "
                     "ending with LF or CRLF");
  Split();
  if (fields_.size() == 1) {
    const std::string_view h = fields_[0];
    const char* sep = h.find(';') != std::string_view::npos ? "';'" : h.find('\t') != h.npos ? "tabs" : nullptr;
    if (sep)
      throw InputError(Where() + "the header is separated by " + sep +
                       ", expected ',' between fields and '.' as the decimal mark (a spreadsheet in a locale "
                       "with decimal commas writes ';' and '1,5'): export the file again as CSV with ',' "
                       "as the field separator and '.' as the decimal separator");
  }
  trailing_empty_column_ = fields_.size() > 1 && line_end_[-1] == ',';
  if (trailing_empty_column_) fields_.pop_back();
  names_.clear();
  for (std::string_view f : fields_) {
    if (f.empty()) throw InputError(Where() + "empty column name in the header row");
    if (std::find(names_.begin(), names_.end(), f) != names_.end())
      throw InputError(Where() + "duplicated column '" + std::string(f) + "' in the header");
    names_.emplace_back(f);
  }
  return true;
}

void CsvReader::CheckFieldCount(size_t found, bool last_empty) const {
  const size_t n = names_.size();
  if (trailing_empty_column_) {
    if (found == n + 1 && last_empty) return;
    if (found == n + 1)
      throw InputError(Where() + "expected an empty last field (the header ends with ','), found a value");
    throw InputError(Where() + "expected " + std::to_string(n) + " fields and a trailing ',' (as in the header), found " +
                     std::to_string(found) + " fields");
  }
  if (found == n) return;
  if (found == n + 1 && last_empty)
    throw InputError(Where() + "row ends with ',' (an empty last field), expected " + std::to_string(n) +
                     " fields as in the header");
  throw InputError(Where() + "expected " + std::to_string(n) + " fields (as in the header), found " +
                   std::to_string(found));
}

bool CsvReader::NextRow() {
  if (!NextLine()) return false;
  Split();
  CheckFieldCount(fields_.size(), fields_.back().empty());
  return true;
}

namespace {

// Reads a number at the start of [b, e) as strtod does in the "C" locale; returns the end of the
// number (b if there is none). Precondition: the byte at e cannot continue a number. std::from_chars
// (correctly rounded, as strtod) reads the common forms; what it leaves (a leading '+', hex, a value
// beyond the double range) goes to strtod.
const char* ScanNumber(const char* b, const char* e, double* v) {
  const auto r = std::from_chars(b, e, *v);
  if (r.ec == std::errc() && (r.ptr == e || *r.ptr == ',' || Blank(*r.ptr))) return r.ptr;
  // strtod would skip leading white space: a number starts with a printable character.
  if (b == e || static_cast<unsigned char>(*b) <= ' ') return b;
  char* q = nullptr;
  const double x = std::strtod(b, &q);
  if (q != b) *v = x;
  return q;
}

}  // namespace

bool CsvReader::ParseNumber(std::string_view f, double* v) {
  const char* e = f.data() + f.size();
  return !f.empty() && ScanNumber(f.data(), e, v) == e;
}

void CsvReader::NotANumber(size_t column, std::string_view text) const {
  throw InputError(Where() + "column '" + names_[column] + "': '" + std::string(text) + "' is not a number");
}

bool CsvReader::NumbersFromFields(double* values) {
  Split();
  CheckFieldCount(fields_.size(), fields_.back().empty());
  for (size_t i = 0; i < names_.size(); ++i)
    if (!ParseNumber(fields_[i], &values[i])) NotANumber(i, fields_[i]);
  return true;
}

bool CsvReader::NextNumbers(double* values) {
  if (!NextLine()) return false;
  const size_t length = static_cast<size_t>(line_end_ - line_begin_);
  if (std::memchr(line_begin_, '"', length)) return NumbersFromFields(values);
  // Unquoted: numbers read straight from the line (a field ends at ',', a blank, '\r', '\n' or the text's
  // NUL, none of which continues a number). Anything unexpected goes to the field-by-field path,
  // which names the column or the field count.
  const size_t n = names_.size();
  const char* s = line_begin_;
  for (size_t i = 0; i < n; ++i) {
    while (s < line_end_ && Blank(*s)) ++s;
    double x = 0;
    const char* q = ScanNumber(s, line_end_, &x);
    const char* after = q;
    while (after < line_end_ && Blank(*after)) ++after;
    const bool last = i + 1 == n;
    if (q == s || (after < line_end_ && *after != ',') || (!last && after >= line_end_))
      return NumbersFromFields(values);
    values[i] = x;
    s = after;
    if (!last) ++s;  // ','
  }
  // Line end, or the trailing ',' of a header that ends with one.
  const bool complete = trailing_empty_column_ ? s + 1 == line_end_ : s == line_end_;
  return complete ? true : NumbersFromFields(values);
}

namespace {
constexpr size_t kSplitBytes = size_t{1} << 20;  // a piece read in two halves at once from this size on
}  // namespace

CsvTable ReadCsv(const std::string& path) { return ReadCsv(path, CsvColumnFilter{}); }

CsvTable ReadCsv(const std::string& path, const CsvColumnFilter& filter) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a folder, expected a CSV file");
  TextFileChunks in(path, "", "a text CSV file");
  // The file in chunks of whole lines (a line longer than a chunk grows the buffer); one byte more
  // for the NUL after an unterminated last line.
  std::vector<char> buf((size_t{1} << 22) + 1);
  size_t have = 0;      // bytes in buf
  size_t parsed = 0;    // bytes of the file handed to the reader
  int lines_done = 0;   // lines of the file before buf
  bool first = true, streamed = false, reserved = false;
  std::optional<CsvReader> reader;
  CsvTable t;
  std::vector<double> row;
  // Whole lines [b, e) into t (the header first). Once the header is known, a long piece is read in
  // two halves at once: the second, from the first line start after its middle, by a copy of the reader
  // on another thread into its own rows, appended after the first's. An error in the first half is
  // the one reported (the file's first), as when read in one go.
  std::vector<std::vector<double>> later_columns;
  std::vector<int> later_lines;
  std::vector<size_t> kept;     // file index of each kept column
  std::vector<size_t> dropped;  // file index of each dropped column (t.dropped's order)
  // Every row `r` reads, into columns and lines; a dropped column's first value failing the check
  // into bad[k] (row within this call, value) when none before.
  using Bad = std::vector<std::pair<size_t, double>>;
  auto ReadRows = [&](CsvReader& r, double* values, std::vector<std::vector<double>>& columns, std::vector<int>& lines,
                      Bad& bad) {
    const size_t start = lines.size();
    while (r.NextNumbers(values)) {
      for (size_t i = 0; i < kept.size(); ++i) columns[i].push_back(values[kept[i]]);
      if (filter.check)
        for (size_t k = 0; k < dropped.size(); ++k)
          if (bad[k].first == SIZE_MAX && !filter.check(t.dropped[k].name, values[dropped[k]]))
            bad[k] = {lines.size() - start, values[dropped[k]]};
      lines.push_back(r.line());
    }
  };
  // The first failing rows of a piece read from table row `offset` on, into t.dropped.
  auto NoteBad = [&](const Bad& bad, size_t offset) {
    for (size_t k = 0; k < bad.size(); ++k)
      if (bad[k].first != SIZE_MAX && t.dropped[k].bad_row == SIZE_MAX)
        t.dropped[k].bad_row = offset + bad[k].first, t.dropped[k].bad_value = bad[k].second;
  };
  auto parse = [&](const char* b, const char* e) {
    if (!reader) reader.emplace(b, e, path);
    else reader->Continue(b, e);
    if (t.names.empty()) {
      if (!reader->ReadHeader()) return;
      const std::vector<std::string>& all = reader->names();
      for (size_t i = 0; i < all.size(); ++i) {
        if (!filter.keep || filter.keep(all[i])) {
          kept.push_back(i);
          t.names.push_back(all[i]);
        } else {
          dropped.push_back(i);
          t.dropped.push_back({all[i], t.names.size(), SIZE_MAX, 0.0});
        }
      }
      t.columns.assign(t.names.size(), {});
      row.resize(all.size());
      if (t.names.empty()) throw InputError(path + ": every column left out by the reader's filter");
    }
    Bad bad(dropped.size(), {SIZE_MAX, 0.0}), later_bad = bad;
    const size_t rows_before = t.rows();
    const char* half = b + (e - b) / 2;
    const char* nl = static_cast<size_t>(e - b) >= kSplitBytes && t.rows() > 0
                         ? static_cast<const char*>(std::memchr(half, '\n', static_cast<size_t>(e - half)))
                         : nullptr;
    if (!nl || nl + 1 >= e) {
      ReadRows(*reader, row.data(), t.columns, t.line_of_row, bad);
      NoteBad(bad, rows_before);
    } else {
      const char* m = nl + 1;  // the second half's first line
      CsvReader later = *reader;
      later.ContinueAfterLine(m, e, reader->line() + static_cast<int>(std::count(b, m, '\n')));
      reader->Continue(b, m);
      later_columns.assign(t.names.size(), {});
      later_lines.clear();
      std::vector<double> later_row(row.size());
      std::exception_ptr error[2];
      ParallelFor(2, 2, [&](size_t k) {
        try {
          if (k == 0) ReadRows(*reader, row.data(), t.columns, t.line_of_row, bad);
          else ReadRows(later, later_row.data(), later_columns, later_lines, later_bad);
        } catch (...) {
          error[k] = std::current_exception();
        }
      });
      for (const std::exception_ptr& x : error)
        if (x) std::rethrow_exception(x);
      NoteBad(bad, rows_before);
      NoteBad(later_bad, t.rows());
      for (size_t i = 0; i < t.columns.size(); ++i)
        t.columns[i].insert(t.columns[i].end(), later_columns[i].begin(), later_columns[i].end());
      t.line_of_row.insert(t.line_of_row.end(), later_lines.begin(), later_lines.end());
      *reader = std::move(later);
    }
    parsed += static_cast<size_t>(e - b);
    if (!reserved && in.size() > parsed && t.rows() > 0) {
      // Rows expected from the bytes per row so far (capacity never touched costs no memory).
      const double rows = static_cast<double>(t.rows()) * static_cast<double>(in.size()) / static_cast<double>(parsed);
      const size_t n = static_cast<size_t>(1.05 * rows) + 64;
      for (auto& c : t.columns) c.reserve(n);
      t.line_of_row.reserve(n);
      reserved = true;
    }
  };
  auto warn_cut = [&](int line) {
    t.dropped_cut_line = line;
    std::fprintf(stderr, "warning: %s:%d: last line has no newline in a streamed exotwin log: dropped "
                 "(the run was killed while writing it)\n", path.c_str(), line);
  };
  // A parse error: what reading the whole file first said before it comes first (a NUL byte
  // anywhere in the file, then the warning for a cut last line).
  auto guarded_parse = [&](const char* b, const char* e) {
    try {
      parse(b, e);
    } catch (const InputError&) {
      bool ends_with_newline = have > 0 && buf[have - 1] == '\n';
      const size_t rest = in.DrainCountingNewlines(&ends_with_newline);
      if (streamed && !ends_with_newline)
        warn_cut(lines_done + static_cast<int>(std::count(buf.data(), buf.data() + have, '\n') + rest) + 1);
      throw;
    }
  };
  for (bool eof = false; !eof;) {
    if (have + 1 == buf.size()) buf.resize(2 * buf.size() - 1);
    const size_t want = buf.size() - 1 - have;
    const size_t got = in.Read(buf.data() + have, want);
    eof = got < want;
    have += got;
    buf[have] = '\0';
    if (first) {
      if (have == 0) throw InputError(path + ": file is empty, expected a CSV header row");
      streamed = std::string_view(buf.data(), have).rfind(kStreamMarker, 0) == 0;
      first = false;
    }
    const char* b = buf.data();
    const char* nl = static_cast<const char*>(memrchr(b, '\n', have));
    if (nl) {
      const size_t whole = static_cast<size_t>(nl + 1 - b);
      guarded_parse(b, nl + 1);
      lines_done = reader->line();
      std::memmove(buf.data(), b + whole, have - whole);
      have -= whole;
      buf[have] = '\0';
    }
    if (eof && have > 0) {
      // An unterminated last line: a row cut by a killed run in a streamed file, else a row.
      if (streamed) warn_cut(lines_done + 1);
      else guarded_parse(buf.data(), buf.data() + have);
    }
  }
  if (t.names.empty()) throw InputError(path + ": no header row (only comments or blank lines)");
  return t;
}

namespace {

// The comment lines and the header row the writers put first, so that ReadCsv reads back exactly
// `names` whatever they hold (a foreign column named `note, "raw"` or `#1`): a name holding a comma,
// a quote, a line break, leading or trailing blanks, or starting with '#' is quoted (RFC 4180,
// quotes doubled); a comment holding line breaks becomes one '# ' line per line.
std::string CsvHead(const std::vector<std::string>& comments, const std::vector<std::string>& names) {
  std::string head;
  for (const auto& c : comments) {
    for (size_t b = 0;;) {
      const size_t e = c.find_first_of("\r\n", b);
      head += "# " + c.substr(b, e == std::string::npos ? std::string::npos : e - b) + "\n";
      if (e == std::string::npos) break;
      b = e + 1;
    }
  }
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    const bool quote = n.find_first_of(",\"\r\n") != std::string::npos || (!n.empty() && (Blank(n.front()) || Blank(n.back()))) ||
                       (i == 0 && !n.empty() && n[0] == '#');
    head += i ? "," : "";
    if (!quote) {
      head += n;
      continue;
    }
    head += '"';
    for (char ch : n) head += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    head += '"';
  }
  return head + "\n";
}

}  // namespace

void WriteFileAtomic(const std::string& path, const std::string& text) {
  CreateParentFolders(path);
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
  // Streamed to the temporary file in blocks of about 1 MiB (the text of a long record is never
  // held whole), then renamed as WriteFileAtomic does. Columns of unequal length are the caller's bug.
  for (const auto* c : columns)
    if (columns.size() != names.size() || c->size() != columns[0]->size())
      throw std::invalid_argument(path + ": WriteCsv: " + std::to_string(names.size()) + " names for " +
                                  std::to_string(columns.size()) + " columns of unequal length");
  CreateParentFolders(path);
  const std::string tmp = path + ".tmp";
  std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
  if (!file) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  std::string out;
  out += CsvHead(comments, names);
  constexpr size_t kBlock = size_t{1} << 20;
  out.reserve(kBlock + 1024);
  const size_t n = columns.empty() ? 0 : columns[0]->size();
  for (size_t r = 0; r < n; ++r) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (c) out += ',';
      AppendNumber(&out, (*columns[c])[r]);
    }
    out += '\n';
    if (out.size() >= kBlock) {
      file.write(out.data(), static_cast<std::streamsize>(out.size()));
      out.clear();
    }
  }
  file.write(out.data(), static_cast<std::streamsize>(out.size()));
  file.flush();
  if (!file) throw InputError(path + ": write failed (" + std::strerror(errno) + ")");
  file.close();
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw InputError(path + ": cannot rename temporary file (" + std::strerror(errno) + ")");
}

void AppendNumberRows(std::string& out, const std::vector<const std::vector<double>*>& columns, char sep) {
  const size_t n = columns.empty() ? 0 : columns[0]->size();
  out.reserve(out.size() + n * columns.size() * 24);
  for (size_t r = 0; r < n; ++r) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (c) out += sep;
      AppendNumber(&out, (*columns[c])[r]);
    }
    out += '\n';
  }
}

}  // namespace exotwin

#include <fcntl.h>
#include <unistd.h>

#include <condition_variable>
#include <mutex>
#include <thread>

namespace exotwin {

// The writer thread: formats and writes one block at a time; the caller waits for it only when it
// hands over the next block before the last is written (or on Flush).
struct CsvStreamWriter::Writer {
  int fd = -1;
  size_t columns = 0;
  std::mutex m;
  std::condition_variable cv;
  std::vector<double> block;  // owned by the thread while busy
  bool busy = false, stop = false;
  std::string error;          // the first write error, reported in the caller's thread
  std::string text;
  std::thread thread;

  // Writes `bytes` whole (EINTR retried); "" or the error's text.
  std::string WriteAll(const char* bytes, size_t size) {
    size_t off = 0;
    while (off < size) {
      const ssize_t w = ::write(fd, bytes + off, size - off);
      if (w < 0) {
        if (errno == EINTR) continue;
        return std::strerror(errno);
      }
      off += static_cast<size_t>(w);
    }
    return "";
  }

  void Run() {
    std::unique_lock<std::mutex> lock(m);
    for (;;) {
      cv.wait(lock, [this] { return busy || stop; });
      if (!busy) return;
      lock.unlock();
      // Shortest text that reads back to the same double (std::to_chars, as AppendNumber), at most 24
      // characters + the separator per column, written in place.
      constexpr size_t kMaxField = 25;
      const size_t rows = block.size() / columns;
      text.resize(rows * (columns * kMaxField + 1));
      char* p = text.data();
      char* const end = p + text.size();
      for (size_t r = 0; r < rows; ++r) {
        const double* v = block.data() + r * columns;
        for (size_t c = 0; c < columns; ++c) {
          if (c) *p++ = ',';
          p = std::to_chars(p, end, v[c]).ptr;
        }
        *p++ = '\n';
      }
      const std::string e = WriteAll(text.data(), static_cast<size_t>(p - text.data()));
      lock.lock();
      if (!e.empty() && error.empty()) error = e;
      block.clear();
      busy = false;
      cv.notify_all();
    }
  }
};

CsvStreamWriter::CsvStreamWriter(const std::string& path, const std::vector<std::string>& names,
                                 const std::vector<std::string>& comments, size_t flush_rows)
    : path_(path), columns_(std::max<size_t>(names.size(), 1)), flush_rows_(flush_rows ? flush_rows : 1),
      writer_(std::make_unique<Writer>()) {
  Writer& w = *writer_;
  CreateParentFolders(path);
  w.fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (w.fd < 0) throw InputError(path + ": cannot write (" + std::strerror(errno) + ")");
  std::string head = std::string(kStreamMarker) + "\n";
  head += CsvHead(comments, names);
  const std::string e = w.WriteAll(head.data(), head.size());
  if (!e.empty()) {
    ::close(w.fd);
    throw InputError(path + ": write failed (" + e + ")");
  }
  w.columns = columns_;
  block_.reserve(flush_rows_ * columns_);
  w.block.reserve(flush_rows_ * columns_);
  w.text.reserve(flush_rows_ * (columns_ * 25 + 1));  // Run's kMaxField: no allocation after start
  w.thread = std::thread([&w] {
    DropRealtimePriority();  // a real-time caller's (serve --rt-priority) tick never waits behind the text
    w.Run();
  });
}

CsvStreamWriter::~CsvStreamWriter() {
  try {
    Flush();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
  }
  {
    std::lock_guard<std::mutex> lock(writer_->m);
    writer_->stop = true;
  }
  writer_->cv.notify_all();
  writer_->thread.join();
  ::close(writer_->fd);
}

void CsvStreamWriter::Row(const double* values, size_t n) {
  for (size_t c = 0; c < columns_; ++c) block_.push_back(c < n ? values[c] : 0.0);
  ++rows_;
  if (block_.size() >= flush_rows_ * columns_) HandOver();
}

// Gives the block to the writer thread once it is idle (its capacity comes back as the next block).
void CsvStreamWriter::HandOver() {
  Writer& w = *writer_;
  std::unique_lock<std::mutex> lock(w.m);
  w.cv.wait(lock, [&w] { return !w.busy; });
  if (!w.error.empty()) throw InputError(path_ + ": write failed (" + w.error + ")");
  w.block.swap(block_);
  w.busy = true;
  w.cv.notify_all();
}

void CsvStreamWriter::Flush() {
  if (!block_.empty()) HandOver();
  Writer& w = *writer_;
  std::unique_lock<std::mutex> lock(w.m);
  w.cv.wait(lock, [&w] { return !w.busy; });
  if (!w.error.empty()) throw InputError(path_ + ": write failed (" + w.error + ")");
}

}  // namespace exotwin
