// The probes of `exotwin bench` (app/bench_probes.h). Optional layers are detected at compile time:
// a probe whose library is not in the build reports {"status": "unavailable"}.
#include <fcntl.h>
#include <mujoco/mujoco.h>
#include <sched.h>
#include <spawn.h>
#include <sys/resource.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <stdexcept>
#include <thread>

#include "app/bench_probes.h"
#include "batch/controller_process.h"
#include "core/file_text.h"
#include "core/realtime.h"
#include "dsp/statistics.h"
#include "formats/csv_table.h"
#include "core/data_dir.h"
#include "batch/fork_pool.h"
#include "runner/runner.h"
#include "batch/scenario_job.h"
#include "runner/sweep_plan.h"
#include "sim/plant.h"
#include "sim/subjects.h"

#include "render/render_plugin.h"
#include "identification/identification.h"
#include "identification/identification_data.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "diagnosis/replay.h"
#include "formats/model_file.h"
#include "formats/measured_data.h"
#include "formats/number_text.h"
#include "model/effect_families.h"

namespace exotwin {
namespace {

using json = nlohmann::ordered_json;

// Best wall time (s) of `repeat` calls of f.
double BestOf(int repeat, const std::function<void()>& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < std::max(1, repeat); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

Scenario GaitScenario(double duration) {
  Scenario s = ReadScenario(DataPath("scenarios/gait_2kmh.yaml"));
  s.protocol.duration = duration;
  s.protocol.ramp = std::min(s.protocol.ramp, duration / 4);
  s.log_measured_csv = false;
  return s;
}

// CPU time (s, user + system) of the terminated, waited-for children of this process so far.
double ChildrenCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// CPU time (s) of this process itself so far.
double SelfCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Spawns argv[0] with argv (stdout and stderr to /dev/null) and waits for it; false if it cannot run
// or exits non-zero.
bool SpawnAndWait(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  int st = 0;
  return rc == 0 && waitpid(pid, &st, 0) == pid && WIFEXITED(st) && WEXITSTATUS(st) == 0;
}

json Unavailable(const std::string& why) { return json{{"status", "unavailable"}, {"reason", why}}; }

// Best wall time (s) of `repeat` bare mj_step loops of n steps on the plant's model (S1's masses), from
// the same start and with constant torques: the floor, MuJoCo alone.
// The same loop on `plant`'s model from q0 with constant torques u (N m).
double BareMjStepSeconds(int repeat, long n, Plant& plant, const Eigen::Vector2d& q0, const Eigen::Vector2d& u) {
  mjModel* m = const_cast<mjModel*>(plant.model());
  mjData* d = plant.data();
  return BestOf(repeat, [&] {
    mj_resetData(m, d);
    d->qpos[0] = q0[0];
    d->qpos[1] = q0[1];
    for (long i = 0; i < n; ++i) {
      d->ctrl[0] = u[0];
      d->ctrl[1] = u[1];
      mj_step(m, d);
    }
  });
}

double BareMjStepSeconds(int repeat, long n) {
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  plant.SetParams(SubjectLegParams(PresetSubject("S1")));
  return BareMjStepSeconds(repeat, n, plant, {0.3, -0.5}, {20.0, 5.0});
}

std::string Seconds(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g s", s);
  return b;
}

// Runs this executable with `args` (output discarded) and waits; throws unless it exits 0.
void RunSelf(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  static char self[] = "exotwin";
  argv.push_back(self);
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("bench: fork failed");
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) {
      dup2(null, 1);
      dup2(null, 2);
    }
    execv("/proc/self/exe", argv.data());
    _exit(127);
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("bench: exotwin " + args.front() + " failed");
}

}  // namespace

json BenchClosedLoop(const BenchConfig& c) {
  const double duration = c.quick ? 2.0 : 10.0;
  const long n = std::lround(duration / 1e-3);
  const double bare = BareMjStepSeconds(c.repeat, n);
  const Scenario s = GaitScenario(duration);
  RunOptions o;
  o.out_dir = c.scratch + "/closed_loop";
  const double closed = BestOf(c.repeat, [&] { RunScenario(s, o); });
  // The human's share (issue 6): the same run without the EMG electrodes (muscles still stepped), and
  // with the muscles driven voluntarily (exaggerated gait: tracking law + allocation every step).
  Scenario no_emg = s, voluntary = s;
  no_emg.human.emg = false;
  voluntary.human.behaviour = "exaggerated_gait";
  voluntary.human.active_from = 0.0;
  const double closed_no_emg = BestOf(c.repeat, [&] { RunScenario(no_emg, o); });
  const double closed_voluntary = BestOf(c.repeat, [&] { RunScenario(voluntary, o); });
  return json{{"status", "ok"},
              {"steps", n},
              {"bare_mj_step_s", bare},
              {"closed_loop_s", closed},
              {"bare_steps_per_s", n / bare},
              {"closed_loop_steps_per_s", n / closed},
              {"closed_loop_x_realtime", duration / closed},
              {"ratio_closed_loop_to_bare", closed / bare},
              {"closed_loop_no_emg_s", closed_no_emg},
              {"closed_loop_voluntary_human_s", closed_voluntary},
              {"emg_cost_us_per_step", 1e6 * (closed - closed_no_emg) / n},
              {"voluntary_human_cost_us_per_step", 1e6 * (closed_voluntary - closed) / n},
              {"ratio_voluntary_human_to_bare", closed_voluntary / bare},
              {"rows", BenchRowsJson({{"closed loop without logs, EMG (exotwin bench)", closed / bare, "x",
                                       "bare mj_step loop", "<= 1.5x", Seconds(closed) + " vs " + Seconds(bare)},
                                      {"closed loop without logs, no EMG", closed_no_emg / bare, "x",
                                       "bare mj_step loop", "<= 1.5x",
                                       Seconds(closed_no_emg) + " vs " + Seconds(bare)}})}};
}

json BenchRunCommand(const BenchConfig& c) {
  const std::string file = DataPath("scenarios/gait_2kmh.yaml");
  const Scenario s = ReadScenario(file);
  const long n = std::lround(s.protocol.duration / 1e-3);
  double bare = 0;
  {
    const ScopedCpuPin pin(FastestCpu(c.cpus));  // the run's main thread goes where the scheduler puts it
    bare = BareMjStepSeconds(c.repeat, n);
  }
  // The run with and without its bag, alternated (a shared machine's load falls on both alike).
  double run = std::numeric_limits<double>::infinity(), mcap = run;
  for (int i = 0; i < std::max(1, c.repeat); ++i) {
    run = std::min(run, BestOf(1, [&] { RunSelf({"run", file, "--out", c.scratch + "/run"}); }));
    mcap = std::min(mcap, BestOf(1, [&] {
                      RunSelf({"run", file, "--out", c.scratch + "/run_mcap", "--mcap", c.scratch + "/run.mcap"});
                    }));
  }
  return json{{"status", "ok"},
              {"steps", n},
              {"bare_mj_step_s", bare},
              {"run_s", run},
              {"run_mcap_s", mcap},
              {"ratio_run_to_bare", run / bare},
              {"ratio_run_mcap_to_run", mcap / run},
              {"rows", BenchRowsJson({{"exotwin run gait_2kmh.yaml (60 s, both CSV logs, start-up included)",
                                       run / bare, "x", "bare mj_step loop, same model and steps", "<= 2.5x",
                                       Seconds(run) + " vs " + Seconds(bare)},
                                      {"run --mcap vs run: gait_2kmh.yaml with its ROS 2 bag (zstd) too",
                                       mcap / run, "x", "the same run with its CSV logs alone", "<= 1.3x",
                                       Seconds(mcap) + " vs " + Seconds(run)}})}};
}

json BenchStartup(const BenchConfig& c) {
  const std::string self = ExecutablePath();
  if (self.empty()) return Unavailable("/proc/self/exe unreadable");
  const int n = c.quick ? 5 : 10 * std::max(1, c.repeat);
  bool ok = true;
  const double help = BestOf(n, [&] { ok &= SpawnAndWait({self, "--help"}); });
  const double base = BestOf(n, [&] { ok &= SpawnAndWait({"/bin/true"}); });
  if (!ok) return Unavailable("exotwin --help or /bin/true did not run");
  return json{{"ratio_help_to_true", help / base},
              {"status", "ok"},
              {"help_s", help},
              {"true_s", base},
              {"target_help_s", 0.03},
              {"runs", n},
              {"rows", BenchRowsJson({{"start-up: exotwin --help", help / base, "x", "/bin/true, spawned the same way",
                                       "< 0.03 s", Seconds(help) + " vs " + Seconds(base)}})}};
}

json BenchRender(const BenchConfig& c) {
  const double seconds = c.quick ? 1.0 : 3.0;
  Plant plant(ShippedModelPath("leg_exowheel.xml"));
  auto video = [&](bool overlays) {
    RenderOptions opt;
    opt.overlays = overlays;
    opt.emg_names = {"VM", "RF", "ST"};
    long frames = 0;
    const std::string path = c.scratch + "/bench.mp4";
    const double cpu0 = SelfCpuSeconds();
    int runs = 0;
    const double t = BestOf(c.quick ? 1 : std::min(c.repeat, 2), [&] {
      const std::unique_ptr<VideoSink> v = OpenVideo(plant.model(), path, opt);
      for (int i = 0; i < static_cast<int>(seconds * 1000); ++i) {
        OverlaySample s;
        s.t = i * 1e-3;
        s.q_hip = 0.6 + 0.5 * std::sin(2 * M_PI * 0.8 * s.t);
        s.q_knee = -0.9 + 0.6 * std::sin(2 * M_PI * 1.1 * s.t);
        s.tau_meas[0] = -20 + 5 * std::sin(3 * s.t), s.tau_meas[1] = 4 * std::cos(2 * s.t);
        s.tau_est[0] = s.tau_meas[0] + 1, s.tau_est[1] = s.tau_meas[1] - 0.5;
        s.emg = {0.1 + 0.05 * std::sin(s.t), 0.2, 0.05};
        if (i == 500) s.event = "knee torque sensor: stuck reading";
        v->AddSample(s);
      }
      v->Finish(seconds);
      frames = v->frames();
      ++runs;
    });
    return std::make_tuple(t, frames, 1e3 * (SelfCpuSeconds() - cpu0) / (runs * frames));
  };
  try {
    const auto [t_ov, frames, cpu_ms] = video(true);
    const auto [t_plain, frames_plain, cpu_ms_plain] = video(false);
    const double fps = frames / t_ov, fps_plain = frames_plain / t_plain;
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    return json{{"x_realtime_with_overlays", fps / 30.0},
                {"status", "ok"},
                {"width", 1280},
                {"height", 720},
                {"frames", frames},
                {"video_fps", 30.0},
                {"overlays_s", t_ov},
                {"no_overlays_s", t_plain},
                {"fps_with_overlays", fps},
                {"fps_without_overlays", fps_plain},
                {"ratio_overlays_to_plain", t_ov / t_plain},
                {"target_fps_with_overlays", 60.0},
                {"cpu_ms_per_frame_with_overlays", cpu_ms},
                {"cpu_ms_per_frame_without_overlays", cpu_ms_plain},
                {"fps_bound_idle_cores_with_overlays", cores * 1e3 / cpu_ms},
                {"rows", BenchRowsJson({{"render 1280x720 with overlays + H.264", fps / 30.0, "x",
                                         "real time (30 fps video)", ">= 2x",
                                         std::to_string(static_cast<int>(std::lround(fps))) + " fps, " +
                                             std::to_string(static_cast<int>(std::lround(cpu_ms))) + " CPU ms/frame"}})}};
  } catch (const std::exception& e) {
    return Unavailable(std::string("renderer failed: ") + e.what());
  }
}

json BenchIdentification(const BenchConfig& c) {
  LegParams truth;
  truth.L1 = 0.41;
  truth.exo = {3.02, 0.74, 3.85, 1.74, 0.15, 0.16};
  truth.human = LumpedParams{1.69, 0.37, 4.54, 1.20, -0.16, 0.42};
  truth.passive = PassiveModel::kRiener1999;
  ProtocolOptions po;
  po.trial_s = 20;
  po.trials = c.quick ? 1 : 2;
  po.emg_rms = 0.05;
  const auto t_sim0 = std::chrono::steady_clock::now();
  const std::vector<MeasuredData> files = SimulateProtocol(truth, po).All();
  const double t_sim = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_sim0).count();
  LegParams known = truth;
  known.human.reset();
  size_t samples = 0;
  for (const auto& f : files) samples += f.size();
  const double data_s = 2.0 * po.trials * po.trial_s;
  const double t = BestOf(c.repeat, [&] { Identify(files, &known, 0); });
  return json{{"status", "ok"},
              {"steps", "3-4 (human, known exo)"},
              {"data_s", data_s},
              {"samples", samples},
              {"identify_s", t},
              {"samples_per_s", samples / t},
              {"x_realtime", data_s / t},
              {"simulate_data_s", t_sim},
              {"ratio_identify_to_simulation", t / t_sim},
              {"rows", BenchRowsJson({{"identify steps 3-4", t / t_sim, "x", "simulating its data", "",
                                       Seconds(t) + " vs " + Seconds(t_sim)}})}};
}

