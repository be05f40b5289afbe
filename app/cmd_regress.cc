// `exotwin regress [--suite DIR] [--baselines DIR] [--update] [--out DIR] [--jobs J] [--all]`:
// the controller-regression gate. Runs every scenario of the suite (one process each, J at a time),
// compares its deterministic metrics with DIR/baselines/<name>.json, prints what moved, writes
// OUT/regress.json; exit 1 on a regression, a failed check, a failed run or a missing baseline.
// --update rewrites the baselines from this run (keeping tolerance overrides) and exits 0 unless a
// run failed.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <optional>

#include <unistd.h>

#include "formats/csv_table.h"
#include "app/bench_probes.h"  // ScopedCpuPin
#include "app/commands.h"
#include "core/output_path.h"
#include "core/data_dir.h"
#include "core/error.h"
#include "batch/controller_process.h"
#include "batch/fork_pool.h"
#include "runner/progress_bar.h"
#include "batch/regress.h"

namespace exotwin {
namespace {

CommandRunner RegisterRegress(CLI::App& app) {
  struct Opts {
    std::string suite, baselines, out = "out/regress";  // suite: default scenarios/ of the data folder
    bool update = false, all = false, controller_process = false;
    std::string controller_bin;
    int jobs = 0;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("regress", "Controller regression: run the scenario suite, compare with baselines");
  sub->add_option("--suite", o->suite, "folder of scenario YAML files (recursive; default: the shipped scenarios/)");
  sub->add_option("--baselines", o->baselines, "folder of baseline JSON files (default: SUITE/baselines)");
  sub->add_flag("--update", o->update, "rewrite the baselines from this run");
  sub->add_option("--out", o->out, "output folder (one sub-folder per scenario, regress.json)");
  sub->add_option("--jobs,-j", o->jobs, "scenarios run in parallel (default: number of cores)");
  sub->add_flag("--all", o->all, "print every metric, not only those that moved");
  sub->add_flag("--controller-process", o->controller_process,
                "run every scenario with exotwin-controller in another process, in lockstep");
  sub->add_option("--controller-bin", o->controller_bin, "the exotwin-controller executable (default: next to exotwin)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    if (o->jobs < 0) throw InputError("--jobs: expected >= 1 (or 0 for the number of cores), got " + std::to_string(o->jobs));
    if (o->suite.empty()) o->suite = DataPath("scenarios");
    const std::vector<SuiteEntry> suite = ListSuite(o->suite);
    const std::string baselines = o->baselines.empty() ? o->suite + "/baselines" : o->baselines;
    std::string controller_bin;
    if (o->controller_process) {
      controller_bin = o->controller_bin.empty() ? DefaultControllerBinary() : o->controller_bin;
      if (controller_bin.empty() || ::access(controller_bin.c_str(), X_OK) != 0)
        throw InputError("--controller-bin: '" + controller_bin + "': no exotwin-controller executable there");
    }
    CreateOutputFolder(o->out);
    auto dir_of = [&](size_t i) { return o->out + "/" + suite[i].scenario.name; };

    for (size_t i = 0; i < suite.size(); ++i) {  // every job's scenario checked before the first job starts
      RunOptions opt;
      opt.out_dir = dir_of(i);
      CheckScenarioRun(suite[i].scenario, opt);
    }
    for (const SuiteEntry& e : suite) KeepScenarioModel(e.scenario);  // loaded once: the workers inherit it
    const int workers = o->jobs > 0 ? o->jobs : DefaultWorkers();
    const std::vector<int> cpus = AllowedCpus();
    const bool pin_workers = !controller_bin.empty() && workers > 1 && cpus.size() > 1;
    ProgressBar bar(suite.size(), "regress");
    size_t done = 0, failed = 0;
    const auto outcomes = RunForked(
        suite.size(), workers,
        [&](size_t i) {
          // --controller-process: each worker, with the controller it starts, on a CPU of its own
          // (ForkWorkerSlot): the lockstep hand-over between the two processes is then a switch on
          // one CPU, not a wake-up of another (tens of us on a virtual machine), and two workers'
          // pairs do not take each other's CPUs.
          const ScopedCpuPin pin(pin_workers ? cpus[static_cast<size_t>(ForkWorkerSlot()) % cpus.size()] : -1);
          RunOptions opt;
          opt.out_dir = dir_of(i);
          opt.controller_process = controller_bin;
          return RunScenarioJob(suite[i].scenario, opt);
        },
        [&](size_t, const JobOutcome& r) {
          ++done;
          failed += r.exit_code != 0;
          bar.Update(done, failed);
        });
    bar.Finish();

    std::vector<ScenarioRegression> results;
    bool input_error = false, run_failed = false;
    for (size_t i = 0; i < suite.size(); ++i) {
      const JobRun run = ReadJobRun(dir_of(i), outcomes[i]);
      if (run.status == "input_error") {
        std::fprintf(stderr, "exotwin: error: %s\n", run.error.c_str());
        input_error = true;
      }
      run_failed |= !run.completed();
      results.push_back(EvaluateRegression(suite[i], run, baselines));
    }
    if (input_error) return 2;

    if (o->update) {
      for (size_t i = 0; i < suite.size(); ++i) {
        if (!results[i].run.completed()) continue;
        const std::string path = results[i].baseline_path;
        std::optional<Baseline> prev;
        if (std::filesystem::exists(path)) prev = ReadBaseline(path);
        WriteBaseline(BaselineFromRun(suite[i], results[i].run, prev ? &*prev : nullptr), path);
        std::printf("%-30s baseline written: %s%s\n", results[i].name.c_str(), path.c_str(),
                    results[i].failed_checks.empty() ? "" : " (note: a check failed in this run)");
      }
      WriteFileAtomic(o->out + "/regress.json", RegressionJson(results));
      return run_failed ? 1 : 0;
    }

    std::fputs(FormatRegressionReport(results, o->all).c_str(), stdout);
    WriteFileAtomic(o->out + "/regress.json", RegressionJson(results));
    for (const auto& r : results)
      if (r.failed()) return 1;
    return 0;
  };
}

const CommandRegistration kRegress(RegisterRegress);

}  // namespace
}  // namespace exotwin
