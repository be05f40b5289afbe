#include "formats/column_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "formats/bag_table.h"
#include "formats/mcap_reader.h"
#include "formats/number_text.h"
#include "dsp/statistics.h"
#include "core/error.h"
#include "core/units.h"
#include "core/yaml_fields.h"

namespace exotwin {
namespace {

const char* const kRequired[] = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
const char kTargets[] =
    "t, q_hip, q_knee, tau_hip, tau_knee, qd_hip, qd_knee, qdd_hip, qdd_knee, cmd_hip, cmd_knee, emg_<channel>";
// Beyond this a column declared in degrees holds something else (encoder counts, centi-degrees, ...).
constexpr double kMaxDegrees = 720.0;

bool IsTarget(const std::string& name) {
  if (name.rfind("emg_", 0) == 0)
    return name.size() > 4 && name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_",
                                                     4) == std::string::npos;
  return IsMeasuredColumn(name);
}

bool IsRequired(const std::string& name) {
  return std::find(std::begin(kRequired), std::end(kRequired), name) != std::end(kRequired);
}

struct Unit {
  const char* name;
  double to_si;
};

// The units a target takes; the first is its SI unit.
std::vector<Unit> UnitsOf(const std::string& target) {
  if (target == "t") return {{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}};
  if (target.rfind("qdd_", 0) == 0) return {{"rad/s^2", 1.0}, {"deg/s^2", kRadPerDeg}};
  if (target.rfind("qd_", 0) == 0) return {{"rad/s", 1.0}, {"deg/s", kRadPerDeg}};
  if (target.rfind("q_", 0) == 0) return {{"rad", 1.0}, {"deg", kRadPerDeg}};
  if (target.rfind("emg_", 0) == 0) return {{"V", 1.0}, {"mV", 1e-3}};
  return {{"N m", 1.0}};
}

ColumnSpec ReadSpec(const YamlContext& c, const std::string& target, const YAML::Node& n) {
  const std::string key = "columns." + target;
  ColumnSpec s;
  s.target = target;
  s.line = n.Mark().line + 1;
  if (n.IsScalar()) {
    s.from = n.Scalar();  // shorthand `q_hip: pos_meas1`
  } else {
    YamlCheckKeys(c, n, key, {"from", "scale", "offset", "unit", "sign"});
    if (!n["from"] || !n["from"].IsScalar())
      c.Fail(key + ".from", "missing, expected the name of the source column" + YamlLine(n));
    s.from = n["from"].Scalar();
    if (n["scale"]) {
      s.scale = YamlNumber(c, n["scale"], key + ".scale", -1e12, 1e12, "");
      if (s.scale == 0) c.Fail(key + ".scale", "expected a non-zero number, got 0" + YamlLine(n["scale"]));
    }
    if (n["offset"]) s.offset = YamlNumber(c, n["offset"], key + ".offset", -1e12, 1e12, "");
    if (n["sign"]) {
      s.sign = YamlNumber(c, n["sign"], key + ".sign", -1e12, 1e12, "");
      if (s.sign != 1 && s.sign != -1)
        c.Fail(key + ".sign", "expected +1 or -1, got " + n["sign"].Scalar() + YamlLine(n["sign"]));
    }
    if (n["unit"]) {
      const YAML::Node u = n["unit"];
      std::string list;
      bool found = false;
      for (const Unit& unit : UnitsOf(target)) {
        list += (list.empty() ? "" : ", ") + std::string(unit.name);
        if (u.IsScalar() && u.Scalar() == unit.name) s.unit = unit.name, s.to_si = unit.to_si, found = true;
      }
      if (!found)
        c.Fail(key + ".unit", "'" + (u.IsScalar() ? u.Scalar() : std::string("?")) + "' is not a unit of " +
                                  target + ", expected one of: " + list + YamlLine(u));
    }
  }
  if (s.from.empty()) c.Fail(key + ".from", "empty, expected the name of the source column" + YamlLine(n));
  return s;
}

// "tau_hip <- -1 * tau_meas1", "q_knee <- pos2 + 90 [deg]".
std::string Describe(const ColumnSpec& s) {
  std::string d = s.target + " <- ";
  if (s.sign < 0) d += "-";
  if (s.scale != 1) d += NumberText(s.scale) + " * ";
  d += s.from;
  if (s.offset != 0) d += " + " + NumberText(s.offset);
  if (!s.unit.empty()) d += " [" + s.unit + "]";
  return d;
}

// Rows that repeat the previous row's time stamp, per `map.duplicates`; `t` is table column 0.
void MergeRepeatedTimes(const ColumnMap& map, const std::string& source, CsvTable* tab, MapReport* rep) {
  const size_t n = tab->rows(), cols = tab->columns.size();
  std::vector<size_t> count;
  size_t w = 0;  // rows kept so far
  for (size_t r = 0; r < n; ++r) {
    const bool repeat = w > 0 && tab->columns[0][r] == tab->columns[0][w - 1];
    if (!repeat) {
      for (size_t c = 0; c < cols; ++c) tab->columns[c][w] = tab->columns[c][r];
      tab->line_of_row[w] = tab->line_of_row[r];
      count.push_back(1);
      ++w;
      continue;
    }
    if (map.duplicates == DuplicateTimes::kError)
      throw InputError(source + ":" + std::to_string(tab->line_of_row[r]) + ": column '" + map.columns[0].from +
                       "' (t): time stamp " + NumberText(tab->columns[0][r]) + " repeats the one on line " +
                       std::to_string(tab->line_of_row[w - 1]) + ", expected distinct time stamps (" +
                       map.source + ": time.duplicates is error; average or first merge them)");
    if (count[w - 1] == 1) ++rep->repeated_stamps;
    ++rep->rows_merged;
    if (rep->repeated_lines.size() < 5) rep->repeated_lines.push_back(tab->line_of_row[r]);
    if (map.duplicates == DuplicateTimes::kAverage)
      for (size_t c = 1; c < cols; ++c) tab->columns[c][w - 1] += tab->columns[c][r];  // summed, divided below
    ++count[w - 1];
  }
  for (size_t c = 0; c < cols; ++c) tab->columns[c].resize(w);
  tab->line_of_row.resize(w);
  if (map.duplicates == DuplicateTimes::kAverage)
    for (size_t r = 0; r < w; ++r)
      if (count[r] > 1)
        for (size_t c = 1; c < cols; ++c) tab->columns[c][r] /= static_cast<double>(count[r]);
}

void StepStatistics(const std::vector<double>& t, MapReport* rep) {
  if (t.size() < 2) return;
  std::vector<double> dt(t.size() - 1);
  for (size_t i = 0; i + 1 < t.size(); ++i) dt[i] = t[i + 1] - t[i];
  double mean = 0, var = 0;
  for (double d : dt) mean += d;
  mean /= static_cast<double>(dt.size());
  for (double d : dt) var += (d - mean) * (d - mean);
  var /= static_cast<double>(dt.size());
  std::sort(dt.begin(), dt.end());
  rep->dt_median = Percentile(dt, 0.5);
  rep->dt_min = dt.front();
  rep->dt_max = dt.back();
  rep->dt_p99 = Percentile(dt, 0.99);
  rep->jitter = rep->dt_median > 0 ? std::sqrt(var) / rep->dt_median : 0.0;
}

}  // namespace

