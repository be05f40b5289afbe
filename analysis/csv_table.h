// Numeric CSV tables: a header row of column names, then one row of numbers per sample. Lines
// starting with '#' are comments. Used for the measured-data CSV of DESIGN.md and every CSV exotwin
// writes.
#pragma once
#include <string>
#include <vector>

namespace exotwin {

struct CsvTable {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  // columns[i] belongs to names[i]
  std::vector<int> line_of_row;              // 1-based file line of each data row

  size_t rows() const { return columns.empty() ? 0 : columns[0].size(); }
  // Index of a column, -1 if absent.
  int Find(const std::string& name) const;
};

// Parses a CSV file. Throws InputError naming the file and line for: unreadable or empty file, no
// header, duplicated or empty column names, a row with the wrong number of fields, a field that is
// not a number. NaN/inf are parsed (callers decide whether they are allowed).
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
// last `flush_rows` (the buffer is written with one write(2) of whole lines, never a partial line).
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
