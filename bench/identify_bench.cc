// Identification time (issue 5: target < 0.1 s for 200 s of 1 kHz data). The data are simulated once
// (identification/identification_data.h, subject S1); the timed part is Identify(): derivative filtering,
// trimming, EMG selection, regressor rows, least squares, standard errors, condition numbers.
//   BM_IdentifyExo/200        steps 1-2, 100 s knee swing + 100 s hip swing (200 s in all)
//   BM_IdentifyHuman/200      steps 3-4, same, with 5 EMG channels (HJ15 eq. 13) and the passive model
//   BM_IdentifyHuman/400      steps 3-4 on the full protocol: 5 x 40 s per configuration
//   BM_IdentifyFromCsv/200    as BM_IdentifyHuman/200 plus parsing the CSV files (the CLI path)
// Run: ./build-ident/bench/identify_bench
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <map>
#include <string>

#include "identification/identification.h"
#include "identification/identification_data.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

LegParams S1(bool human) {
  LegParams p;
  p.L1 = 0.41;
  p.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  if (human) {
    p.human = LumpedParams{1.69, 0.37, 4.54, 1.20, -0.16, 0.42};
    p.passive = PassiveModel::kRiener1999;
  }
  return p;
}

// Recordings of `seconds` in all (half per configuration, trials of 20 or 40 s), cached.
const ProtocolData& Data(bool human, int seconds) {
  static std::map<std::pair<bool, int>, ProtocolData> cache;
  auto it = cache.find({human, seconds});
  if (it != cache.end()) return it->second;
  ProtocolOptions o;
  o.trial_s = seconds >= 400 ? 40 : 20;
  o.trials = static_cast<int>(seconds / (2 * o.trial_s));
  if (human) o.emg_rms = 0.05;
  return cache[{human, seconds}] = SimulateProtocol(S1(human), o);
}

void BM_IdentifyExo(benchmark::State& st) {
  const auto files = Data(false, static_cast<int>(st.range(0))).All();
  for (auto _ : st) benchmark::DoNotOptimize(Identify(files, nullptr, 0.41));
  st.counters["samples"] = static_cast<double>(files.size() * files[0].size());
}

void BM_IdentifyHuman(benchmark::State& st) {
  const auto files = Data(true, static_cast<int>(st.range(0))).All();
  const LegParams known = S1(false);
  for (auto _ : st) benchmark::DoNotOptimize(Identify(files, &known, 0));
  st.counters["samples"] = static_cast<double>(files.size() * files[0].size());
}

void BM_IdentifyFromCsv(benchmark::State& st) {
  const testing::ScopedTempDir tmp("identify_bench");
  const std::string& dir = tmp.path();
  const ProtocolData& d = Data(true, static_cast<int>(st.range(0)));
  WriteProtocolCsv(d, dir);
  const LegParams known = S1(false);
  for (auto _ : st) {
    std::vector<MeasuredData> files;
    for (const MeasuredData& m : d.All()) files.push_back(ReadMeasuredCsv(dir + "/" + m.source + ".csv"));
    benchmark::DoNotOptimize(Identify(files, &known, 0));
  }
}

BENCHMARK(BM_IdentifyExo)->Arg(200)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IdentifyHuman)->Arg(200)->Arg(400)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IdentifyFromCsv)->Arg(200)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace exotwin

BENCHMARK_MAIN();