std::string MapReport::Summary() const {
  std::string s = "map " + map + " on " + input + ": " + std::to_string(rows_in) + " rows in, " +
                  std::to_string(rows_out) + " out\n  columns: ";
  for (size_t i = 0; i < mapped.size(); ++i) s += (i ? "; " : "") + mapped[i];
  s += "\n  repeated time stamps: ";
  if (repeated_stamps == 0) {
    s += "none";
  } else {
    s += std::to_string(repeated_stamps) + " (" + std::to_string(rows_merged) + " rows merged by " + duplicates +
         "; lines";
    for (int l : repeated_lines) s += " " + std::to_string(l);
    if (rows_merged > repeated_lines.size()) s += " ...";
    s += ")";
  }
  s += "\n  time step: median " + NumberText(dt_median * 1e3) + " ms, min " + NumberText(dt_min * 1e3) + " ms, max " +
       NumberText(dt_max * 1e3) + " ms, p99 " + NumberText(dt_p99 * 1e3) + " ms; jitter " + NumberText(100 * jitter) +
       " % of the median (std of the step)\n";
  return s;
}

ColumnMap ReadColumnMap(const std::string& path) {
  const YAML::Node root = ParseYaml(ReadYamlText(path, "column map"), path);
  const YamlContext c{path};
  if (!root || root.IsNull())
    throw InputError(path + ": empty column map, expected columns: with t, q_hip, q_knee, tau_hip, tau_knee");
  if (!root.IsMap()) throw InputError(path + ": expected a YAML mapping at the top level (columns:, time:)");
  YamlCheckKeys(c, root, "", {"columns", "time"});
  ColumnMap m;
  m.source = path;
  const YAML::Node cols = root["columns"];
  if (!cols) c.Fail("columns", "missing, expected a mapping from schema columns to source columns");
  YamlCheckKeys(c, cols, "columns", IsTarget, kTargets);
  for (const auto& kv : cols) m.columns.push_back(ReadSpec(c, kv.first.Scalar(), kv.second));
  std::vector<ColumnSpec> ordered;
  // A map of a one-joint device's log (DESIGN.md "One-joint devices") targets no hip column.
  const bool one_joint = std::none_of(m.columns.begin(), m.columns.end(), [](const ColumnSpec& s) {
    return s.target.size() > 4 && s.target.compare(s.target.size() - 4, 4, "_hip") == 0;
  });
  for (const char* req : kRequired) {
    if (one_joint && (std::string(req) == "q_hip" || std::string(req) == "tau_hip")) continue;
    const auto it = std::find_if(m.columns.begin(), m.columns.end(),
                                 [&](const ColumnSpec& s) { return s.target == req; });
    if (it == m.columns.end())
      c.Fail("columns", "missing required target '" + std::string(req) +
                            (one_joint ? "', expected t, q_knee and tau_knee (a one-joint map) or t, q_hip, "
                                         "q_knee, tau_hip and tau_knee"
                                       : "', expected t, q_hip, q_knee, tau_hip and tau_knee") +
                            YamlLine(cols));
    ordered.push_back(*it);
  }
  for (const ColumnSpec& s : m.columns)
    if (!IsRequired(s.target)) ordered.push_back(s);
  m.columns = std::move(ordered);
  if (const YAML::Node time = root["time"]) {
    YamlCheckKeys(c, time, "time", {"duplicates"});
    if (const YAML::Node d = time["duplicates"]) {
      const std::string v = d.IsScalar() ? d.Scalar() : "";
      if (v == "average") m.duplicates = DuplicateTimes::kAverage;
      else if (v == "first") m.duplicates = DuplicateTimes::kFirst;
      else if (v == "error") m.duplicates = DuplicateTimes::kError;
      else c.Fail("time.duplicates", "'" + v + "' is not one of: average, first, error" + YamlLine(d));
    }
  }
  return m;
}

