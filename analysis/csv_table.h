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
