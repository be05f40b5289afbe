#include "batch/sweep_run.h"

#include <chrono>
#include <set>

#include "core/error.h"
#include "batch/fork_pool.h"
#include "runner/progress_bar.h"
#include "sim/subjects.h"

namespace exotwin {

SweepRow MakeSweepRow(const std::string& scenario, uint64_t seed, int subject, const JobRun& run) {
  SweepRow r;
  r.scenario = scenario;
  r.subject = subject;
  r.subject_seed = SubjectSeed(seed, subject);
  r.status = run.status;
  for (const CheckResult& c : run.checks) r.checks_failed += c.passed ? 0 : 1;
  const Subject s = DrawSubject(seed, subject);
  r.values["subject_weight_kg"] = s.weight;
  r.values["subject_height_m"] = s.height;
  r.values["subject_age_y"] = s.age;
  r.values["subject_L1_m"] = s.L1;
  r.values["subject_L2_m"] = s.L2;
  for (const auto& kv : run.metrics)
    if (IsDeterministicMetric(kv.first)) r.values[kv.first] = kv.second;
  return r;
}

SweepOutcome RunSweep(const SweepOptions& opt) {
  if (opt.subjects < 1) throw InputError("--subjects: expected >= 1, got " + std::to_string(opt.subjects));
  if (opt.jobs < 0) throw InputError("--jobs: expected >= 1 (0 = number of cores), got " + std::to_string(opt.jobs));
  if (opt.scenario_files.empty()) throw InputError("--scenario: expected at least one scenario file");
  std::vector<Scenario> scenarios;
  SweepOutcome out;
  SweepManifest& m = out.manifest;
  std::set<std::string> names;
  for (const std::string& f : opt.scenario_files) {
    scenarios.push_back(ReadScenario(f));
    if (!names.insert(scenarios.back().name).second)
      throw InputError(f + ": name: '" + scenarios.back().name + "' given twice, expected distinct scenarios");
    m.scenarios.push_back(scenarios.back().name);
    m.files.push_back(f);
  }
  m.subjects = opt.subjects;
  m.seed = opt.seed;
  if (opt.sharded) m.shard = opt.shard;

  for (const Scenario& s : scenarios) {  // every job's scenario checked before the first job starts
    RunOptions ro;
    ro.out_dir = opt.out_dir;
    CheckScenarioRun(WithPopulationSubject(s, opt.seed, 0), ro);
  }
  for (const Scenario& s : scenarios) KeepScenarioModel(s);  // loaded once: the workers inherit it
  const std::vector<SweepJob> jobs = PlanSweep(scenarios.size(), opt.subjects, opt.shard);
  auto dir_of = [&](const SweepJob& j) {
    return opt.out_dir + "/runs/" + scenarios[j.scenario].name + "/subject_" + std::to_string(j.subject);
  };
  const auto t0 = std::chrono::steady_clock::now();
  ProgressBar bar(jobs.size(), "sweep", opt.progress);
  size_t done = 0, bad = 0;
  const auto outcomes = RunForked(
      jobs.size(), opt.jobs > 0 ? opt.jobs : DefaultWorkers(),
      [&](size_t i) {
        Scenario s = WithPopulationSubject(scenarios[jobs[i].scenario], opt.seed, jobs[i].subject);
        s.log_measured_csv = opt.logs;
        RunOptions ro;
        ro.out_dir = dir_of(jobs[i]);
        return RunScenarioJob(s, ro);
      },
      [&](size_t, const JobOutcome& o) {
        ++done;
        bad += o.exit_code != 0;
        bar.Update(done, bad);
      });
  bar.Finish();
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  for (size_t i = 0; i < jobs.size(); ++i) {
    const JobRun run = ReadJobRun(dir_of(jobs[i]), outcomes[i]);
    const std::string& name = scenarios[jobs[i].scenario].name;
    out.rows.push_back(MakeSweepRow(name, opt.seed, jobs[i].subject, run));
    if (run.status == "input_error") ++out.input_errors;
    if (!run.completed()) ++out.failed_runs;
    if (run.status == "check_failed") ++out.check_failures;
    if (!run.completed())
      out.problems.push_back(name + " subject " + std::to_string(jobs[i].subject) + ": " + run.status + ": " + run.error);
  }
  WriteSweepAggregate(opt.out_dir, m, out.rows);
  SortRows(m, &out.rows);
  return out;
}

}  // namespace exotwin
