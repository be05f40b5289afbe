#include "runner/sweep_plan.h"

#include <cstdlib>

#include "core/error.h"
#include "core/rng.h"

namespace exotwin {
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
  return sweep_seed ^ MixSeed(static_cast<uint64_t>(index)) ^ MixSeed(0);
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