GenerateOptions BenchFrictionRecord(double duration_s) {
  GenerateOptions g;
  g.seed = 2024;
  g.duration = duration_s;
  g.rate = 1000;
  g.effects = 1;
  g.allowed = {kCoulombFriction};
  return g;
}

json BenchPython(const BenchConfig& c) {
  // The module as laid out next to this program: P/bin/exotwin -> P/lib/python3/dist-packages/exotwin
  // (the build tree: build/app/exotwin -> build/lib/python3/dist-packages; python/CMakeLists.txt).
  const std::string self = ExecutablePath();
  if (self.empty()) return Unavailable("/proc/self/exe unreadable");
  const std::filesystem::path prefix = std::filesystem::path(self).parent_path().parent_path();
  const std::string pythonpath = (prefix / "lib" / "python3" / "dist-packages").string();
  if (!std::filesystem::exists(pythonpath + "/exotwin/__init__.py"))
    return Unavailable("the Python module is not built (" + pythonpath + "/exotwin)");
  const char* env_python = std::getenv("EXOTWIN_PYTHON");
  const std::string python = env_python && *env_python ? env_python : "/usr/bin/python3";  // Debian's (numpy)
  const std::string out = c.scratch + "/python_bench.json";
  const char* old = std::getenv("PYTHONPATH");
  const std::string saved = old ? old : "";
  setenv("PYTHONPATH", (pythonpath + (saved.empty() ? "" : ":" + saved)).c_str(), 1);
  std::vector<std::string> args = {python, "-m", "exotwin.bench", "--exotwin", self, "--repeat",
                                   std::to_string(c.repeat), "--json", out};
  if (c.quick) args.push_back("--quick");
  if (const int cpu = FastestCpu(c.cpus); cpu >= 0) args.insert(args.end(), {"--cpu", std::to_string(cpu)});
  const bool ok = SpawnAndWait(args);
  if (old) setenv("PYTHONPATH", saved.c_str(), 1);
  else unsetenv("PYTHONPATH");
  if (!ok) return Unavailable(python + " -m exotwin.bench failed (run it by hand to see why)");
  return json::parse(ReadTextFile(out, "python bench", "JSON"));
}

