// Column maps (DESIGN.md "Column map"): a YAML file that turns a foreign CSV (another rig's log)
// into the measured-data schema: per schema column a source column, a scale, an offset, a unit and a
// sign; and what to do with rows that repeat a time stamp. ReadMeasured is the one entry point the
// commands use to read a --measured file with or without --map.
#pragma once
#include <string>
#include <vector>

#include "formats/csv_table.h"
#include "formats/measured_data.h"

namespace exotwin {

// One schema column and how it is computed from a source column:
//   value_SI = to_si * (sign * scale * raw + offset)
// i.e. scale and offset give the value in `unit`, which is then converted to SI.
struct ColumnSpec {
  std::string target;   // schema column: t, q_hip, tau_knee, qd_hip, cmd_knee, emg_VM, ...
  std::string from;     // source column name
  double scale = 1.0;   // non-zero
  double offset = 0.0;  // in `unit`, added after the scale
  double sign = 1.0;    // +1 or -1
  std::string unit;     // as declared (empty: SI)
  double to_si = 1.0;   // factor from `unit` to SI
  int line = 0;         // line of the entry in the map file (1-based), for messages
};

// Rows that repeat the previous row's time stamp.
enum class DuplicateTimes {
  kAverage,  // merged into one row holding the mean of each column (default)
  kFirst,    // the first row kept, the repeats dropped
  kError,    // bad input
};

struct ColumnMap {
  std::string source;               // the map file, for messages
  std::vector<ColumnSpec> columns;  // required targets first (t, q_hip, q_knee, tau_hip, tau_knee; a one-joint map
                                    // without hip targets: t, q_knee, tau_knee), then as in the file
  DuplicateTimes duplicates = DuplicateTimes::kAverage;
};

// What ApplyColumnMap did, for stderr and for tests.
struct MapReport {
  std::string map, input;
  size_t rows_in = 0, rows_out = 0;
  size_t repeated_stamps = 0;       // time stamps held by more than one row
  size_t rows_merged = 0;           // rows folded into (average) or dropped after (first) an earlier one
  std::vector<int> repeated_lines;  // input lines of the first (up to 5) rows repeating a stamp
  std::string duplicates = "average";  // the map's time.duplicates
  // Time step of the output rows, s, and its jitter: the step's standard deviation over its median.
  double dt_median = 0, dt_min = 0, dt_max = 0, dt_p99 = 0, jitter = 0;
  std::vector<std::string> mapped;  // one line per target: "tau_hip <- -1 * tau_meas1"
  std::string Summary() const;      // a few lines for stderr
};

// Reads and validates a column map. Throws InputError naming the map file, the key (e.g.
// "columns.q_knee.scale") and the line for: malformed YAML, unknown keys or targets, a missing
// required target or `from`, a zero scale, a sign other than +-1, a unit the target does not take.
ColumnMap ReadColumnMap(const std::string& path);

// Applies a map to a foreign table (`source`: its file name; the output keeps its line numbers for
// messages) and validates the result as MeasuredFromTable does. Throws InputError for a source column
// missing from the table, an angle in degrees beyond +-720 deg, a repeated time stamp under
// `duplicates: error`, and for whatever the schema rejects (the message then names the map).
MeasuredData ApplyColumnMap(const ColumnMap& map, const CsvTable& in, const std::string& source,
                            MapReport* report = nullptr, size_t min_samples = 20);

// Reads a --measured file: in the schema when `map_path` is empty (ReadMeasuredCsv), else a foreign
// CSV through the map at `map_path`, or a ROS 2 bag (IsBagPath: an .mcap file or a rosbag2 folder;
// formats/bag_table.h) through it; a bag without a map is bad input. `report` (optional) receives
// what the map did. `keep`: the columns the caller reads (ReadMeasuredCsv's; a schema CSV's only).
MeasuredData ReadMeasured(const std::string& csv_path, const std::string& map_path, size_t min_samples = 20,
                          MapReport* report = nullptr, const MeasuredColumns& keep = {});

}  // namespace exotwin
