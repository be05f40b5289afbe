// OpenSim storage files (.sto / .mot): EMG envelopes, inverse-kinematics angles, inverse-dynamics
// moments as OpenSim writes them. The one reader of these files in exotwin (emg-fit, emg-predict).
//
// Accepted layout (DESIGN.md "OpenSim storage files"):
//  - a header ending with a line `endheader` (version-1 files: `version=1`, `nRows=`, `nColumns=`,
//    `inDegrees=yes|no`, free text lines; SIMM-era `datarows N` / `datacolumns N` without '=' count
//    as nRows / nColumns), or no header at all when the first line is the column
//    names line starting with `time`;
//  - one line of column names, then one row of numbers per line; fields separated by tabs and/or
//    spaces, separators at the end of a line ignored (a trailing tab is not a column);
//  - a `time` column (s), strictly increasing; blank lines ignored.
// Everything else throws InputError naming the file and the line: a header without `endheader`, a
// row whose number of values differs from the number of column names, a field that is not a number,
// non-increasing or non-finite time, repeated column names, nRows / nColumns that disagree with the
// table, an `inDegrees` value other than yes / no.
#pragma once
#include <string>
#include <vector>

namespace exotwin {

struct StorageTable {
  std::string source;                        // file name, for messages
  std::vector<std::string> names;            // every column, `time` included, in file order
  std::vector<std::vector<double>> columns;  // columns[i] belongs to names[i]
  std::vector<int> line_of_row;              // 1-based file line of each row
  int names_line = 0;                        // 1-based line of the column names
  int endheader_line = 0;                    // 1-based line of `endheader`, 0 without a header
  int in_degrees = -1;                       // inDegrees: 1 yes, 0 no, -1 not stated

  size_t rows() const { return line_of_row.size(); }
  int Find(const std::string& name) const;  // index of a column, -1 if absent
  const std::vector<double>& Time() const;   // the `time` column, s
  // A column by name; throws InputError "<source>: no column '<name>' (<what>)" when absent.
  const std::vector<double>& Column(const std::string& name, const std::string& what) const;
  // An angle column in rad: converted from degrees when inDegrees=yes. Throws InputError when the
  // column is absent or when the header does not state the unit (no inDegrees line: the message names
  // the endheader line, or the column names line of a file without header).
  std::vector<double> AngleRad(const std::string& name) const;
};

// Parses storage text; `source` names it in messages. Text that is not valid (core/file_text.h
// CheckText: UTF-8 without control characters) is an InputError naming its line and byte.
StorageTable ParseStorage(const std::string& text, const std::string& source);
// Reads and parses a storage file; throws InputError when it cannot be read.
StorageTable ReadStorage(const std::string& path);

// Writes an OpenSim version-1 storage file that OpenSim (Storage, TimeSeriesTable) and ReadStorage
// open: the line `name`, `version=1`, `nRows=`, `nColumns=`, `inDegrees=yes|no` (`in_degrees`: the
// unit of the angle columns), `notes` as free text lines, `endheader`; then the column names and one
// row per sample, tab-separated, values as AppendNumber writes them (doubles round-trip exactly). `names` must contain
// `time` (s, strictly increasing); every column as long as the first. Written atomically (temporary
// file, rename). Throws InputError when the file cannot be written or the columns disagree.
void WriteStorage(const std::string& path, const std::string& name, const std::vector<std::string>& names,
                  const std::vector<const std::vector<double>*>& columns, bool in_degrees,
                  const std::vector<std::string>& notes = {});

// The content of a CSV the twin writes (measured.csv, truth.csv: header row, `t` in s, SI units) as
// a storage file at `sto_path`: `t` becomes `time`, every other column keeps its name and its SI
// value (angles in rad: inDegrees=no). Throws InputError naming the CSV for unreadable content.
void CsvToStorage(const std::string& csv_path, const std::string& sto_path);

}  // namespace exotwin
