// `predict` throughput (samples/s) next to a bare mj_inverse loop on the same data, in one run.
//   ./build/bench/predict_bench
// BM_BareMjInverse: only mj_inverse on preset qpos/qvel/qacc (the floor).
// BM_PlantInverseDynamics: Plant::InverseDynamics (mj_inverse + passive torque + bookkeeping).
// BM_PredictPipeline: DeriveKinematics (zero-phase filter, derivatives) + PredictTorque.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <cmath>

#include "formats/measured_data.h"
#include "diagnosis/predict.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

constexpr int kSamples = 60000;  // one minute at 1 kHz

LegParams S1() {
  LegParams p;
  p.L1 = 0.41;
  p.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  p.human = LumpedParams{1.69, 0.37, 4.54, 1.20, -0.16, 0.42};
  p.passive = PassiveModel::kRiener1999;
  return p;
}

MeasuredData Data() {
  CsvTable tab;
  tab.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
  tab.columns.assign(5, std::vector<double>(kSamples, 0.0));
  for (int i = 0; i < kSamples; ++i) {
    const double t = i * 1e-3;
    tab.columns[0][i] = t;
    tab.columns[1][i] = 0.35 + 0.2 * std::sin(2 * M_PI * 0.5 * t);
    tab.columns[2][i] = -0.7 + 0.4 * std::sin(2 * M_PI * 0.5 * t + 1);
  }
  return MakeMeasuredData(std::move(tab), "bench");
}

void BM_BareMjInverse(benchmark::State& state) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  plant.SetParams(S1());
  const Kinematics k = DeriveKinematics(Data());
  mjData* d = mj_makeData(plant.model());
  mjModel* m = const_cast<mjModel*>(plant.model());
  m->opt.disableflags |= mjDSBL_CONSTRAINT;
  for (auto _ : state) {
    double sum = 0;
    for (int i = 0; i < kSamples; ++i) {
      d->qpos[0] = k.q[0][i]; d->qpos[1] = k.q[1][i];
      d->qvel[0] = k.qd[0][i]; d->qvel[1] = k.qd[1][i];
      d->qacc[0] = k.qdd[0][i]; d->qacc[1] = k.qdd[1][i];
      mj_inverse(m, d);
      sum += d->qfrc_inverse[0];
    }
    benchmark::DoNotOptimize(sum);
  }
  mj_deleteData(d);
  state.counters["samples_per_s"] = benchmark::Counter(kSamples, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_BareMjInverse)->Unit(benchmark::kMillisecond);

void BM_PlantInverseDynamics(benchmark::State& state) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  plant.SetParams(S1());
  const Kinematics k = DeriveKinematics(Data());
  for (auto _ : state) {
    const Prediction p = PredictTorque(plant, k);
    benchmark::DoNotOptimize(p.tau_S[0].data());
  }
  state.counters["samples_per_s"] = benchmark::Counter(kSamples, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PlantInverseDynamics)->Unit(benchmark::kMillisecond);

void BM_PredictPipeline(benchmark::State& state) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  plant.SetParams(S1());
  const MeasuredData data = Data();
  for (auto _ : state) {
    const Prediction p = PredictTorque(plant, DeriveKinematics(data));
    benchmark::DoNotOptimize(p.tau_S[0].data());
  }
  state.counters["samples_per_s"] = benchmark::Counter(kSamples, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PredictPipeline)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace exotwin

BENCHMARK_MAIN();
