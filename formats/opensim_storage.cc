#include "formats/opensim_storage.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "formats/csv_table.h"
#include "formats/number_rows.h"
#include "formats/number_text.h"
#include "core/error.h"
#include "core/file_text.h"
#include "core/units.h"

namespace exotwin {
namespace {

// Fields separated by runs of tabs and spaces; leading and trailing separators ignored.
std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == '\t' || line[i] == ' ' || line[i] == '\r')) ++i;
    if (i >= line.size()) break;
    size_t j = i;
    while (j < line.size() && line[j] != '\t' && line[j] != ' ' && line[j] != '\r') ++j;
    out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

[[noreturn]] void Fail(const std::string& source, int line, const std::string& what) {
  throw InputError(source + (line > 0 ? ": line " + std::to_string(line) : "") + ": " + what);
}

// "key=value" header line; false when the line has no '='.
bool KeyValue(const std::string& line, std::string* key, std::string* value) {
  const size_t eq = line.find('=');
  if (eq == std::string::npos) return false;
  *key = Trim(line.substr(0, eq)), *value = Trim(line.substr(eq + 1));
  return true;
}

// SIMM-era motion header line "datarows 101" / "datacolumns 3" (key, blank, value; no '='): the
// counts older tools write. Other lines without '=' are free text.
bool SimmKeyValue(const std::string& line, std::string* key, std::string* value) {
  const std::vector<std::string> f = Fields(line);
  if (f.size() != 2 || (f[0] != "datarows" && f[0] != "datacolumns")) return false;
  *key = f[0], *value = f[1];
  return true;
}

}  // namespace

int StorageTable::Find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

const std::vector<double>& StorageTable::Time() const { return Column("time", "time, s"); }

const std::vector<double>& StorageTable::Column(const std::string& name, const std::string& what) const {
  const int i = Find(name);
  if (i < 0) throw InputError(source + ": no column '" + name + "' (" + what + ")");
  return columns[i];
}

std::vector<double> StorageTable::AngleRad(const std::string& name) const {
  std::vector<double> v = Column(name, "joint angle");
  if (in_degrees < 0)
    throw InputError(source + ": line " + std::to_string(endheader_line > 0 ? endheader_line : names_line) +
                     ": the header does not state the angle unit of '" + name +
                     "' (expected an inDegrees=yes or inDegrees=no line before " +
                     (endheader_line > 0 ? "endheader" : "the column names; this file has no header") + ")");
  if (in_degrees == 1)
    for (double& x : v) x *= kRadPerDeg;
  return v;
}

