// The full closed loop (physics + CAN bus + sensors + controller + logging) against a bare mj_step
// loop of the same model and number of steps, in one run:
//   ./build/bench/closed_loop_bench
// BM_BareMjStep: mj_step with a constant torque (the floor: MuJoCo alone).
// BM_ClosedLoopNoLogs / BM_ClosedLoop: `exotwin run` of the gait scenario (10 s = 10000 steps)
// without and with the measured/truth CSV logs.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <filesystem>

#include "scenarios/runner.h"
#include "sim/plant.h"
#include "sim/subjects.h"

namespace exotwin {
namespace {

constexpr double kDuration = 10.0;

void BM_BareMjStep(benchmark::State& state) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  plant.SetParams(SubjectLegParams(PresetSubject("S1")));
  mjModel* m = const_cast<mjModel*>(plant.model());
  mjData* d = plant.data();
  const int n = static_cast<int>(kDuration / m->opt.timestep);
  for (auto _ : state) {
    mj_resetData(m, d);
    d->qpos[0] = 0.3;
    d->qpos[1] = -0.5;
    for (int i = 0; i < n; ++i) {
      d->ctrl[0] = 20.0;
      d->ctrl[1] = 5.0;
      mj_step(m, d);
    }
    benchmark::DoNotOptimize(d->qpos[0]);
  }
  state.counters["steps_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_BareMjStep)->Unit(benchmark::kMillisecond);

void ClosedLoop(benchmark::State& state, bool logs) {
  Scenario s = ReadScenario(std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/gait_2kmh.yaml");
  s.protocol.duration = kDuration;
  s.log_measured_csv = logs;
  RunOptions o;
  o.out_dir = (std::filesystem::temp_directory_path() / "exotwin_bench_closed_loop").string();
  for (auto _ : state) {
    const RunResult r = RunScenario(s, o);
    benchmark::DoNotOptimize(r.metrics.size());
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(kDuration * 1000, benchmark::Counter::kIsIterationInvariantRate);
}
void BM_ClosedLoopNoLogs(benchmark::State& state) { ClosedLoop(state, false); }
void BM_ClosedLoop(benchmark::State& state) { ClosedLoop(state, true); }
BENCHMARK(BM_ClosedLoopNoLogs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoop)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace exotwin

BENCHMARK_MAIN();
