// CSV files as exotwin reads them (DESIGN.md "Measured-data CSV", "What the CSV reader accepts"): a
// header row of column names, then one record per line. Every CSV exotwin reads goes through
// CsvReader: measured data and column maps' inputs (ReadCsv), sweep tables (runner/sweep_table.cc).
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace exotwin {

// First comment line of every streamed CSV: every complete row of such a file ends with '\n'.
inline constexpr const char* kStreamMarker = "# exotwin stream: complete rows end with a newline";

// Splits a CSV text into a header and records. The dialect (RFC 4180 without line breaks in fields):
// - a UTF-8 byte-order mark at the start is skipped; lines end with LF or CRLF;
// - blank lines and lines whose first non-blank character is '#' are skipped (comments);
// - fields are separated by ','; spaces and tabs around a field are ignored;
// - a field may be quoted ("..."): inside, ',' is a character and "" is one '"'; a quoted field ends
//   on its line; a '"' inside an unquoted field is an error;
// - the first record is the header: non-empty, distinct names; a header ending with ',' declares an
//   empty last column: every row must end with ',' too, and the column is dropped;
// - every row has as many fields as the header;
// - a number is what strtod reads in the "C" locale over the whole field ("1.5", "-2e-3", "nan",
//   "inf", "0x1p-3"); a quoted field holding a number is that number.
// A header separated by ';' or by tabs is rejected with a message naming the separator and the fix.
// Errors are InputError naming "source:line:".
class CsvReader {
 public:
  // `text` is the whole file and must outlive the reader; `source` names it in messages.
  CsvReader(const std::string& text, std::string source);
  // The text [begin, end): whole lines of a file read in chunks (see Continue). Precondition: the
  // byte at `end` is readable and cannot continue a number ('\n', '\r' or a NUL).
  CsvReader(const char* begin, const char* end, std::string source);

  // Goes on with the next whole lines [begin, end) of the same file (header, line numbers and
  // dialect kept; the previous text may be gone). Precondition as for the constructor.
  void Continue(const char* begin, const char* end);
  // Continue where [begin, end) starts after line `line_before` of the file: for a copy of the reader
  // that reads a later part of the same text (on another thread) while this one reads the part before.
  void ContinueAfterLine(const char* begin, const char* end, int line_before);

  // Reads the header row. False if the text holds no record (only comments or blank lines).
  bool ReadHeader();
  const std::vector<std::string>& names() const { return names_; }

  // Advances to the next row and splits it; false at the end of the text. Then field(i), i <
  // names().size(), is the text of field i (quotes removed).
  bool NextRow();
  std::string_view field(size_t i) const { return fields_[i]; }
  // Field i of the current row (after NextRow) as a number; false if it is not one.
  bool Number(size_t i, double* v) const { return ParseNumber(fields_[i], v); }

  // Advances to the next row and parses every field as a number into values[0 .. names().size());
  // false at the end of the text. Throws InputError naming the column for a field that is not a
  // number. The fast path of numeric tables: an unquoted row is parsed in place.
  bool NextNumbers(double* values);

  int line() const { return line_; }  // 1-based line of the current record
  std::string Where() const;          // "source:line: "

 private:
  bool NextLine();
  void Split();
  void CheckFieldCount(size_t found, bool last_empty) const;
  bool NumbersFromFields(double* values);  // NextNumbers on the split line
  [[noreturn]] void NotANumber(size_t column, std::string_view text) const;
  // True if the whole of `f` is a number (the rule above). Precondition: the byte after `f` cannot
  // continue a number (the reader's fields are followed by ',', a blank, a line end or a NUL).
  static bool ParseNumber(std::string_view f, double* v);

  const char* next_;  // start of the next line
  const char* end_;   // end of the text
  const char *line_begin_ = nullptr, *line_end_ = nullptr;  // current line, without its line end
  int line_ = 0;
  std::string source_;
  std::vector<std::string> names_;
  bool trailing_empty_column_ = false;
  std::vector<std::string_view> fields_;
  std::string unquoted_;  // quoted fields' text, each followed by a NUL; reserved per line, never reallocated
};

struct CsvTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[i] belongs to names[i]
  std::vector<int> line_of_row;              // 1-based file line of each data row
  int dropped_cut_line = 0;  // line number of a cut last line dropped from a streamed file, else 0
  // Columns ReadCsv read (every field a number) but did not keep (CsvColumnFilter::keep false), in
  // file order: `before` kept columns precede it in the file; the first row whose value failed the
  // filter's check (rows() if none) and that value.
  struct Dropped {
    std::string name;
    size_t before = 0;
    size_t bad_row = 0;
    double bad_value = 0;
  };
  std::vector<Dropped> dropped;

  size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  // Index of a column, -1 if absent.
  int Find(const std::string& name) const;
};