StorageTable ParseStorage(const std::string& text, const std::string& source) {
  CheckText(text, source, "an OpenSim storage (.sto/.mot) text");  // labels are written to CSV and JSON
  StorageTable t;
  t.source = source;
  std::vector<std::string> lines;
  {
    std::istringstream is(text);
    for (std::string l; std::getline(is, l);) lines.push_back(l);
  }
  size_t k = 0;
  while (k < lines.size() && Trim(lines[k]).empty()) ++k;
  if (k == lines.size()) Fail(source, 0, "empty file (expected an OpenSim storage file)");
  long n_rows = -1, n_cols = -1;
  const std::vector<std::string> first = Fields(lines[k]);
  if (first.empty() || first[0] != "time") {  // a header, ended by `endheader`
    size_t end = k;
    for (; end < lines.size(); ++end) {
      const std::string l = Trim(lines[end]);
      if (l == "endheader") break;
      std::string key, value;
      if (!KeyValue(l, &key, &value) && !SimmKeyValue(l, &key, &value)) continue;  // free text
      const int line = static_cast<int>(end + 1);
      if (key == "inDegrees") {
        if (value == "yes") t.in_degrees = 1;
        else if (value == "no") t.in_degrees = 0;
        else Fail(source, line, "inDegrees='" + value + "' (expected yes or no)");
      } else if (key == "nRows" || key == "nColumns" || key == "datarows" || key == "datacolumns") {
        char* e = nullptr;
        errno = 0;
        const long v = std::strtol(value.c_str(), &e, 10);
        if (value.empty() || *e != '\0' || errno != 0 || v < 0)
          Fail(source, line, key + "='" + value + "' (expected a non-negative integer)");
        (key == "nRows" || key == "datarows" ? n_rows : n_cols) = v;
      }
    }
    if (end < lines.size()) t.endheader_line = static_cast<int>(end + 1);
    if (end == lines.size())
      Fail(source, static_cast<int>(k + 1),
           "a header without 'endheader' (an OpenSim storage file starts with the column names "
           "line 'time ...' or with a header ended by a line 'endheader')");
    k = end + 1;
    while (k < lines.size() && Trim(lines[k]).empty()) ++k;
    if (k == lines.size()) Fail(source, static_cast<int>(end + 1), "no column names after endheader");
  }
  t.names_line = static_cast<int>(k + 1);
  t.names = Fields(lines[k]);
  std::set<std::string> seen;
  for (const std::string& n : t.names)
    if (!seen.insert(n).second) Fail(source, t.names_line, "column '" + n + "' appears twice");
  const int time_col = t.Find("time");
  if (time_col < 0) Fail(source, t.names_line, "no 'time' column among the column names");
  if (n_cols >= 0 && static_cast<size_t>(n_cols) != t.names.size())
    Fail(source, t.names_line,
         std::to_string(t.names.size()) + " column names, the header says nColumns=" + std::to_string(n_cols));
  t.columns.assign(t.names.size(), {});
  for (++k; k < lines.size(); ++k) {
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> f = Fields(lines[k]);
    if (f.empty()) continue;
    if (f.size() != t.names.size())
      Fail(source, line,
           std::to_string(f.size()) + " values, " + std::to_string(t.names.size()) +
               " column names (line " + std::to_string(t.names_line) + ")");
    for (size_t c = 0; c < f.size(); ++c) {
      char* e = nullptr;
      const double v = std::strtod(f[c].c_str(), &e);
      if (*e != '\0') Fail(source, line, "'" + f[c] + "' in column '" + t.names[c] + "' is not a number");
      t.columns[c].push_back(v);
    }
    const std::vector<double>& time = t.columns[time_col];
    const double now = time.back();
    if (!std::isfinite(now)) Fail(source, line, "time '" + f[time_col] + "' is not finite");
    if (time.size() >= 2 && !(now > time[time.size() - 2]))
      Fail(source, line,
           "time " + NumberText(now, 10) + " s does not increase (previous row " +
               NumberText(time[time.size() - 2], 10) + " s)");
    t.line_of_row.push_back(line);
  }
  if (t.rows() < 2) Fail(source, t.names_line, "fewer than 2 rows of data");
  if (n_rows >= 0 && static_cast<size_t>(n_rows) != t.rows())
    Fail(source, t.line_of_row.back(),
         std::to_string(t.rows()) + " rows of data, the header says nRows=" + std::to_string(n_rows) +
             " (a cut file?)");
  return t;
}

StorageTable ReadStorage(const std::string& path) {
  // The project's text-file reader (unreadable file, NUL bytes: InputError naming the file).
  return ParseStorage(ReadTextFile(path, "OpenSim storage", "an OpenSim storage (.sto/.mot) text file"), path);
}

void WriteStorage(const std::string& path, const std::string& name, const std::vector<std::string>& names,
                  const std::vector<const std::vector<double>*>& columns, bool in_degrees,
                  const std::vector<std::string>& notes) {
  if (names.size() != columns.size() || columns.empty())
    throw InputError(path + ": internal: " + std::to_string(names.size()) + " column names for " +
                     std::to_string(columns.size()) + " columns");
  bool has_time = false;
  for (const std::string& n : names) has_time = has_time || n == "time";
  if (!has_time) throw InputError(path + ": internal: no 'time' column to write");
  const size_t rows = columns[0]->size();
  for (size_t c = 0; c < columns.size(); ++c)
    if (columns[c]->size() != rows)
      throw InputError(path + ": internal: column '" + names[c] + "' has " + std::to_string(columns[c]->size()) +
                       " rows, '" + names[0] + "' " + std::to_string(rows));
  std::string out = name + "\nversion=1\nnRows=" + std::to_string(rows) + "\nnColumns=" +
                    std::to_string(names.size()) + "\ninDegrees=" + (in_degrees ? "yes" : "no") + "\n";
  for (const std::string& n : notes) out += n + "\n";
  out += "endheader\n";
  for (size_t c = 0; c < names.size(); ++c) out += (c ? "\t" : "") + names[c];
  out += '\n';
  AppendNumberRows(out, columns, '\t');
  WriteFileAtomic(path, out);
}

void CsvToStorage(const std::string& csv_path, const std::string& sto_path) {
  const CsvTable csv = ReadCsv(csv_path);
  if (csv.Find("t") < 0) throw InputError(csv_path + ": no column 't' (time, s) to write as 'time' in " + sto_path);
  std::vector<std::string> names;
  std::vector<const std::vector<double>*> cols;
  for (size_t c = 0; c < csv.names.size(); ++c) {
    names.push_back(csv.names[c] == "t" ? "time" : csv.names[c]);
    cols.push_back(&csv.columns[c]);
  }
  WriteStorage(sto_path, sto_path.substr(sto_path.find_last_of('/') + 1), names, cols, false,
               {"exotwin: the content of " + csv_path + " (SI units: s, rad, rad/s, N m, V)"});
}

}  // namespace exotwin
