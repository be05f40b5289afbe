// Render + encode speed of render/ at 1280x720 against real time (30 fps of simulated time).
// Each iteration writes a 3 s video (90 frames) fed with 1 kHz states, including the final flush.
// Counters: fps = frames per wall-clock second; x_realtime = fps / 30 (> 1 is faster than real time);
// cpu_ms_frame = CPU time of all threads (llvmpipe, x264, caller) per frame, which bounds the fps an
// otherwise idle machine reaches: fps <= cores * 1000 / cpu_ms_frame (useful on a shared machine).
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "render/scene_renderer.h"
#include "render/video_renderer.h"
#include "sim/plant.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

constexpr double kSeconds = 3.0;

// CPU time (s) of every thread of this process so far.
double ProcessCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void RunVideo(benchmark::State& state, const RenderOptions& opt) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  const testing::ScopedTempDir tmp("render_bench");
  const std::string path = tmp.File("bench.mp4");
  long frames = 0;
  const double cpu0 = ProcessCpuSeconds();
  for (auto _ : state) {
    VideoRenderer video(plant.model(), path, opt);
    for (int i = 0; i < int(kSeconds * 1000); ++i) {
      OverlaySample s;
      s.t = i * 1e-3;
      s.q_hip = 0.6 + 0.5 * std::sin(2 * M_PI * 0.8 * s.t);
      s.q_knee = -0.9 + 0.6 * std::sin(2 * M_PI * 1.1 * s.t);
      s.tau_meas[0] = -20 + 5 * std::sin(3 * s.t), s.tau_meas[1] = 4 * std::cos(2 * s.t);
      s.tau_est[0] = s.tau_meas[0] + 1, s.tau_est[1] = s.tau_meas[1] - 0.5;
      s.emg = {0.1 + 0.05 * std::sin(s.t), 0.2, 0.05};
      if (i == 1500) s.event = "knee torque sensor: stuck reading";
      video.AddSample(s);
    }
    video.Finish();
    frames += video.frames();
  }
  const double cpu = ProcessCpuSeconds() - cpu0;
  state.counters["cpu_ms_frame"] = 1e3 * cpu / double(frames);
  state.counters["fps"] = benchmark::Counter(double(frames), benchmark::Counter::kIsRate);
  state.counters["x_realtime"] = benchmark::Counter(double(frames) / opt.fps, benchmark::Counter::kIsRate);
}

void BM_Video720pOverlays(benchmark::State& state) { RunVideo(state, RenderOptions{}); }
void BM_Video720pNoOverlays(benchmark::State& state) {
  RenderOptions o;
  o.overlays = false;
  RunVideo(state, o);
}
void BM_Video720pShadowsMsaa4(benchmark::State& state) {
  RenderOptions o;
  o.shadows = true;
  o.multisamples = 4;
  RunVideo(state, o);
}

// OSMesa render + read-back alone (no overlays, no encoding), per frame.
void BM_SceneRender720p(benchmark::State& state) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  SceneRenderer r(plant.model(), RenderOptions{});
  std::vector<double> q(plant.model()->qpos0, plant.model()->qpos0 + plant.model()->nq);
  double t = 0;
  const double cpu0 = ProcessCpuSeconds();
  for (auto _ : state) {
    q[0] = 0.6 + 0.5 * std::sin(t), q[1] = -0.9 + 0.6 * std::sin(1.3 * t);
    t += 1.0 / 30;
    benchmark::DoNotOptimize(r.Render(q.data()).data);
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["cpu_ms_frame"] = 1e3 * (ProcessCpuSeconds() - cpu0) / double(state.iterations());
}

// Overlay drawing alone on a 1280x720 frame (4 s charts of 1 kHz samples, 3 EMG channels, events).
void BM_OverlayDraw720p(benchmark::State& state) {
  RenderOptions opt;
  opt.emg_names = {"VM", "RF", "ST"};
  OverlayHistory h(opt);
  for (int i = 0; i < 5000; ++i) {
    OverlaySample s;
    s.t = i * 1e-3;
    s.tau_meas[0] = -20 + 5 * std::sin(3 * s.t), s.tau_meas[1] = 4 * std::cos(2 * s.t);
    s.tau_est[0] = s.tau_meas[0] + 1, s.tau_est[1] = s.tau_meas[1] - 0.5;
    s.emg = {0.1 + 0.05 * std::sin(s.t), 0.2, 0.05};
    if (i % 1000 == 0) s.event = "event " + std::to_string(i);
    h.Add(s);
  }
  cv::Mat frame(720, 1280, CV_8UC3, cv::Scalar(40, 40, 40));
  for (auto _ : state) {
    cv::Mat f = frame.clone();
    h.Draw(f);
    benchmark::DoNotOptimize(f.data);
  }
}

BENCHMARK(BM_OverlayDraw720p)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Video720pOverlays)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK(BM_Video720pNoOverlays)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();
BENCHMARK(BM_Video720pShadowsMsaa4)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
BENCHMARK(BM_SceneRender720p)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace exotwin

BENCHMARK_MAIN();
