// What a population sweep runs: scenarios x virtual subjects, optionally one shard of it.
// Subject i of a sweep with seed K is DrawSubject(K, i) (sim/subjects.h); shard k of n holds the
// subjects with i mod n == k, so the shards partition the sweep deterministically.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runner/scenario.h"

namespace exotwin {

struct Shard {
  int k = 0, n = 1;  // 0 <= k < n
  bool Holds(int subject) const { return subject % n == k; }
  std::string ToString() const;  // "k/n"
};

// Parses "K/N" (0 <= K < N, N >= 1). Throws InputError naming --shard and the expected form.
Shard ParseShard(const std::string& text);

// The seed for SubjectSpec::random_seed that makes the runner's population draw (which takes
// DrawSubject(seed, 0)) equal to DrawSubject(sweep_seed, index) bit for bit.
uint64_t SubjectSeed(uint64_t sweep_seed, int index);

// The scenario with its subject replaced by population draw `index` of `sweep_seed` (the passive
// model is kept; preset and params_file are cleared).
Scenario WithPopulationSubject(Scenario s, uint64_t sweep_seed, int index);

struct SweepJob {
  size_t scenario = 0;  // index into the scenario list
  int subject = 0;      // population index
};

// Jobs of the shard in the aggregate's order: scenario-major, subjects ascending.
std::vector<SweepJob> PlanSweep(size_t n_scenarios, int n_subjects, const Shard& shard);

}  // namespace exotwin