json BenchReplay(const BenchConfig& c) {
  // The DFKI rig's model (examples/real_rig/model.yaml) with the effects diagnose names there.
  LegParams p = ReadModelFile(DataPath("examples/real_rig/model.yaml"));
  auto fx_of = [](const char* name, const char* joint, double v) {
    Effect e;
    e.name = name, e.joint = joint, e.value = v;
    return e;
  };
  p.effects = {fx_of(kCoulombFriction, "hip", 0.155), fx_of(kCoulombFriction, "knee", 0.147),
               fx_of(kInertiaError, "knee", 0.00275)};
  PlantEffects fx;
  const std::unique_ptr<Plant> twin = MakeReplayPlant(p, "bench", "", &fx);
  Plant& plant = *twin;
  // The record: the plant itself driven by sums of sines at 1 kHz (angles and torque as a rig logs).
  const double duration = c.quick ? 20.0 : 600.0;
  const long n = std::lround(duration / plant.timestep());
  ReplaySeries s;
  s.source = "bench";
  plant.Reset({0.2, -0.3}, {0, 0});
  for (long i = 0; i < n; ++i) {
    const double t = plant.time();
    const Eigen::Vector2d u(0.8 * std::sin(2 * M_PI * 0.7 * t) + 0.3 * std::sin(2 * M_PI * 1.9 * t),
                            0.3 * std::sin(2 * M_PI * 1.1 * t) + 0.1 * std::sin(2 * M_PI * 2.7 * t));
    s.t.push_back(t);
    for (int j = 0; j < 2; ++j) {
      s.q[j].push_back(plant.q()[j]);
      s.q0[j].push_back(plant.q()[j]);
      s.qd0[j].push_back(plant.qd()[j]);
      s.tau_R[j].push_back(u[j]);
    }
    plant.Step(u);
  }
  ReplayScore score;
  const double replay = BestOf(c.repeat, [&] { score = Replay(plant, s, 0.5).score; });
  // The floor: a bare mj_step loop of the same (rigid) model over the same simulated time.
  Plant bare_plant(ExowheelMjcfPath(false));
  bare_plant.SetParams(p);
  const double bare = BareMjStepSeconds(c.repeat, n, bare_plant, {0.2, -0.3}, {0.5, 0.2});
  return json{{"ratio_replay_to_bare", replay / bare},
              {"record_s", duration},
              {"steps", n},
              {"windows", score.windows},
              {"replay_s", replay},
              {"bare_mj_step_s", bare},
              {"rows", BenchRowsJson({{"replay of " + std::to_string(static_cast<int>(duration)) +
                                           " s at 1 kHz (DFKI rig, friction + armature, 0.5 s windows)",
                                       replay / bare, "x", "bare mj_step loop (same model, same time)", "<= 2x",
                                       Seconds(replay) + " vs " + Seconds(bare)}})}};
}

