// `exotwin convert --map MAP.yaml IN.csv --out DATA.csv` (DESIGN.md): a foreign CSV or a ROS 2 bag
// through a column map into the measured-data schema; what the map did (rows, repeated time stamps, time step and
// jitter) goes to stderr. The output is written whole or not at all (WriteCsv).
#include <CLI/CLI.hpp>

#include <cstdio>

#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "app/commands.h"

namespace exotwin {
namespace {

CommandRunner RegisterConvert(CLI::App& app) {
  struct Opts {
    std::string map, in, out;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "convert", "Foreign CSV -> measured-data CSV through a column map (rename, scale, offset, units, sign)");
  sub->add_option("--map", o->map, "column map (YAML, DESIGN.md \"Column map\")")->required();
  sub->add_option("input", o->in, "foreign CSV or ROS 2 bag (.mcap, rosbag2 folder) to convert")->required();
  sub->add_option("--out", o->out, "measured-data CSV to write")->required();
  return [sub, o]() -> int {
    if (!*sub) return -1;
    MapReport report;
    const MeasuredData data = ReadMeasured(o->in, o->map, 1, &report);
    std::fprintf(stderr, "convert: %s", report.Summary().c_str());
    const CsvTable table = TableAsRecorded(data);  // a one-joint record as such
    std::vector<const std::vector<double>*> cols;
    for (const auto& c : table.columns) cols.push_back(&c);
    std::vector<std::string> comments = {"exotwin convert: measured-data CSV (DESIGN.md)",
                                         "source: " + o->in, "map: " + o->map};
    for (const std::string& m : report.mapped) comments.push_back("  " + m);
    if (report.rows_merged > 0)
      comments.push_back(std::to_string(report.rows_merged) + " rows repeating a time stamp merged (" +
                         report.duplicates + ")");
    WriteCsv(o->out, table.names, cols, comments);
    return 0;
  };
}

const CommandRegistration kConvert(RegisterConvert);

}  // namespace
}  // namespace exotwin
