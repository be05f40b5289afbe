// The HAL-3 scenario runner: see hal_runner.h.
#include "runner/hal_runner.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "analysis/csv_table.h"
#include "analysis/stress_metrics.h"
#include "controller/hal_loop.h"
#include "core/error.h"
#include "hwsim/emg_node.h"
#include "hwsim/hal3_knee_node.h"
#include "hwsim/virtual_can_bus.h"
#include "protocol/candump.h"
#include "runner/hal_emg_calibration.h"
#include "runner/sweep_plots.h"
#include "sim/hal3_plant.h"
#include "sim/muscles.h"
#include "sim/subjects.h"
#include "sim/synthetic_emg.h"

namespace exotwin {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kExt = 1, kFlex = 3;  // EMG channels of HAL's two sensor units: VM, ST
constexpr double kPaperViscousOptimum = 1.56;  // Lee & Sankai sec. 4.2, N m/(rad/s)
constexpr double kRmsWindow = 0.1;  // s, T of eq. (1), controller and calibration alike

struct Mean {
  double sum = 0;
  long n = 0;
  void Add(double v) { sum += v, ++n; }
  double get() const { return n ? sum / n : 0.0; }
};

// Ground truth the on-line RLS (eq. 8-13) can identify. Eq. (4) lets D(t), K(t) vary, and in the
// twin they vary within every swing (co-contraction only in swing-down, the contraction's velocity /
// angle factors with the activation). An estimator of CONSTANT D, K over its memory (forgetting
// factor rho: weight rho^(k-j), ~dt/(1-rho) = 1 s) converges, with the exact input, to the weighted
// least-squares projection of the operator's true viscoelastic torque v = mu - mu_c onto (thd, th):
//   (D, K) = argmin sum_j rho^(k-j) (v_j + D thd_j + K th_j)^2,
// not to the time mean of D(t), K(t), which no window of data determines when D(t), K(t) switch with
// the swing phase. Seed 1: K(t) ~ 7 N m/rad in the swing-down co-contraction and ~1 otherwise, time
// mean ~3.1; the projection ~1.0; the same RLS fed the exact mu_c gives D within 2 % and K within
// 6 % of the projection (and K 67 % below the time mean). The 20 % check compares with this truth.
class ProjectedViscoelasticity {
 public:
  explicit ProjectedViscoelasticity(double rho) : rho_(rho) {}
  // v: true viscoelastic torque (N m), thd (rad/s), th (rad).
  void Add(double v, double thd, double th) {
    svv_ = rho_ * svv_ + thd * thd, svp_ = rho_ * svp_ + thd * th, spp_ = rho_ * spp_ + th * th;
    sv1_ = rho_ * sv1_ + v * thd, sv2_ = rho_ * sv2_ + v * th;
  }
  bool valid() const { return svv_ * spp_ - svp_ * svp_ > 1e-9 * (svv_ * spp_ + 1e-30); }
  double D() const { return -(spp_ * sv1_ - svp_ * sv2_) / (svv_ * spp_ - svp_ * svp_); }  // N m s/rad
  double K() const { return -(svv_ * sv2_ - svp_ * sv1_) / (svv_ * spp_ - svp_ * svp_); }  // N m/rad