json BenchMotionFit(const BenchConfig& c) {
  // The record: the shipped gait (S1, closed loop) on a plant holding a knee backlash of 0.02 rad.
  const double duration = c.quick ? 15.0 : 60.0;
  Scenario s = GaitScenario(duration);
  Effect dead_band;
  dead_band.name = kBacklash, dead_band.joint = "knee", dead_band.value = 0.02;
  dead_band.unit = FindFamily(kBacklash)->unit;
  s.plant_effects = {dead_band};
  s.plant_effects_source = "bench: plant.effects";
  s.log_measured_csv = true;  // the record
  RunOptions o;
  o.out_dir = c.scratch + "/motion_fit";
  RunScenario(s, o);
  const MeasuredData record = ReadMeasuredCsv(o.out_dir + "/measured.csv");
  const LegParams model = ReadModelFile(DataPath("examples/S1.yaml"));
  PlantEffects fx;
  const std::unique_ptr<Plant> plant = MakeReplayPlant(model, "bench", "", &fx);
  const ReplaySeries series = ReplaySeriesOf(record, fx, ReplayInput::kTorque, kReplayCutoffHz);
  const double replay = BestOf(c.repeat, [&] { Replay(*plant, series, 0.5); });
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  opt.threads = 2;
  Diagnosis d;
  const double fit = BestOf(1, [&] { d = Diagnose(model, record, opt); });
  std::string named;
  for (const auto& e : d.effects)
    named += (named.empty() ? "" : ", ") + e.effect.name + " " + e.effect.joint + " " + NumberText(e.effect.value, 4);
  const std::string work = "diagnose --fit motion of " + std::to_string(static_cast<int>(duration)) +
                           " s closed-loop gait (S1, knee backlash 0.02 rad), 2 threads";
  return json{{"status", "ok"},
              {"record_s", duration},
              {"named", named},
              {"motion_fit_s", fit},
              {"replay_s", replay},
              {"replays", fit / replay},
              {"rows", BenchRowsJson({{work, fit / replay, "x", "one replay of the record (0.5 s windows)", "<= 150x",
                                       Seconds(fit) + " vs " + Seconds(replay) + "; named: " + (named.empty() ? "nothing" : named)}})}};
}

