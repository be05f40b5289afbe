#include "runner/sweep_plan.h"

#include <cstdlib>

#include "model/input_error.h"

namespace exotwin {
namespace {

// The SplitMix64 finaliser of sim/subjects.cc (DrawSubject seeds its engine with
// SplitMix64(seed ^ SplitMix64(index))); tests/runner/sweep_plan_test.cc pins the equivalence.
uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace

std::string Shard::ToString() const { return std::to_string(k) + "/" + std::to_string(n); }

Shard ParseShard(const std::string& text) {
  const auto fail = [&]() -> Shard {
    throw InputError("--shard: '" + text + "', expected K/N with integers 0 <= K < N (e.g. 0/4)");
  };
  const size_t slash = text.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 == text.size()) return fail();
  for (size_t i = 0; i < text.size(); ++i)
    if (i != slash && (text[i] < '0' || text[i] > '9')) return fail();
  if (slash > 9 || text.size() - slash - 1 > 9) return fail();
  Shard s;
  s.k = std::atoi(text.substr(0, slash).c_str());
  s.n = std::atoi(text.substr(slash + 1).c_str());
  if (s.n < 1 || s.k >= s.n) return fail();
  return s;
}

uint64_t SubjectSeed(uint64_t sweep_seed, int index) {
  return sweep_seed ^ SplitMix64(static_cast<uint64_t>(index)) ^ SplitMix64(0);
}

Scenario WithPopulationSubject(Scenario s, uint64_t sweep_seed, int index) {
  s.subject.preset.clear();
  s.subject.params_file.clear();
  s.subject.random_seed = SubjectSeed(sweep_seed, index);
  return s;
}

std::vector<SweepJob> PlanSweep(size_t n_scenarios, int n_subjects, const Shard& shard) {
  std::vector<SweepJob> jobs;
  for (size_t sc = 0; sc < n_scenarios; ++sc)
    for (int i = 0; i < n_subjects; ++i)
      if (shard.Holds(i)) jobs.push_back({sc, i});
  return jobs;
}

}  // namespace exotwin