// Parses a numeric CSV file with CsvReader. Throws InputError naming the file and line for: a folder,
// an unreadable, empty or binary (NUL byte) file, no header, duplicated or empty column
// names, a row with the wrong number of fields, a field that is not a number. NaN/inf are parsed
// (callers decide whether they are allowed). In a file that starts with kStreamMarker, an
// unterminated last line is a row cut by a killed run: it is dropped, with a warning on stderr, and
// its line number kept in dropped_cut_line.
CsvTable ReadCsv(const std::string& path);

// Which columns a reader keeps: a long record's columns that no stage reads cost memory as they are
// read. keep(name) false: the column is read (every field must be a number) but not stored; then
// check(name, value), when set, tests each of its values as read, the first failing row noted in
// CsvTable::dropped (so that a validation of the table sees what it would have seen).
struct CsvColumnFilter {
  std::function<bool(const std::string& name)> keep;
  std::function<bool(const std::string& name, double value)> check;
};
// ReadCsv keeping the columns `filter` keeps (all when filter.keep is empty).
CsvTable ReadCsv(const std::string& path, const CsvColumnFilter& filter);

// Appends the shortest text of v that reads back to the same double (std::to_chars: no locale, no
// printf cost; "1e-05" where %.17g writes "1.0000000000000001e-05").
void AppendNumber(std::string* out, double v);

// Writes a table with full double precision (AppendNumber: every number reads back to the same
// double as %.17g's text), header first. `comments` go first as '# ' lines.
// Written to a temporary file and renamed, so a reader never sees a partial file.
void WriteCsv(const std::string& path, const std::vector<std::string>& names,
              const std::vector<const std::vector<double>*>& columns,
              const std::vector<std::string>& comments = {});

// Writes `text` to `path` atomically (temporary file in the same folder, then rename).
void WriteFileAtomic(const std::string& path, const std::string& text);

}  // namespace exotwin

namespace exotwin {

// Streams rows to a CSV file as a run produces them. Rows are collected as numbers in blocks of
// `flush_rows`; a writer thread turns each full block into text (as AppendNumber) and writes it while
// the caller goes on (the text costs as much as the simulation of the row on one core), so that an
// abort (SIGKILL) loses at most the rows of the last two blocks, and an exception none (the destructor
// writes every row). Blocks are written whole lines at a time, but a SIGKILL can still cut a write(2)
// to a regular file at a page boundary (Linux checks for fatal signals between pages), so the last
// line of a killed run may be cut. The file's first line is kStreamMarker; ReadCsv drops an
// unterminated last line of such a file (and says so), and keeps every complete row. Row and Flush
// allocate nothing once the first block is full.
class CsvStreamWriter {
 public:
  // Opens (truncates) `path` and writes the comments and the header. Throws InputError if it cannot.
  CsvStreamWriter(const std::string& path, const std::vector<std::string>& names,
                  const std::vector<std::string>& comments = {}, size_t flush_rows = 100);
  // Writes the rows not written yet (a write error then is reported on stderr, not thrown).
  ~CsvStreamWriter();
  CsvStreamWriter(const CsvStreamWriter&) = delete;
  CsvStreamWriter& operator=(const CsvStreamWriter&) = delete;
  // Appends one row: values[0..n), missing columns 0. Throws InputError when an earlier block could
  // not be written.
  void Row(const double* values, size_t n);
  // Returns once every row appended so far is written. Throws InputError on a write error.
  void Flush();
  size_t rows() const { return rows_; }

 private:
  struct Writer;  // the thread and the block it writes (csv_table.cc)
  void HandOver();
  std::string path_;
  size_t columns_, flush_rows_, rows_ = 0;
  std::vector<double> block_;  // the rows appended since the last hand-over, row-major
  std::unique_ptr<Writer> writer_;
};

}  // namespace exotwin