json BenchDiagnosis(const BenchConfig& c) {
  const GenerateOptions g = BenchFrictionRecord(c.quick ? 20 : 60);
  const LegParams base = ReadModelFile(DataPath("examples/S1.yaml"));
  const auto t_gen0 = std::chrono::steady_clock::now();
  const GeneratedData data = GenerateMeasured(base, g);
  const double t_gen = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_gen0).count();
  const double t = BestOf(std::min(c.repeat, 2), [&] { Diagnose(base, data.data); });
  return json{{"status", "ok"},
              {"data_s", g.duration},
              {"samples", data.data.size()},
              {"hidden_effect", kCoulombFriction},
              {"diagnose_s", t},
              {"samples_per_s", data.data.size() / t},
              {"x_realtime", g.duration / t},
              {"generate_data_s", t_gen},
              {"ratio_diagnose_to_generation", t / t_gen},
              {"rows", BenchRowsJson({{"diagnose " + std::to_string(static_cast<int>(g.duration)) + " s of 1 kHz data",
                                       t / t_gen, "x", "generating the data", "", Seconds(t) + " vs " + Seconds(t_gen)}})}};
}

std::vector<BenchCpu> MeasureCpus(const BenchConfig& c) {
  std::vector<BenchCpu> cpus;
  for (const int cpu : AllowedCpus()) {
    const ScopedCpuPin pin(cpu);
    if (!pin.pinned()) return {};
    cpus.push_back({cpu, BareMjStepSeconds(c.repeat, c.quick ? 2000 : 20000)});
  }
  return cpus;
}

