#include "batch/regress.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "core/error.h"

namespace exotwin {

namespace fs = std::filesystem;

std::vector<SuiteEntry> ListSuite(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir + ": --suite: expected a folder of scenario YAML files");
  std::vector<std::string> files;
  for (auto it = fs::recursive_directory_iterator(dir, ec); it != fs::recursive_directory_iterator(); ++it) {
    const fs::path& p = it->path();
    const std::string base = p.filename().string();
    if (it->is_directory() && (base == "baselines" || base == "known_gaps" || base[0] == '.')) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && p.extension() == ".yaml" && base[0] != '.') files.push_back(p.string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir + ": --suite: no *.yaml scenario file in this folder");
  std::vector<SuiteEntry> out;
  std::map<std::string, std::string> names;
  for (const std::string& f : files) {
    SuiteEntry e;
    e.path = f;
    e.relative = fs::relative(f, dir).string();
    e.scenario = ReadScenario(f);
    auto [it, fresh] = names.emplace(e.scenario.name, f);
    if (!fresh)
      throw InputError(f + ": name: '" + e.scenario.name + "' is also the name of " + it->second +
                       ", expected unique scenario names in a suite (they key the baselines)");
    out.push_back(std::move(e));
  }
  return out;
}

bool ScenarioRegression::regressed() const {
  return std::any_of(deltas.begin(), deltas.end(), [](const MetricDelta& d) { return IsFailure(d.verdict); });
}

bool ScenarioRegression::failed() const {
  return !run.completed() || !has_baseline || regressed() || !failed_checks.empty();
}

namespace {

std::map<std::string, double> Deterministic(const std::map<std::string, double>& m) {
  std::map<std::string, double> out;
  for (const auto& kv : m)
    if (IsDeterministicMetric(kv.first)) out.insert(kv);
  return out;
}

}  // namespace

ScenarioRegression EvaluateRegression(const SuiteEntry& e, const JobRun& run, const std::string& baseline_dir) {
  ScenarioRegression r;
  r.name = e.scenario.name;
  r.source = e.relative;
  r.baseline_path = baseline_dir + "/" + r.name + ".json";
  r.run = run;
  for (const CheckResult& c : run.checks)
    if (!c.passed) r.failed_checks.push_back(c);
  std::error_code ec;
  r.has_baseline = fs::exists(r.baseline_path, ec);
  if (r.has_baseline && run.completed()) {
    const Baseline b = ReadBaseline(r.baseline_path);
    r.deltas = CompareMetrics(Deterministic(b.metrics), Deterministic(run.metrics), b.tolerance);
  }
  return r;
}

Baseline BaselineFromRun(const SuiteEntry& e, const JobRun& run, const Baseline* previous) {
  Baseline b;
  b.scenario = e.scenario.name;
  b.source = e.relative;
  b.seed = e.scenario.seed;
  b.metrics = Deterministic(run.metrics);
  if (previous) b.tolerance = previous->tolerance;
  return b;
}

namespace {

std::string Num(double v) {
  if (std::isnan(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

}  // namespace

std::string FormatRegressionReport(const std::vector<ScenarioRegression>& results, bool show_all) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof(line), "%-30s %-30s %12s %12s %12s %10s  %s\n", "scenario", "metric", "baseline", "now",
                "delta", "tolerance", "verdict");
  out += line;
  int failed = 0, moved_total = 0;
  for (const ScenarioRegression& r : results) {
    std::string status;
    if (!r.run.completed()) status = "RUN FAILED (" + r.run.status + "): " + r.run.error;
    else if (!r.has_baseline) status = "NO BASELINE: " + r.baseline_path + " (run with --update to create it)";
    int moved = 0, beyond = 0;
    for (const MetricDelta& d : r.deltas) {
      if (d.verdict != Verdict::kSame) ++moved;
      if (IsFailure(d.verdict)) ++beyond;
      if (!show_all && d.verdict == Verdict::kSame) continue;
      std::snprintf(line, sizeof(line), "%-30s %-30s %12s %12s %12s %10s  %s\n", r.name.c_str(), d.metric.c_str(),
                    Num(d.baseline).c_str(), Num(d.now).c_str(), Num(d.delta).c_str(), Num(d.tolerance).c_str(),
                    VerdictName(d.verdict));
      out += line;
    }
    moved_total += moved;
    for (const CheckResult& c : r.failed_checks) {
      std::snprintf(line, sizeof(line), "%-30s check FAILED: %s: %s = %.6g, limit %s %.6g\n", r.name.c_str(),
                    c.name.c_str(), c.metric.c_str(), c.value, c.op.c_str(), c.limit);
      out += line;
    }
    if (status.empty()) {
      status = r.failed() ? "FAIL" : "ok";
      status += " (" + std::to_string(r.deltas.size()) + " metrics, " + std::to_string(moved) + " moved, " +
                std::to_string(beyond) + " beyond tolerance, " + std::to_string(r.failed_checks.size()) +
                " checks failed)";
    }
    std::snprintf(line, sizeof(line), "%-30s %s\n", r.name.c_str(), status.c_str());
    out += line;
    if (r.failed()) ++failed;
  }
  std::snprintf(line, sizeof(line), "regress: %zu scenarios, %d failed, %d metrics moved in all\n", results.size(),
                failed, moved_total);
  out += line;
  return out;
}

std::string RegressionJson(const std::vector<ScenarioRegression>& results) {
  nlohmann::ordered_json j;
  j["passed"] = std::none_of(results.begin(), results.end(), [](const ScenarioRegression& r) { return r.failed(); });
  j["scenarios"] = nlohmann::ordered_json::array();
  for (const ScenarioRegression& r : results) {
    nlohmann::ordered_json s;
    s["name"] = r.name;
    s["source"] = r.source;
    s["baseline"] = r.baseline_path;
    s["has_baseline"] = r.has_baseline;
    s["run_status"] = r.run.status;
    if (!r.run.error.empty()) s["error"] = r.run.error;
    s["regressed"] = r.regressed();
    s["failed"] = r.failed();
    s["failed_checks"] = nlohmann::ordered_json::array();
    for (const CheckResult& c : r.failed_checks)
      s["failed_checks"].push_back({{"name", c.name}, {"metric", c.metric}, {"value", c.value}, {"op", c.op},
                                    {"limit", c.limit}});
    s["metrics"] = nlohmann::ordered_json::array();
    for (const MetricDelta& d : r.deltas)
      s["metrics"].push_back({{"metric", d.metric}, {"baseline", d.baseline}, {"now", d.now}, {"delta", d.delta},
                              {"tolerance", d.tolerance}, {"verdict", VerdictName(d.verdict)}});
    j["scenarios"].push_back(s);
  }
  return j.dump(2) + "\n";
}

}  // namespace exotwin