MeasuredData ApplyColumnMap(const ColumnMap& map, const CsvTable& in, const std::string& source,
                            MapReport* report, size_t min_samples) {
  MapReport rep;
  rep.map = map.source;
  rep.input = source;
  rep.rows_in = in.rows();
  rep.duplicates = map.duplicates == DuplicateTimes::kAverage ? "average"
                   : map.duplicates == DuplicateTimes::kFirst ? "first"
                                                              : "error";
  CsvTable out;
  out.line_of_row = in.line_of_row;
  for (const ColumnSpec& s : map.columns) {
    const int c = in.Find(s.from);
    if (c < 0) {
      std::string have;
      for (const std::string& name : in.names) have += (have.empty() ? "" : ", ") + name;
      throw InputError(map.source + ": columns." + s.target + ".from (line " + std::to_string(s.line) +
                       "): missing required column '" + s.from + "' in " + source +
                       ", expected one of its columns: " + have);
    }
    std::vector<double> v(in.rows());
    for (size_t r = 0; r < v.size(); ++r) {
      const double x = s.sign * s.scale * in.columns[c][r] + s.offset;  // in s.unit
      if (s.unit == "deg" && std::abs(x) > kMaxDegrees)
        throw InputError(source + ":" + std::to_string(in.line_of_row[r]) + ": column '" + s.from + "' (" +
                         s.target + " in deg, " + map.source + " line " + std::to_string(s.line) + "): " +
                         NumberText(x) + " deg is beyond +-720 deg, expected an angle in degrees (is the unit right?)");
      v[r] = s.to_si * x;
    }
    out.names.push_back(s.target);
    out.columns.push_back(std::move(v));
    rep.mapped.push_back(Describe(s));
  }
  MergeRepeatedTimes(map, source, &out, &rep);
  MeasuredData d;
  try {
    d = MeasuredFromTable(std::move(out), source, min_samples);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (after the column map " + map.source + ")");
  }
  rep.rows_out = d.size();
  StepStatistics(d.t(), &rep);
  if (report) *report = rep;
  return d;
}

MeasuredData ReadMeasured(const std::string& csv_path, const std::string& map_path, size_t min_samples,
                          MapReport* report, const MeasuredColumns& keep) {
  const bool bag = IsBagPath(csv_path);
  if (bag && map_path.empty())
    throw InputError(csv_path + ": a ROS 2 bag needs a column map (--map MAP.yaml) naming the topics' fields, "
                                "e.g. t: {from: /exo/joint_states.header.stamp}, q_hip: {from: "
                                "\"/exo/joint_states.position[hip]\"} (DESIGN.md \"ROS 2 bags (MCAP) in and out\")");
  if (map_path.empty()) return ReadMeasuredCsv(csv_path, min_samples, keep);
  const ColumnMap map = ReadColumnMap(map_path);
  return ApplyColumnMap(map, bag ? BagTable(csv_path, map) : ReadCsv(csv_path), csv_path, report, min_samples);
}

}  // namespace exotwin