 private:
  double rho_, svv_ = 0, svp_ = 0, spp_ = 0, sv1_ = 0, sv2_ = 0;
};

Hal3PlantParams PlantParams(const Scenario& s) {
  if (!s.subject.params_file.empty())
    throw InputError(s.source + ": subject.params: device hal3 takes a preset or random_seed subject");
  if (!s.subject.preset.empty()) return Hal3ParamsForSubject(PresetSubject(s.subject.preset));
  if (s.subject.random_seed) return Hal3ParamsForSubject(DrawSubject(*s.subject.random_seed, 0));
  return Hal3PlantParams();
}

// The operator's muscles: ground truth drawn from the seed, plus the relaxed knee's own passive
// viscoelasticity about the hanging leg (our choice: K0 = 1.5 N m/rad, D0 = 0.3 N m s/rad, of the
// order of pendulum-test values for a relaxed knee; Hayashi's D, K include it).
MuscleParams OperatorMuscles(const Scenario& s) {
  MuscleParams p = DrawMuscleParams(s.human.muscle_seed);
  p.K0[1] = 1.5;
  p.D0[1] = 0.3;
  return p;
}

controller::HalLoopConfig LoopConfig(const Scenario& s, const Hal3PlantParams& pp,
                                     const controller::HalEmgCoefficients& emg, double B_v) {
  controller::HalLoopConfig c;
  const std::string& mode = s.hal.mode;
  c.mode = mode == "none" ? controller::HalMode::kNone
                          : (mode == "assist" ? controller::HalMode::kAssist : controller::HalMode::kImpedance);
  c.rate_hz = s.controller.rate_hz;
  c.rms_window = kRmsWindow;
  c.tau_max = std::min(60.0, s.controller.torque_limit);
  c.extensor_channel = kExt;
  c.flexor_channel = kFlex;
  c.velocity.sample_rate_hz = s.controller.rate_hz;
  // tau_c (Lee & Sankai; Hayashi eq. 6): identified exoskeleton (eq. 15; the twin hands over its
  // true values: identification itself is tested in tests/controller/hal_assist_test.cc). Inertia
  // is not compensated (I_v = I: a causal acceleration estimate from a potentiometer is too noisy).
  c.impedance.actual = {pp.hal_I(), pp.R, pp.hal_mgl(), pp.C};
  c.impedance.target = {pp.hal_I(), B_v, pp.hal_mgl(), 0.0};
  controller::HalAssistConfig& a = c.assist;
  a.dt = 1.0 / s.controller.rate_hz;
  a.alpha_mu = s.hal.alpha_mu;
  a.alpha_zeta = s.hal.alpha_zeta;
  a.emg = emg;
  a.tau_max = c.tau_max;
  a.rls.dt = a.dt;
  a.rls.R = pp.R;        // eq. (15)
  a.rls.mgl = pp.mgl();  // eq. (14)
  a.rls.I0 = pp.I();
  a.rls.gravity_in_input = s.hal.rls_gravity_in_input;
  a.rls.known_inertia = s.hal.rls_known_inertia;
  if (s.hal.rls_friction_in_input) {  // the identified C of tau_c (eq. 15), smoothed as tau_c smooths it
    a.friction_C = c.impedance.actual.C;
    a.friction_eps = c.impedance.coulomb_eps;
  }
  return c;
}

struct TrialOut {
  std::map<std::string, double> m;
};

TrialOut RunTrial(const Scenario& s, const RunOptions& opt, uint64_t seed, double B_v,
                  const std::string& suffix, RunResult* result, CandumpWriter* can_log,
                  double epoch) {
  const Hal3PlantParams pp = PlantParams(s);
  Hal3Plant plant;
  plant.SetParams(pp);
  const double dt = plant.timestep();
  const double ctrl_dt = 1.0 / s.controller.rate_hz;
  if (std::abs(ctrl_dt / dt - std::round(ctrl_dt / dt)) > 1e-9 || ctrl_dt < dt - 1e-12)
    throw InputError(s.source + ": controller.rate_hz: expected the physics rate (1000 Hz) divided by an integer");
  const int steps_per_tick = static_cast<int>(std::lround(ctrl_dt / dt));

  const MuscleParams mp = OperatorMuscles(s);
  const SyntheticEmgConfig emg_cfg = DefaultSyntheticEmgConfig();
  const HalEmgCalibrationSpec cal{kExt, kFlex, kRmsWindow, s.hal.calibration_levels, 0.02, s.hal.calibration_hi,
                                  s.hal.calibration_rest};
  const controller::HalEmgCoefficients coeffs = CalibrateHalEmg(mp, emg_cfg, cal, seed + 11);
  MuscleModel muscles(mp, dt);
  TrackingGains gains = KneeSwingBehaviour::KneeSwingGains();
  gains.inertia[1] = pp.I();  // a rehearsed operator knows its leg + HAL (Hayashi sec. III)
  gains.feedback_delay = s.hal.operator_delay;
  gains.cocontraction_synergy = s.hal.cc_synergy;
  KneeSwingBehaviour swing(mp, s.hal.swing_freq, s.hal.cc_up, s.hal.cc_down, pp.mgl(), gains);
  SyntheticEmg emg(emg_cfg, seed + 13);

  hwsim::VirtualCanBus bus(BusConfigOf(s.hardware, seed));
  TapToCandump(bus, can_log, epoch);
  auto* ctrl_ep = bus.AddNode("hal_controller", {msg::kIdHalKneeStatus, msg::kIdEmgSamples});
  auto* knee_ep = bus.AddNode("hal_knee", {msg::kIdHalKneeCommand});
  auto* emg_ep = bus.AddNode("emg_amplifier", {msg::kIdControllerHeartbeat});  // receives nothing used
  hwsim::Hal3KneeNodeSpec ks;
  ks.torque_sensor_skew = s.hardware.torque_sensor_skew;
  ks.driver.lag = s.hardware.motor_lag;
  ks.driver.limit = std::min(60.0, s.hardware.torque_limit);
  ks.driver.watchdog = s.hardware.watchdog;
  hwsim::Hal3KneeNode knee(ks, knee_ep, seed + 1);
  hwsim::EmgNode emg_node(hwsim::EmgAmplifierSpec{}, emg_ep);
  const controller::HalLoopConfig loop_cfg = LoopConfig(s, pp, coeffs, B_v);
  controller::HalLoop loop(loop_cfg, ctrl_ep);

  std::unique_ptr<CsvStreamWriter> measured, truth_log;
  if (s.log_measured_csv) {
    const std::vector<std::string> comments = {
        "exotwin run " + s.name + " (HAL-3) mode " + s.hal.mode + " B_v " + std::to_string(B_v) +
        " seed " + std::to_string(result->seed)};
    measured = std::make_unique<CsvStreamWriter>(
        opt.out_dir + "/measured" + suffix + ".csv",
        std::vector<std::string>{"t", "q_knee", "tau_knee", "cmd_knee", "emg_GMAX", "emg_VM", "emg_RF",
                                 "emg_ST", "emg_GAS", "E_ext", "E_flex", "mu_hat", "D_hat", "K_hat"},
        comments);
    truth_log = std::make_unique<CsvStreamWriter>(
        opt.out_dir + "/truth" + suffix + ".csv",
        std::vector<std::string>{"t", "th", "thd", "tau_motor", "tau_muscle", "tau_interaction", "D_true",
                                 "K_true", "mu_contraction"},
        comments);
    result->files.push_back("measured" + suffix + ".csv");
    result->files.push_back("truth" + suffix + ".csv");
  }

  const double w = 2 * kPi * s.hal.swing_freq;
  plant.Reset(0.35, 0.65 * w, 0.0);
  const long n_steps = std::lround(s.protocol.duration / dt);
  const long log_every = std::max(1L, std::lround(1.0 / (s.log_rate_hz * dt)));
  Mean ext_up, ext_down, flex_up, flex_down, rect_up, strain_up, strain_down, mu_up;
  Mean D_hat, K_hat, D_true, K_true, D_proj, K_proj, track2;
  // Same memory as the RLS: its rho is per control tick, the sums here run per physics step.
  ProjectedViscoelasticity projected(std::pow(loop_cfg.assist.rls.rho, dt / ctrl_dt));
  std::vector<double> tau_m, m_e, m_f;
  double th_max = -10, th_min = 10, t = 0;
  // Timing of one physics step [t, t + dt], as runner.cc's (DESIGN.md "Sampling instant of a joint
  // node"): the plant holds the driver's output at t over [t, t + dt]; the knee node samples th(t)
  // and the frame torque at t at one instant; the controller ticks at t + dt/2 on that frame, and its
  // command shows in the driver's output at t + dt (one sample from sampling to torque). The frame
  // torque at t needs the acceleration a(t) of this step (Hal3Plant::interaction_torque: semi-implicit
  // Euler, a(t) from the state at t and the torques held over [t, t + dt]), so the step is computed
  // before the tick: everything it uses is fixed at t, and the controller sees the plant only
  // through the bus.
  double tau_motor = 0;  // the driver's output at t = 0: no command yet
  for (long k = 0; k < n_steps; ++k) {
    const double th_t = plant.th();
    const Eigen::Vector2d q(kPi / 2, th_t - kPi / 2), qd(0, plant.thd());
    muscles.Step(swing.Excitation(t, q, qd));
    const MuscleTorques mt = muscles.Torques(q, qd);
    const double mu = mt.total()[1];
    const double applied = tau_motor;  // held over [t, t + dt], for the metrics and truth.csv
    plant.Step(tau_motor, mu);
    knee.Sample(t, th_t, plant.interaction_torque());  // one instant: th(t) and the frame torque at t
    if (k % steps_per_tick == 0) {
      bus.AdvanceTo(t + 0.5 * dt);
      loop.Tick(t + 0.5 * dt);
    }
    bus.AdvanceTo(t + 0.999 * dt);
    tau_motor = knee.Applied(t + dt, dt);  // the driver at t + dt
    t = plant.time();
    const double th = plant.th(), thd = plant.thd();
    const MuscleVec raw = emg.Sample(muscles.electrical_activation());
    std::array<double, hwsim::EmgAmplifier::kChannels> v{};
    for (int c = 0; c < kNumMuscles; ++c) v[c] = raw[c];
    emg_node.Sample(t, v);

    // Ground truth of Hayashi eq. (4): muscle torque = mu_c - D thd - K th with the contraction's
    // angle/velocity factors (eq. 26-27 structure, q_c = hanging) moved into D and K.
    const MuscleVec& a = muscles.mechanical_activation();
    double sum_alpha_a = 0, mu_c = 0, mu_ext = 0;
    for (int m = 0; m < kNumMuscles; ++m) {
      const int sg = ActionSign(MuscleAt(m), 1);
      if (!sg) continue;
      sum_alpha_a += mp.alpha(m, 1) * a[m];
      mu_c += sg * mp.alpha(m, 1) * a[m];
      if (sg > 0) mu_ext += mp.alpha(m, 1) * a[m];
    }
    const double Dt = mt.D[1] + mp.gamma[1] * sum_alpha_a, Kt = mt.K[1] - mp.beta[1] * sum_alpha_a;
    projected.Add(mu - mu_c, thd, th);  // v = -D thd - K th (up to the ForceFactor clamp)
    const controller::HalTelemetry& tel = loop.telemetry();
    if (t >= s.hal.settle) {
      Eigen::Vector2d qs, qds, qdds;
      KneeSwingBehaviour::Intended(t, s.hal.swing_freq, qs, qds, qdds);
      track2.Add(std::pow(qs[1] + kPi / 2 - th, 2));
      th_max = std::max(th_max, th);
      th_min = std::min(th_min, th);
      if (th > 0 && thd > 0) {
        ext_up.Add(tel.E_e), flex_up.Add(tel.E_f), rect_up.Add(std::abs(emg_node.last_output()[kExt]));
        strain_up.Add(knee.last_strain()), mu_up.Add(mu_ext);
      } else if (th > 0 && thd < 0) {
        ext_down.Add(tel.E_e), flex_down.Add(tel.E_f), strain_down.Add(knee.last_strain());
      }
      tau_m.push_back(mu);
      m_e.push_back(emg_node.last_output()[kExt]);
      m_f.push_back(emg_node.last_output()[kFlex]);
      D_true.Add(Dt), K_true.Add(Kt);
      if (projected.valid()) D_proj.Add(projected.D()), K_proj.Add(projected.K());
      D_hat.Add(tel.assist.D), K_hat.Add(tel.assist.K);
    }
    if (measured && k % log_every == 0) {
      const auto& o = emg_node.last_output();
      const double row[] = {t, tel.th, tel.strain, tel.tau_cmd, o[0], o[1], o[2], o[3], o[4],
                            tel.E_e, tel.E_f, tel.assist.mu_hat, tel.assist.D, tel.assist.K};
      measured->Row(row, 14);
      const double trow[] = {t, th, thd, applied, mu, plant.interaction_torque(), Dt, Kt, mu_c};
      truth_log->Row(trow, 9);
    }
    if (opt.on_sample && k % log_every == 0) {
      const double qa[2] = {kPi / 2, th - kPi / 2}, ta[2] = {0, applied};
      opt.on_sample(t, qa, ta);
    }
  }
  TrialOut out;
  auto& m = out.m;
  m["samples"] = static_cast<double>((n_steps + log_every - 1) / log_every);  // log-rate rows (k % log_every == 0)
  m["emg_ext_up_V"] = ext_up.get();
  m["emg_ext_down_V"] = ext_down.get();
  m["emg_flex_up_V"] = flex_up.get();
  m["emg_flex_down_V"] = flex_down.get();
  m["emg_ext_up_rect_V"] = rect_up.get();
  m["strain_up_Nm"] = strain_up.get();
  m["strain_down_Nm"] = strain_down.get();
  m["mu_ext_up_Nm"] = mu_up.get();
  m["J_tau_m"] = tau_m.empty() ? 0.0 : MeanAbsMoment(tau_m, dt);  // Lee & Sankai eq. (12)
  m["J_e"] = IntegratedMyoelectricity(m_e, dt);                   // eq. (16)
  m["J_f"] = IntegratedMyoelectricity(m_f, dt);                   // eq. (15)
  m["th_max"] = th_max;
  m["th_min"] = th_min;
  m["tracking_rms_rad"] = std::sqrt(track2.get());
  m["plant_I"] = pp.I();
  m["plant_mgl"] = pp.mgl();
  m["emg_a_ext"] = coeffs.extensor.a;
  m["emg_a_flex"] = coeffs.flexor.a;
  m["emg_b_ext"] = coeffs.extensor.b;
  m["emg_b_flex"] = coeffs.flexor.b;
  m["emg_baseline_ext_V"] = coeffs.baseline_e;
  m["emg_baseline_flex_V"] = coeffs.baseline_f;
  if (s.hal.mode == "assist") {
    m["rls_D_mean"] = D_hat.get();
    m["rls_K_mean"] = K_hat.get();
    m["truth_D_mean"] = D_proj.get();  // identifiable truth (ProjectedViscoelasticity)
    m["truth_K_mean"] = K_proj.get();
    m["truth_D_timemean"] = D_true.get();  // plain time means of D(t), K(t), for information
    m["truth_K_timemean"] = K_true.get();
    m["rls_D_err_pct"] = 100 * std::abs(D_hat.get() / D_proj.get() - 1);
    m["rls_K_err_pct"] = 100 * std::abs(K_hat.get() / K_proj.get() - 1);
    // The same error against the stiffness the RLS actually sees, K' = K + G(th) ~ K + Mgl (eq. 8):
    // K is ~6 % of K' in the seated swing, so this says how close eq. (13) comes on its own scale.
    m["rls_K_err_pct_of_Kprime"] = 100 * std::abs(K_hat.get() - K_proj.get()) / (K_proj.get() + pp.mgl());
    m["rls_I_hat"] = loop.assist().rls().I();
  }
  const hwsim::CanBusStatistics st = bus.Statistics();
  m["bus_load_pct"] = st.mean_load_percent;
  m["frames_dropped"] = static_cast<double>(st.drops);
  m["emg_gaps"] = loop.telemetry().emg_gaps;
  return out;
}

std::string Fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%g", v);
  return b;
}

}  // namespace

