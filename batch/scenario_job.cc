#include "batch/scenario_job.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "batch/controller_process.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

void WriteError(const std::string& dir, const std::string& msg) {
  std::ofstream(dir + "/error.txt") << msg << "\n";
}

std::string ReadText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  std::string s = ss.str();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

}  // namespace

bool IsDeterministicMetric(const std::string& name) {
  return name != "wall_time_s" && name.rfind("link_", 0) != 0;  // link_*: the controller link's, not the scenario's
}

int RunScenarioJob(const Scenario& s, const RunOptions& opt) {
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  std::filesystem::remove(opt.out_dir + "/error.txt", ec);
  std::filesystem::remove(opt.out_dir + "/result.json", ec);
  try {
    const bool remote = !opt.controller_process.empty();
    return (remote ? RunWithControllerProcess(s, opt, opt.controller_process) : RunScenario(s, opt)).all_passed()
               ? kJobOk
               : kJobCheckFailed;
  } catch (const InputError& e) {
    WriteError(opt.out_dir, e.what());
    return kJobInputError;
  } catch (const SimulationError& e) {
    WriteError(opt.out_dir, e.what());
    return kJobDiverged;
  } catch (const std::exception& e) {
    WriteError(opt.out_dir, std::string("internal error: ") + e.what());
    return 70;
  }
}

JobRun ReadJobRun(const std::string& dir, const JobOutcome& o) {
  JobRun r;
  if (o.signal != 0) {
    r.status = "crashed";
    r.error = std::string("killed by signal ") + std::to_string(o.signal) + " (" + strsignal(o.signal) + ")";
    return r;
  }
  if (o.exit_code != kJobOk && o.exit_code != kJobCheckFailed) {
    r.status = o.exit_code == kJobInputError ? "input_error" : o.exit_code == kJobDiverged ? "diverged" : "crashed";
    r.error = ReadText(dir + "/error.txt");
    if (r.error.empty()) r.error = "exit code " + std::to_string(o.exit_code);
    return r;
  }
  std::ifstream f(dir + "/result.json");
  nlohmann::json j;
  try {
    f >> j;
    for (auto it = j.at("metrics").begin(); it != j.at("metrics").end(); ++it)
      r.metrics[it.key()] = it.value().is_number() ? it.value().get<double>() : std::nan("");
    for (const auto& c : j.at("checks")) {
      CheckResult cr;
      cr.name = c.at("name").get<std::string>();
      cr.metric = c.value("metric", "");
      cr.op = c.value("op", "");
      cr.value = c.at("value").is_number() ? c.at("value").get<double>() : std::nan("");
      cr.limit = c.at("limit").get<double>();
      cr.passed = c.at("passed").get<bool>();
      r.checks.push_back(cr);
    }
  } catch (const std::exception& e) {
    r.status = "crashed";
    r.error = dir + "/result.json: unreadable (" + e.what() + ")";
    return r;
  }
  r.status = o.exit_code == kJobOk ? "ok" : "check_failed";
  return r;
}

}  // namespace exotwin
