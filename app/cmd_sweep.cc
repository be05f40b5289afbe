// `exotwin sweep --scenario S.yaml [--scenario ...] --subjects N [--seed K] [--jobs J]
//                [--shard K/N] [--logs] --out DIR`
// Runs the scenarios over virtual subjects 0..N-1 of the population with seed K (one process per
// run, J at a time, progress bar with ETA on a terminal); writes DIR/sweep.csv, summary.json,
// sweep.json and plots/*.svg (scenarios/sweep_table.h). --shard K/N runs only the subjects with
// i mod N == K; `exotwin merge` joins the parts. Exit 0 when every run completed and passed its
// checks, 1 if a check failed or a run diverged/crashed (the aggregate is written anyway), 2 on bad input.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "app/commands.h"
#include "core/error.h"
#include "runner/progress_bar.h"
#include "batch/sweep_run.h"

namespace exotwin {
namespace {

CommandRunner RegisterSweep(CLI::App& app) {
  auto o = std::make_shared<SweepOptions>();
  auto shard = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand("sweep", "Run scenarios over a population of virtual subjects, in parallel");
  sub->add_option("--scenario", o->scenario_files, "scenario YAML (repeatable)")->required();
  sub->add_option("--subjects", o->subjects, "number of virtual subjects N (population draws 0..N-1)")->required();
  sub->add_option("--seed", o->seed, "population seed K (default 1)");
  sub->add_option("--jobs,-j", o->jobs, "runs in parallel (default: number of cores)");
  sub->add_option("--shard", *shard, "K/N: only subjects i with i mod N == K (0 <= K < N)");
  sub->add_flag("--logs", o->logs, "keep measured.csv / truth.csv of every run");
  sub->add_option("--out", o->out_dir, "output folder")->required();
  return [sub, o, shard]() -> int {
    if (!*sub) return -1;
    if (!shard->empty()) {
      o->shard = ParseShard(*shard);
      o->sharded = true;
    }
    const SweepOutcome r = RunSweep(*o);
    for (const std::string& p : r.problems) std::fprintf(stderr, "exotwin sweep: %s\n", p.c_str());
    if (r.input_errors > 0) return 2;
    std::printf("sweep: %zu runs (%zu scenario(s) x %d subjects%s) in %s: %zu completed, %d failed a check, %d failed\n",
                r.rows.size(), r.manifest.scenarios.size(), o->subjects,
                o->sharded ? (", shard " + o->shard.ToString()).c_str() : "",
                ProgressBar::FormatDuration(r.wall_s).c_str(), r.rows.size() - r.failed_runs, r.check_failures,
                r.failed_runs);
    std::printf("  %s/sweep.csv, %s/summary.json, %s/plots/\n", o->out_dir.c_str(), o->out_dir.c_str(),
                o->out_dir.c_str());
    return (r.failed_runs > 0 || r.check_failures > 0) ? 1 : 0;
  };
}

const CommandRegistration kSweep(RegisterSweep);

}  // namespace
}  // namespace exotwin
