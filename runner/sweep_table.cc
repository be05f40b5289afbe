#include "runner/sweep_table.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <iterator>
#include <tuple>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "formats/csv_table.h"
#include "dsp/statistics.h"
#include "core/output_path.h"
#include "core/error.h"
#include "core/file_text.h"
#include "runner/sweep_plots.h"

namespace exotwin {
namespace {

const char* const kFixed[] = {"scenario", "subject", "subject_seed", "status", "checks_failed"};

std::string Num(double v) {
  if (std::isnan(v)) return "nan";
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string Quote(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

void SortRows(const SweepManifest& m, std::vector<SweepRow>* rows) {
  std::map<std::string, size_t> order;
  for (size_t i = 0; i < m.scenarios.size(); ++i) order.emplace(m.scenarios[i], i);
  auto key = [&](const SweepRow& r) {
    auto it = order.find(r.scenario);
    return std::make_tuple(it != order.end() ? it->second : order.size(), r.scenario, r.subject);
  };
  std::stable_sort(rows->begin(), rows->end(), [&](const SweepRow& a, const SweepRow& b) { return key(a) < key(b); });
}

std::string SweepCsv(const std::vector<SweepRow>& rows) {
  std::set<std::string> cols;
  for (const SweepRow& r : rows)
    for (const auto& kv : r.values) cols.insert(kv.first);
  std::string out;
  for (const char* f : kFixed) out += std::string(out.empty() ? "" : ",") + f;
  for (const std::string& c : cols) out += "," + Quote(c);
  out += "\n";
  for (const SweepRow& r : rows) {
    out += Quote(r.scenario) + "," + std::to_string(r.subject) + "," + std::to_string(r.subject_seed) + "," +
           Quote(r.status) + "," + std::to_string(r.checks_failed);
    for (const std::string& c : cols) {
      auto it = r.values.find(c);
      out += "," + (it != r.values.end() ? Num(it->second) : std::string());
    }
    out += "\n";
  }
  return out;
}

std::vector<SweepRow> ParseSweepCsv(const std::string& text, const std::string& source) {
  CsvReader in(text, source);
  if (!in.ReadHeader()) throw InputError(source + ": empty, expected a sweep CSV with a header row");
  const std::vector<std::string>& header = in.names();
  for (size_t i = 0; i < std::size(kFixed); ++i)
    if (header.size() <= i || header[i] != kFixed[i])
      throw InputError(in.Where() + "expected the sweep header starting scenario,subject,subject_seed,status,checks_failed");
  std::vector<SweepRow> rows;
  while (in.NextRow()) {
    auto fail = [&](const std::string& what) { throw InputError(in.Where() + what); };
    SweepRow r;
    r.scenario = in.field(0);
    try {
      const std::string subject(in.field(1)), seed(in.field(2)), checks(in.field(4));
      size_t pos = 0;
      r.subject = std::stoi(subject, &pos);
      if (pos != subject.size() || r.subject < 0) throw std::invalid_argument("");
      r.subject_seed = std::stoull(seed, &pos);
      if (pos != seed.size()) throw std::invalid_argument("");
      r.checks_failed = std::stoi(checks, &pos);
      if (pos != checks.size()) throw std::invalid_argument("");
    } catch (const std::exception&) {
      fail("subject, subject_seed and checks_failed: expected non-negative integers");
    }
    r.status = in.field(3);
    for (size_t i = std::size(kFixed); i < header.size(); ++i) {
      if (in.field(i).empty()) continue;  // no value of this metric in this run
      double v = 0;
      if (!in.Number(i, &v))
        fail("column " + header[i] + ": '" + std::string(in.field(i)) + "', expected a number");
      r.values[header[i]] = v;
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

std::string SweepSummaryJson(const SweepManifest& m, const std::vector<SweepRow>& rows) {
  nlohmann::ordered_json j;
  j["subjects"] = m.subjects;
  j["seed"] = m.seed;
  j["scenarios"] = nlohmann::ordered_json::object();
  for (const std::string& sc : m.scenarios) {
    nlohmann::ordered_json s;
    std::map<std::string, int> statuses;
    std::map<std::string, std::vector<double>> cols;
    int runs = 0;
    for (const SweepRow& r : rows) {
      if (r.scenario != sc) continue;
      ++runs;
      ++statuses[r.status];
      if (r.status != "ok" && r.status != "check_failed") continue;
      for (const auto& kv : r.values)
        if (!std::isnan(kv.second)) cols[kv.first].push_back(kv.second);
    }
    s["runs"] = runs;
    s["status"] = statuses;
    s["metrics"] = nlohmann::ordered_json::object();
    for (auto& [name, v] : cols) {
      double sum = 0;
      for (double x : v) sum += x;
      const double mean = sum / v.size();
      double ss = 0;
      for (double x : v) ss += (x - mean) * (x - mean);
      std::vector<double> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      nlohmann::ordered_json st;
      st["n"] = v.size();
      st["mean"] = mean;
      st["sd"] = v.size() > 1 ? std::sqrt(ss / (v.size() - 1)) : 0.0;
      st["min"] = sorted.front();
      st["max"] = sorted.back();
      st["p5"] = Percentile(sorted, 0.05);
      st["p95"] = Percentile(sorted, 0.95);
      s["metrics"][name] = st;
    }
    j["scenarios"][sc] = s;
  }
  return j.dump(2) + "\n";
}

std::string ManifestJson(const SweepManifest& m, size_t rows) {
  nlohmann::ordered_json j;
  j["scenarios"] = m.scenarios;
  j["files"] = m.files;
  j["subjects"] = m.subjects;
  j["seed"] = m.seed;
  j["shard"] = m.shard ? nlohmann::ordered_json(m.shard->ToString()) : nlohmann::ordered_json(nullptr);
  j["rows"] = rows;
  return j.dump(2) + "\n";
}

SweepManifest ParseManifestJson(const std::string& text, const std::string& source) {
  SweepManifest m;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    m.scenarios = j.at("scenarios").get<std::vector<std::string>>();
    m.files = j.at("files").get<std::vector<std::string>>();
    m.subjects = j.at("subjects").get<int>();
    m.seed = j.at("seed").get<uint64_t>();
    if (!j.at("shard").is_null()) m.shard = ParseShard(j.at("shard").get<std::string>());
  } catch (const InputError& e) {
    throw InputError(source + ": shard: " + e.what());
  } catch (const std::exception& e) {
    throw InputError(source + ": expected a sweep manifest {scenarios, files, subjects, seed, shard} (" + e.what() + ")");
  }
  return m;
}

void WriteSweepAggregate(const std::string& dir, const SweepManifest& m, std::vector<SweepRow> rows) {
  SortRows(m, &rows);
  CreateOutputFolder(dir + "/plots");
  WriteFileAtomic(dir + "/sweep.csv", SweepCsv(rows));
  WriteFileAtomic(dir + "/summary.json", SweepSummaryJson(m, rows));
  WriteFileAtomic(dir + "/sweep.json", ManifestJson(m, rows.size()));
  for (const std::string& sc : m.scenarios)
    WriteFileAtomic(dir + "/plots/" + PlotFileName(sc), SweepHistogramsSvg(sc, rows));
}

void ReadSweepAggregate(const std::string& dir, SweepManifest* m, std::vector<SweepRow>* rows) {
  *m = ParseManifestJson(ReadTextFile(dir + "/sweep.json", "sweep manifest", "a JSON text file"), dir + "/sweep.json");
  *rows = ParseSweepCsv(ReadTextFile(dir + "/sweep.csv", "sweep table", "a text CSV file"), dir + "/sweep.csv");
}

}  // namespace exotwin