json BenchSweep(const BenchConfig& c) {
  const int subjects = c.quick ? 2 : 8;
  const Scenario base = GaitScenario(c.quick ? 2.0 : 20.0);
  KeepScenarioModel(base);  // as `exotwin sweep`: loaded once, the workers inherit it
  auto run = [&](int workers) {
    const auto outcomes = RunForked(subjects, workers, [&](size_t i) {
      RunOptions o;
      o.out_dir = c.scratch + "/sweep_j" + std::to_string(workers) + "/subject_" + std::to_string(i);
      return RunScenarioJob(WithPopulationSubject(base, 1, static_cast<int>(i)), o);
    });
    for (const JobOutcome& o : outcomes)
      if (o.exit_code != kJobOk && o.exit_code != kJobCheckFailed)
        throw std::runtime_error("bench sweep: a run failed (exit " + std::to_string(o.exit_code) + ")");
  };
  // Wall and CPU time of the fastest of `repeat` calls: cpu / wall = the cores the pool actually got.
  struct Timing {
    double wall = std::numeric_limits<double>::infinity(), children = 0, self = 0;
  };
  auto timed = [&](int workers) {
    Timing best;
    for (int i = 0; i < std::max(1, c.repeat); ++i) {
      const double c0 = ChildrenCpuSeconds(), p0 = SelfCpuSeconds();
      const auto t0 = std::chrono::steady_clock::now();
      run(workers);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (wall < best.wall) best = {wall, ChildrenCpuSeconds() - c0, SelfCpuSeconds() - p0};
    }
    return best;
  };
  // One worker on the fastest CPU (where the scheduler may put it, and where the single-threaded
  // probes run), two on all of them: the speed-up the machine's CPUs allow is SpeedupBoundOfCpus.
  Timing j1;
  {
    const ScopedCpuPin pin(FastestCpu(c.cpus));
    j1 = timed(1);
  }
  const Timing j2 = timed(2);
  const double bound = SpeedupBoundOfCpus(c.cpus);
  const double t1 = j1.wall, t2 = j2.wall, cpu1 = j1.children, cpu2 = j2.children, parent1 = j1.self;
  // The parent's own work (fork, wait, reading results) is the serial part of a sweep; with it,
  // Amdahl's law bounds the speed-up 2 idle cores would give (memory bandwidth not modelled).
  const double serial = parent1 / std::max(1e-12, parent1 + cpu1);
  return json{{"status", "ok"},
              {"runs", subjects},
              {"sim_s_per_run", base.protocol.duration},
              {"jobs1_s", t1},
              {"jobs2_s", t2},
              {"speedup_2_jobs", t1 / t2},
              {"target_speedup", 1.85},
              {"cores_used_jobs1", cpu1 / t1},
              {"cores_used_jobs2", cpu2 / t2},
              {"serial_fraction", serial},
              {"amdahl_speedup_2_idle_cores", 1.0 / (serial + (1.0 - serial) / 2.0)},
              {"jobs1_pinned_to_fastest_cpu", FastestCpu(c.cpus)},
              {"speedup_bound_of_these_cpus", bound},
              {"rows", BenchRowsJson({{"sweep " + std::to_string(subjects) + " subjects, --jobs 2", t1 / t2, "x",
                                       "the same sweep with --jobs 1 (on the fastest CPU)", ">= 1.85x",
                                       Seconds(t2) + " vs " + Seconds(t1) + ", cores used " +
                                           std::to_string(cpu2 / t2).substr(0, 4) + "; these CPUs allow " +
                                           std::to_string(bound).substr(0, 4) + "x"},
                                      {"sweep: the parent's share of the CPU time", 100.0 * serial, "%",
                                       "parent + workers, --jobs 1", "< 2 %",
                                       Seconds(parent1) + " of " + Seconds(parent1 + cpu1)}})}};
}

}  // namespace exotwin

