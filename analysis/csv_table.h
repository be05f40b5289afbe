// Numeric CSV tables: a header row of column names, then one row of numbers per sample. Lines
// starting with '#' are comments. Used for the measured-data CSV of DESIGN.md and every CSV exotwin
// writes.
#pragma once
#include <string>
#include <vector>

namespace exotwin {

// First comment line of every streamed CSV: every complete row of such a file ends with '\n'.
inline constexpr const char* kStreamMarker = "# exotwin stream: complete rows end with a newline";

struct CsvTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[i] belongs to names[i]
  std::vector<int> line_of_row;              // 1-based file line of each data row
  int dropped_cut_line = 0;  // line number of a cut last line dropped from a streamed file, else 0

  size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  // Index of a column, -1 if absent.
  int Find(const std::string& name) const;
};

// Parses a CSV file. Throws InputError naming the file and line for: unreadable or empty file, no
// header, duplicated or empty column names, a row with the wrong number of fields, a field that is
// not a number. NaN/inf are parsed (callers decide whether they are allowed). In a file that starts
// with kStreamMarker, an unterminated last line is a row cut by a killed run: it is dropped, with a
// warning on stderr, and its line number kept in dropped_cut_line.
CsvTable ReadCsv(const std::string& path);

// Writes a table with full double precision (%.17g), header first. `comments` go first as '# ' lines.
// Written to a temporary file and renamed, so a reader never sees a partial file.
void WriteCsv(const std::string& path, const std::vector<std::string>& names,
              const std::vector<const std::vector<double>*>& columns,
              const std::vector<std::string>& comments = {});

// Writes `text` to `path` atomically (temporary file in the same folder, then rename).
void WriteFileAtomic(const std::string& path, const std::string& text);

}  // namespace exotwin

namespace exotwin {

// Streams rows to a CSV file as a run produces them, so that an abort loses at most the rows of the
// last `flush_rows`. The buffer holds whole lines only, but a SIGKILL can still cut a write(2) to a
// regular file at a page boundary (Linux checks for fatal signals between pages), so the last line
// of a killed run may be cut. The file's first line is kStreamMarker; ReadCsv drops an unterminated
// last line of such a file (and says so), and keeps every complete row.
class CsvStreamWriter {
 public:
  // Opens (truncates) `path` and writes the comments and the header. Throws InputError if it cannot.
  CsvStreamWriter(const std::string& path, const std::vector<std::string>& names,
                  const std::vector<std::string>& comments = {}, size_t flush_rows = 100);
  ~CsvStreamWriter();
  CsvStreamWriter(const CsvStreamWriter&) = delete;
  CsvStreamWriter& operator=(const CsvStreamWriter&) = delete;
  // Appends one row (values.size() == number of columns).
  void Row(const double* values, size_t n);
  void Flush();
  size_t rows() const { return rows_; }

 private:
  int fd_ = -1;
  std::string path_, buffer_;
  size_t columns_, flush_rows_, pending_ = 0, rows_ = 0;
};

}  // namespace exotwin