RunResult RunHalScenario(const Scenario& s, const RunOptions& opt) {
  if (s.device != Device::kHal3) throw InputError(s.source + ": device: RunHalScenario needs device: hal3");
  RunResult result;
  result.scenario = s.name;
  result.seed = opt.seed ? *opt.seed : s.seed;
  std::filesystem::create_directories(opt.out_dir);
  std::unique_ptr<CandumpWriter> can_log;
  if (!opt.can_log.empty()) can_log = std::make_unique<CandumpWriter>(opt.can_log, "can0");
  const auto wall0 = std::chrono::steady_clock::now();
  auto& m = result.metrics;

  const bool sweep = !s.hal.sweep_viscosity.empty();
  const std::vector<double> values = sweep ? s.hal.sweep_viscosity : std::vector<double>{s.hal.virtual_viscosity};
  const int runs = sweep ? static_cast<int>(values.size()) : s.protocol.trials;
  std::vector<std::map<std::string, double>> per_run;
  for (int i = 0; i < runs; ++i) {
    const double B_v = sweep ? values[i] : values[0];
    // A sweep keeps the same seed for every value (common random numbers): only B_v changes.
    const uint64_t seed = result.seed * 7919ull + static_cast<uint64_t>(sweep ? 0 : i);
    const std::string suffix = runs > 1 ? "_trial" + std::to_string(i + 1) : "";
    per_run.push_back(RunTrial(s, opt, seed, B_v, suffix, &result, can_log.get(), i * (s.protocol.duration + 1.0)).m);
  }
  // Single run (or trials): the metrics of the last run; a sweep adds per-value metrics.
  for (const auto& kv : per_run.back()) m[kv.first] = kv.second;
  double samples = 0;
  for (const auto& r : per_run) samples += r.at("samples");
  m["samples"] = samples;  // all runs (trials or sweep values), as the EXOwheel runner counts trials
  if (sweep) {
    std::vector<double> J, Je, Jf;
    for (const auto& r : per_run) J.push_back(r.at("J_tau_m")), Je.push_back(r.at("J_e")), Jf.push_back(r.at("J_f"));
    const std::vector<double> Jme = NormalizeByMax(Je), Jmf = NormalizeByMax(Jf);  // eq. (13)-(18)
    const size_t best = ArgMin(J);
    for (size_t i = 0; i < values.size(); ++i) {
      m["J_tau_m@" + Fmt(values[i])] = J[i];
      m["J_me@" + Fmt(values[i])] = Jme[i];
      m["J_mf@" + Fmt(values[i])] = Jmf[i];
    }
    m["sweep_argmin_viscosity"] = values[best];
    m["sweep_min_J_tau_m"] = J[best];
    // Rise of the mean musculoskeletal moment from the trough to the ends of the swept range, %: a
    // trough inside the range (Lee & Sankai Fig. 9) has both > 0.
    m["sweep_rise_low_pct"] = 100 * (J.front() / J[best] - 1);
    m["sweep_rise_high_pct"] = 100 * (J.back() / J[best] - 1);
    m["sweep_argmin_J_me_viscosity"] = values[ArgMin(Je)];
    m["sweep_paper_optimum"] = kPaperViscousOptimum;
    std::vector<double> bv = values;
    WriteCsv(opt.out_dir + "/sweep.csv", {"B_v", "J_tau_m", "J_e", "J_f", "J_me", "J_mf"},
             {&bv, &J, &Je, &Jf, &Jme, &Jmf},
             {"Lee & Sankai eq. (12)-(18) over the virtual viscous coefficient B_v (N m s/rad)"});
    result.files.push_back("sweep.csv");
    // The curves of Lee & Sankai Fig. 9: each criterion over B_v, scaled to its maximum (J_me, J_mf
    // are eq. 13-18's own normalisation), with the twin's and the paper's optimum marked.
    LineChart chart;
    chart.title = s.name + ": stress criteria over the virtual viscous coefficient (Lee & Sankai Fig. 9)";
    chart.x_label = "virtual viscous coefficient B_v (N m s/rad)";
    chart.y_label = "criterion / its maximum";
    const double J_max = *std::max_element(J.begin(), J.end());
    std::vector<double> J_scaled;
    for (double v : J) J_scaled.push_back(J_max > 0 ? v / J_max : 0.0);
    chart.series = {{"J_tau_m (eq. 12) / max", bv, J_scaled, "#c0392b"},
                    {"J_me, extensor (eq. 16)", bv, Jme, "#2c6fbb"},
                    {"J_mf, flexor (eq. 15)", bv, Jmf, "#2e9a48"}};
    chart.markers = {{values[best], "twin minimum " + Fmt(values[best]), "#c0392b"},
                     {kPaperViscousOptimum, "paper " + Fmt(kPaperViscousOptimum), "#555555"}};
    WriteFileAtomic(opt.out_dir + "/sweep.svg", LineChartSvg(chart));
    result.files.push_back("sweep.svg");
  }
  m["runs"] = runs;
  m["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  FinishRun(s, result, opt.out_dir + "/result.json");
  return result;
}

}  // namespace exotwin