namespace exotwin {
namespace {

// SCHED_FIFO priority the real-time rows ask for (granted or not: the row says which).
constexpr int kBenchRtPriority = 50;

// The link figures of one real-time run: gait for `duration` s, serve's twin here and exotwin-controller
// as its child, both at kBenchRtPriority when the kernel grants it, with one core kept busy by a
// spinning child process when `busy_core`.
json RealtimeRun(const BenchConfig& c, const std::string& controller_bin, double duration, bool busy_core) {
  pid_t busy = -1;
  if (busy_core) {
    busy = fork();
    if (busy == 0) {
      for (volatile unsigned long i = 0;; i = i + 1) {
      }
    }
  }
  const std::string dir = c.scratch + (busy_core ? "/rt_busy" : "/rt_idle");
  std::filesystem::create_directories(dir);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t run = fork();
  if (run == 0) {  // its own process: the priority taken is not the bench's
    const RealtimeGrant g = RequestRealtime(kBenchRtPriority);
    WriteFileAtomic(dir + "/grant.txt", g.fifo ? "SCHED_FIFO " + std::to_string(g.priority) + (g.memory_locked ? ", memory locked" : "")
                                               : "normal priority (refused: " + g.refused + ")");
    try {
      RunOptions opt;
      opt.out_dir = dir;
      Scenario s = GaitScenario(duration);
      RunWithControllerProcess(s, opt, controller_bin, 10.0, ServeClock::kRealtime);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench: realtime run: %s\n", e.what());
      _exit(1);
    }
    _exit(0);
  }
  int st = 0;
  waitpid(run, &st, 0);
  if (busy > 0) {
    kill(busy, SIGKILL);
    waitpid(busy, nullptr, 0);
  }
  if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) return Unavailable("the real-time run failed");
  const json r = json::parse(ReadTextFile(dir + "/result.json", "result", "JSON"));
  const json& m = r.at("metrics");
  return json{{"load", busy_core ? "one core kept busy (a spinning process)" : "no added load"},
              {"scheduling", ReadTextFile(dir + "/grant.txt", "", "text")},
              {"duration_s", duration},
              {"jitter_p50_us", m.at("link_jitter_p50_us")},
              {"jitter_p99_us", m.at("link_jitter_p99_us")},
              {"jitter_max_us", m.at("link_jitter_max_us")},
              {"late_cycles", m.at("link_late_cycles")},
              {"missed_cycles", m.at("link_missed_cycles")}};
}

// The machine's floor (DeadlineLoopJitter): the real-time runs' tick loop with no twin and no
// controller, for `duration` s at the controller's 1 kHz, in a child process at kBenchRtPriority (when
// granted) with its memory locked and the same spin before each deadline as serve's (--rt-spin's
// default). Late: ticks that started half a period or more after their deadline (the twin's answer
// window); missed: a whole period or more (the next tick's deadline had passed).
json FloorRun(const BenchConfig& c, double duration) {
  constexpr double kPeriod = 1e-3, kSpin = 100e-6;
  const std::string dir = c.scratch + "/rt_floor";
  std::filesystem::create_directories(dir);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t run = fork();
  if (run == 0) {
    const RealtimeGrant g = RequestRealtime(kBenchRtPriority);
    std::vector<double> j = DeadlineLoopJitter(kPeriod, duration, kSpin);
    long late = 0, missed = 0;
    for (const double x : j) late += x >= 0.5 * kPeriod, missed += x >= kPeriod;
    std::sort(j.begin(), j.end());
    const json r{{"scheduling", g.fifo ? "SCHED_FIFO " + std::to_string(g.priority) + (g.memory_locked ? ", memory locked" : "")
                                       : "normal priority (refused: " + g.refused + ")"},
                 {"ticks", j.size()},
                 {"jitter_p50_us", 1e6 * Percentile(j, 0.5)},
                 {"jitter_p99_us", 1e6 * Percentile(j, 0.99)},
                 {"jitter_max_us", j.empty() ? 0.0 : 1e6 * j.back()},
                 {"late_ticks", late},
                 {"missed_ticks", missed}};
    try {
      WriteFileAtomic(dir + "/floor.json", r.dump());
    } catch (...) {
      _exit(1);
    }
    _exit(0);
  }
  int st = 0;
  waitpid(run, &st, 0);
  if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) return Unavailable("the floor run failed");
  json r = json::parse(ReadTextFile(dir + "/floor.json", "floor", "JSON"));
  r["duration_s"] = duration;
  return r;
}

std::string Us(double us) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f us", us);
  return b;
}

}  // namespace

