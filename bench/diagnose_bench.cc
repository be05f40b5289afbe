// `diagnose` on 10 minutes of 1 kHz data (target < 2 s), one hidden effect, in-memory (no CSV I/O).
//   ./build/bench/diagnose_bench --benchmark_min_time=1x   (or --benchmark_repetitions=3)
#include <benchmark/benchmark.h>

#include <map>

#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "core/data_dir.h"
#include "model/effect_families.h"

namespace exotwin {
namespace {

const GeneratedData& TenMinutes(const std::string& effect) {
  static std::map<std::string, GeneratedData> cache;
  auto it = cache.find(effect);
  if (it == cache.end()) {
    GenerateOptions g;
    g.seed = 2024, g.duration = 600, g.rate = 1000;
    g.effects = effect.empty() ? 0 : 1;
    if (!effect.empty()) g.allowed = {effect};
    it = cache.emplace(effect, GenerateMeasured(
        ReadModelFile(DataPath("examples/S1.yaml")), g)).first;
  }
  return it->second;
}

void Run(benchmark::State& state, const std::string& effect) {
  const GeneratedData& data = TenMinutes(effect);
  const LegParams base = ReadModelFile(DataPath("examples/S1.yaml"));
  for (auto _ : state) {
    const Diagnosis d = Diagnose(base, data.data);
    benchmark::DoNotOptimize(d.joints[0].rmse_after);
  }
  state.counters["samples"] = static_cast<double>(data.data.size());
}

void BM_Diagnose10min_Clean(benchmark::State& s) { Run(s, ""); }
void BM_Diagnose10min_Coulomb(benchmark::State& s) { Run(s, kCoulombFriction); }
void BM_Diagnose10min_SeriesCompliance(benchmark::State& s) { Run(s, kSeriesCompliance); }
BENCHMARK(BM_Diagnose10min_Clean)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_Diagnose10min_Coulomb)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_Diagnose10min_SeriesCompliance)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace exotwin

BENCHMARK_MAIN();
