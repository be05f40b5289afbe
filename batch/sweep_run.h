// Runs a population sweep (`exotwin sweep`): every scenario over subjects 0..N-1 of the population
// (or one shard of them), one forked process per run, J at a time; writes the aggregate.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "batch/scenario_job.h"
#include "runner/sweep_table.h"

namespace exotwin {

struct SweepOptions {
  std::vector<std::string> scenario_files;
  int subjects = 0;      // N >= 1
  uint64_t seed = 1;     // population seed
  int jobs = 0;          // parallel runs; 0 = number of cores
  Shard shard;           // {0, 1} = everything
  bool sharded = false;  // record the shard in the manifest (--shard given)
  std::string out_dir = "out/sweep";
  bool logs = false;     // also write each run's measured.csv / truth.csv
  bool progress = true;  // progress bar on stderr (only drawn on a terminal)
};

struct SweepOutcome {
  SweepManifest manifest;
  std::vector<SweepRow> rows;         // sorted
  std::vector<std::string> problems;  // "scenario subject i: status: message" for failed runs
  int input_errors = 0, failed_runs = 0, check_failures = 0;
  double wall_s = 0;
};

// The row of one finished run: subject characteristics (subject_weight_kg, subject_height_m,
// subject_age_y, subject_L1_m, subject_L2_m) plus the run's deterministic metrics.
SweepRow MakeSweepRow(const std::string& scenario, uint64_t seed, int subject, const JobRun& run);

// Reads the scenarios (InputError on a bad file, duplicate names or subjects < 1), runs the sweep
// into out_dir/runs/<scenario>/subject_<i>/ and writes the aggregate into out_dir.
SweepOutcome RunSweep(const SweepOptions& opt);

}  // namespace exotwin
