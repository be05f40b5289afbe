// The full closed loop (physics + CAN bus + sensors + controller + logging) against a bare mj_step
// loop of the same model and number of steps, in one run:
//   ./build/bench/closed_loop_bench
// BM_BareMjStep: mj_step with a constant torque (the floor: MuJoCo alone).
// BM_ClosedLoopNoLogs / BM_ClosedLoop: `exotwin run` of the gait scenario (10 s = 10000 steps)
// without and with the measured/truth CSV logs. The gait scenario's subject S1 wears the human
// model: muscles (relaxed) and 5 EMG channels through the amplifier node on the bus.
// The cost of the human (issue 6): BM_ClosedLoopNoEmg drops the electrodes (muscles still stepped),
// BM_ClosedLoopExaggerated drives the muscles voluntarily (exaggerated gait, tracking law + box-
// constrained allocation every step), BM_MuscleStep / BM_SyntheticEmg time the two models alone.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>


#include "core/data_dir.h"
#include "runner/runner.h"
#include "sim/muscles.h"
#include "sim/synthetic_emg.h"
#include "sim/plant.h"
#include "sim/subjects.h"
#include "tests/temp_dir.h"

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

enum class Human { kRelaxedWithEmg, kRelaxedNoEmg, kExaggeratedWithEmg };

void ClosedLoop(benchmark::State& state, bool logs, Human human = Human::kRelaxedWithEmg) {
  Scenario s = ReadScenario(DataPath("scenarios/gait_2kmh.yaml"));
  s.protocol.duration = kDuration;
  s.log_measured_csv = logs;
  s.human.emg = human != Human::kRelaxedNoEmg;
  if (human == Human::kExaggeratedWithEmg) {
    s.human.behaviour = "exaggerated_gait";
    s.human.active_from = 0.0;
  }
  RunOptions o;
  const testing::ScopedTempDir tmp("bench_closed_loop");
  o.out_dir = tmp.path();
  for (auto _ : state) {
    const RunResult r = RunScenario(s, o);
    benchmark::DoNotOptimize(r.metrics.size());
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(kDuration * 1000, benchmark::Counter::kIsIterationInvariantRate);
}
void BM_ClosedLoopNoLogs(benchmark::State& state) { ClosedLoop(state, false); }
void BM_ClosedLoop(benchmark::State& state) { ClosedLoop(state, true); }
void BM_ClosedLoopNoEmg(benchmark::State& state) { ClosedLoop(state, false, Human::kRelaxedNoEmg); }
void BM_ClosedLoopExaggerated(benchmark::State& state) {
  ClosedLoop(state, false, Human::kExaggeratedWithEmg);
}
BENCHMARK(BM_ClosedLoopNoLogs)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoop)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoopNoEmg)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ClosedLoopExaggerated)->Unit(benchmark::kMillisecond);

// The muscle model alone: 10 000 steps of activation dynamics + delay line + torques.
void BM_MuscleStep(benchmark::State& state) {
  MuscleModel muscles(DrawMuscleParams(1), 1e-3);
  const int n = static_cast<int>(kDuration * 1000);
  for (auto _ : state) {
    muscles.Reset();
    Eigen::Vector2d q(0.3, -0.5), qd(0.5, -1.0);
    for (int i = 0; i < n; ++i) {
      MuscleVec u = MuscleVec::Constant(0.05 + 0.04 * ((i / 200) % 2));
      muscles.Step(u);
      benchmark::DoNotOptimize(muscles.Torques(q, qd).total()[0]);
    }
  }
  state.counters["steps_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_MuscleStep)->Unit(benchmark::kMillisecond);

// Synthetic surface EMG alone: 10 000 samples of 5 channels (shaping filters, baseline, crosstalk).
void BM_SyntheticEmg(benchmark::State& state) {
  SyntheticEmg emg(DefaultSyntheticEmgConfig(), 1);
  const int n = static_cast<int>(kDuration * 1000);
  const MuscleVec e = MuscleVec::Constant(0.1);
  for (auto _ : state) {
    for (int i = 0; i < n; ++i) benchmark::DoNotOptimize(emg.Sample(e)[0]);
  }
  state.counters["steps_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SyntheticEmg)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace exotwin

BENCHMARK_MAIN();
