// The aggregate of a population sweep: one row per (scenario, subject) with the subject's
// characteristics and the run's deterministic metrics, the sweep's manifest, and summary statistics.
// Files in the sweep folder: sweep.csv (rows), summary.json (stats per scenario and column),
// sweep.json (manifest), plots/<scenario>.svg (histograms). A shard's folder holds the same files
// for its rows; `exotwin merge` rebuilds the unsharded aggregate from them.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "runner/sweep_plan.h"

namespace exotwin {

struct SweepRow {
  std::string scenario;
  int subject = 0;             // population index
  uint64_t subject_seed = 0;   // SubjectSeed(seed, subject)
  std::string status;          // JobRun::status
  int checks_failed = 0;
  std::map<std::string, double> values;  // subject_* characteristics and metrics (absent = empty cell)
};

struct SweepManifest {
  std::vector<std::string> scenarios;  // names, in run order
  std::vector<std::string> files;      // scenario files as given on the command line
  int subjects = 0;                    // N of the whole sweep
  uint64_t seed = 1;
  std::optional<Shard> shard;          // none for an unsharded or merged sweep
};

// Sorts rows scenario-major (manifest order), then by subject.
void SortRows(const SweepManifest& m, std::vector<SweepRow>* rows);

// CSV text: scenario,subject,subject_seed,status,checks_failed, then the union of value names
// (sorted); numbers in the shortest form that reads back to the same double.
std::string SweepCsv(const std::vector<SweepRow>& rows);
// Parses SweepCsv text. Throws InputError naming `source` and the line on malformed content.
std::vector<SweepRow> ParseSweepCsv(const std::string& text, const std::string& source);

// summary.json: per scenario the run count, statuses and, per column, n, mean, sd (n-1), min, max,
// p5, p95 (linear interpolation) over the completed runs.
std::string SweepSummaryJson(const SweepManifest& m, const std::vector<SweepRow>& rows);

std::string ManifestJson(const SweepManifest& m, size_t rows);
// Throws InputError naming `source` on a malformed manifest.
SweepManifest ParseManifestJson(const std::string& text, const std::string& source);

// Writes sweep.csv, summary.json, sweep.json and plots/*.svg into dir (rows sorted first).
void WriteSweepAggregate(const std::string& dir, const SweepManifest& m, std::vector<SweepRow> rows);

// Reads a part folder written by WriteSweepAggregate. Throws InputError.
void ReadSweepAggregate(const std::string& dir, SweepManifest* m, std::vector<SweepRow>* rows);

// Joins shard folders into the unsharded aggregate. Throws InputError if the parts disagree
// (scenarios, subjects, seed, shard count), a shard is missing or given twice, or a row is duplicated.
void MergeSweepParts(const std::vector<std::string>& dirs, SweepManifest* m, std::vector<SweepRow>* rows);

}  // namespace exotwin
