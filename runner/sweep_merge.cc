// MergeSweepParts (sweep_table.h): joins the folders of `exotwin sweep --shard K/N` runs.
#include <set>

#include "core/error.h"
#include "runner/sweep_table.h"

namespace exotwin {

void MergeSweepParts(const std::vector<std::string>& dirs, SweepManifest* merged, std::vector<SweepRow>* rows) {
  if (dirs.empty()) throw InputError("merge: expected at least one part folder");
  rows->clear();
  std::set<int> shards;
  std::set<std::pair<std::string, int>> seen;
  int n_shards = 0;
  for (size_t i = 0; i < dirs.size(); ++i) {
    SweepManifest m;
    std::vector<SweepRow> part;
    ReadSweepAggregate(dirs[i], &m, &part);
    const std::string where = dirs[i] + "/sweep.json";
    const int n = m.shard ? m.shard->n : 1, k = m.shard ? m.shard->k : 0;
    if (i == 0) {
      *merged = m;
      merged->shard.reset();
      n_shards = n;
    } else {
      if (m.scenarios != merged->scenarios)
        throw InputError(where + ": scenarios differ from " + dirs[0] + ", expected parts of the same sweep");
      if (m.subjects != merged->subjects || m.seed != merged->seed)
        throw InputError(where + ": subjects " + std::to_string(m.subjects) + " seed " + std::to_string(m.seed) +
                         ", expected subjects " + std::to_string(merged->subjects) + " seed " +
                         std::to_string(merged->seed) + " as in " + dirs[0]);
      if (n != n_shards)
        throw InputError(where + ": shard " + std::to_string(k) + "/" + std::to_string(n) + ", expected a shard of " +
                         std::to_string(n_shards) + " as in " + dirs[0]);
    }
    if (!shards.insert(k).second)
      throw InputError(where + ": shard " + std::to_string(k) + "/" + std::to_string(n) + " given twice");
    const Shard shard{k, n};
    for (SweepRow& r : part) {
      if (!shard.Holds(r.subject))
        throw InputError(dirs[i] + "/sweep.csv: subject " + std::to_string(r.subject) + " does not belong to shard " +
                         shard.ToString());
      if (!seen.insert({r.scenario, r.subject}).second)
        throw InputError(dirs[i] + "/sweep.csv: row " + r.scenario + " subject " + std::to_string(r.subject) +
                         " appears in two parts");
      rows->push_back(std::move(r));
    }
  }
  if (static_cast<int>(shards.size()) != n_shards) {
    std::string missing;
    for (int k = 0; k < n_shards; ++k)
      if (!shards.count(k)) missing += (missing.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(n_shards);
    throw InputError("merge: missing shard(s) " + missing + ", expected all " + std::to_string(n_shards) + " parts");
  }
  SortRows(*merged, rows);
}

}  // namespace exotwin