json BenchLink(const BenchConfig& c) {
  const std::string bin = DefaultControllerBinary();
  if (bin.empty()) return Unavailable("exotwin-controller not found next to exotwin");
  const double duration = c.quick ? 5.0 : 60.0;
  Scenario s = ReadScenario(DataPath("scenarios/gait_2kmh.yaml"));
  s.protocol.duration = duration;
  RunOptions in_opt, out_opt;
  in_opt.out_dir = c.scratch + "/link_in_process";
  out_opt.out_dir = c.scratch + "/link_lockstep";
  const double in_process = BestOf(c.repeat, [&] { RunScenario(s, in_opt); });
  auto identical = [&] {  // the lockstep run's logs are the in-process run's
    return ReadTextFile(in_opt.out_dir + "/measured.csv", "", "CSV") == ReadTextFile(out_opt.out_dir + "/measured.csv", "", "CSV") &&
           ReadTextFile(in_opt.out_dir + "/truth.csv", "", "CSV") == ReadTextFile(out_opt.out_dir + "/truth.csv", "", "CSV");
  };
  json j{{"status", "ok"}, {"duration_s", duration}, {"in_process_s", in_process}};
  std::vector<BenchRow> rows;
  // Each transport unpinned (the ends spin, on the CPUs the scheduler gives them), then both processes
  // pinned to one CPU (the controller inherits the pin): the hand-over is then a switch on that CPU
  // instead of a wake-up of the other (the placement of regress's workers); over unix: neither end
  // spins, over shm: the waits yield the CPU.
  for (const BusKind transport : {BusKind::kUnix, BusKind::kShm}) {
    const std::string scheme = transport == BusKind::kShm ? "shm" : "unix";
    const double lockstep = BestOf(c.repeat, [&] {
      RunWithControllerProcess(s, out_opt, bin, 10.0, ServeClock::kLockstep, transport);
    });
    const bool same = identical();
    double one_cpu = 0;
    {
      const ScopedCpuPin pin(FastestCpu(c.cpus));
      if (pin.pinned())
        one_cpu = BestOf(c.repeat, [&] { RunWithControllerProcess(s, out_opt, bin, 10.0, ServeClock::kLockstep, transport); });
    }
    rows.push_back({"lockstep over " + scheme + ": serve + exotwin-controller, gait_2kmh " + Seconds(duration) +
                        (same && identical() ? " (logs identical)" : " (logs DIFFER)"),
                    lockstep / in_process, "x", "the in-process run, same scenario", "<= 3x",
                    Seconds(lockstep) + " vs " + Seconds(in_process)});
    if (one_cpu > 0)
      rows.push_back({"lockstep over " + scheme + ", both processes pinned to one CPU" +
                          (transport == BusKind::kShm ? ", waits yield" : ", no spin"),
                      one_cpu / in_process, "x", "the in-process run, same scenario", "<= 3x",
                      Seconds(one_cpu) + " vs " + Seconds(in_process)});
    j[scheme] = json{{"lockstep_s", lockstep},
                     {"ratio_lockstep_to_in_process", lockstep / in_process},
                     {"lockstep_one_cpu_s", one_cpu},
                     {"logs_identical", same && identical()}};
  }
  if (!c.quick) {  // the whole suite, both ways (about a minute)
    try {
      const double regress = BestOf(1, [&] { RunSelf({"regress", "--out", c.scratch + "/regress_in"}); });
      const double remote = BestOf(1, [&] { RunSelf({"regress", "--controller-process", "--out", c.scratch + "/regress_out"}); });
      j["regress_s"] = regress;
      j["regress_controller_process_s"] = remote;
      rows.push_back({"regress --controller-process (the shipped suite, over shm)", remote / regress, "x", "regress, in-process",
                      "<= 3x", Seconds(remote) + " vs " + Seconds(regress)});
    } catch (const std::exception& e) {
      j["regress"] = Unavailable(e.what());
    }
  }
  const double rt_duration = c.quick ? 2.0 : 60.0;
  for (const bool busy : {false, true}) {
    const json r = RealtimeRun(c, bin, rt_duration, busy);
    j[busy ? "realtime_busy_core" : "realtime_idle"] = r;
    if (r.value("status", "") == "unavailable") continue;
    rows.push_back({"realtime gait " + Seconds(rt_duration) + ", " + r.at("load").get<std::string>() + ", " +
                        r.at("scheduling").get<std::string>(),
                    r.at("jitter_p99_us").get<double>(), "us p99", "tick start vs its deadline", "<= 100 us",
                    "p50 " + Us(r.at("jitter_p50_us")) + ", max " + Us(r.at("jitter_max_us")) + " (<= 1000 us), late " +
                        std::to_string(r.at("late_cycles").get<long>()) + ", missed " +
                        std::to_string(r.at("missed_cycles").get<long>())});
  }
  const json floor = FloorRun(c, rt_duration);
  j["realtime_floor"] = floor;
  if (floor.value("status", "") != "unavailable")
    rows.push_back({"machine floor: the same deadline loop, no twin, " + Seconds(rt_duration) + ", " +
                        floor.at("scheduling").get<std::string>(),
                    floor.at("jitter_p99_us").get<double>(), "us p99", "tick start vs its deadline", "",
                    "p50 " + Us(floor.at("jitter_p50_us")) + ", max " + Us(floor.at("jitter_max_us")) + ", late " +
                        std::to_string(floor.at("late_ticks").get<long>()) + ", missed " +
                        std::to_string(floor.at("missed_ticks").get<long>())});
  j["rows"] = BenchRowsJson(rows);
  return j;
}

}  // namespace exotwin
