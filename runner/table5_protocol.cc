#include "runner/table5_protocol.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "identification/identification.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/csv_table.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "runner/runner.h"
#include "runner/scenario.h"
#include "sim/subjects.h"

namespace exotwin {

namespace {

namespace fs = std::filesystem;

constexpr double kGaitTail = 0.2;  // s recorded after the last stride (filter edge)

// The scenario file `rel` of the folder with the subject and the trial settings substituted.
Scenario LoadStep(const Table5Options& opt, const std::string& rel, const std::string& subject) {
  const std::string dir = opt.scenario_dir.empty() ? ShippedScenarioDir() : opt.scenario_dir;
  Scenario s = ReadScenario(dir + "/" + rel);
  s.subject.preset = subject;
  s.subject.random_seed.reset();
  s.subject.params_file.clear();
  return s;
}

// Runs the scenario into `dir`, appends its failed checks to `failed` (prefixed by `tag`).
RunResult RunInto(const Scenario& s, const std::string& dir, const std::string& tag,
                  std::vector<std::string>* failed) {
  fs::remove_all(dir);
  RunOptions ro;
  ro.out_dir = dir;
  RunResult r = RunScenario(s, ro);
  for (const CheckResult& c : r.checks)
    if (!c.passed) failed->push_back(tag + ": " + c.name + " = " + std::to_string(c.value) + " (limit " + c.op + " " +
                                     std::to_string(c.limit) + ")");
  return r;
}

// Every measured*.csv of a run folder, sorted by name.
std::vector<MeasuredData> ReadRun(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("measured", 0) == 0 && e.path().extension() == ".csv") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir + ": the run wrote no measured*.csv");
  std::vector<MeasuredData> out;
  for (const std::string& f : files) out.push_back(ReadMeasuredCsv(f));
  return out;
}

void Log(const Table5Options& opt, const std::string& line) {
  if (opt.log) opt.log(line);
}

}  // namespace

std::string ShippedScenarioDir() { return DataPath("scenarios"); }

Table5SubjectRun RunTable5Subject(const std::string& subject, const Table5Options& opt) {
  if (opt.trials < 1) throw InputError("table5: --trials: expected at least 1");
  if (!(opt.trial_duration >= 5.0)) throw InputError("table5: --trial-duration: expected at least 5 s");
  if (opt.strides < 1) throw InputError("table5: --strides: expected at least 1");
  const Subject preset = PresetSubject(subject);  // throws InputError listing the valid names
  const auto wall0 = std::chrono::steady_clock::now();
  Table5SubjectRun run;
  Table5Entry& e = run.entry;
  e.subject = subject;
  const std::string base = opt.out_dir + "/" + subject;
  fs::create_directories(base);

  const char* steps[4] = {"identification/step1_exo_knee.yaml", "identification/step2_exo_hip.yaml",
                          "identification/step3_knee.yaml", "identification/step4_hip.yaml"};
  std::vector<MeasuredData> exo_files, human_files;
  for (int k = 0; k < 4; ++k) {
    Scenario s = LoadStep(opt, steps[k], subject);
    s.protocol.trials = opt.trials;
    s.protocol.duration = opt.trial_duration;
    if (k == 2) e.truth = ResolveSubject(s);  // exo + human + passive as the twin holds them
    const std::string dir = base + "/step" + std::to_string(k + 1);
    const RunResult r = RunInto(s, dir, subject + " step " + std::to_string(k + 1), &run.failed_checks);
    char line[200];
    std::snprintf(line, sizeof(line), "%s: step %d (%s) %d x %.0f s in %.1f s wall", subject.c_str(), k + 1,
                  s.name.c_str(), opt.trials, opt.trial_duration, r.metrics.at("wall_time_s"));
    Log(opt, line);
    std::vector<MeasuredData> files = ReadRun(dir);
    auto& into = k < 2 ? exo_files : human_files;
    for (MeasuredData& f : files) into.push_back(std::move(f));
    if (!opt.keep_logs) fs::remove_all(dir);
  }

  IdentificationOptions iopt;
  const IdentificationResult exo = Identify(exo_files, nullptr, preset.L1, iopt);
  WriteFileAtomic(base + "/exo.yaml", ModelToYaml(exo.params, "exotwin table5: " + subject + " steps 1-2",
                                                  IdentificationYaml(exo, iopt)));
  LegParams known = exo.params;
  const IdentificationResult human = Identify(human_files, &known, preset.L1, iopt);
  WriteFileAtomic(base + "/subject.yaml", ModelToYaml(human.params, "exotwin table5: " + subject + " steps 3-4",
                                                      IdentificationYaml(human, iopt)));
  e.identified = human.params;

  Scenario gait = LoadStep(opt, "gait_2kmh.yaml", subject);
  gait.subject.passive = PassiveModel::kRiener1999;
  gait.human.behaviour = "relaxed";
  gait.protocol.trials = 1;
  // strides x period after the ramp, plus a tail so that the derivative filter's edge stays outside.
  const double t_from = gait.protocol.ramp, t_to = t_from + opt.strides * gait.protocol.stride_period;
  gait.protocol.duration = t_to + kGaitTail;
  const std::string gdir = base + "/gait";
  RunInto(gait, gdir, subject + " gait", &run.failed_checks);
  const MeasuredData g = ReadRun(gdir).front();
  ComputeTable5Rmse(g, t_from, t_to, preset.weight, preset.L2, &e);
  if (!opt.keep_logs) fs::remove_all(gdir);
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  char line[120];
  std::snprintf(line, sizeof(line), "%s: done in %.1f s wall", subject.c_str(), run.wall_s);
  Log(opt, line);
  return run;
}

}  // namespace exotwin
