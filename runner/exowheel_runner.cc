// The EXOwheel closed-loop runner: see exowheel_runner.h.
#include "runner/exowheel_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>

#include "formats/csv_table.h"
#include "core/output_path.h"
#include "controller/exo_controller.h"
#include "dsp/butterworth.h"
#include "model/leg_dynamics.h"
#include "render/render_plugin.h"
#include "runner/cosim_rig.h"
#include "runner/exowheel_setup.h"
#include "runner/fault_injection.h"
#include "runner/progress_bar.h"
#include "runner/remote_controller.h"
#include "sim/muscles.h"
#include "sim/plant.h"
#include "sim/synthetic_emg.h"

namespace exotwin {
namespace {

// rad -> deg as (rad * 180) / pi, the rounding the tracking metrics' baselines hold bit for bit
// (rad * kDegPerRad differs in the last bit for about a quarter of the values).
double Deg(double rad) { return rad * 180.0 / M_PI; }

struct Accum {
  double sum2 = 0, max = 0;
  size_t n = 0;
  void Add(double e) {
    sum2 += e * e;
    max = std::max(max, std::abs(e));
    ++n;
  }
  double rms() const { return n ? std::sqrt(sum2 / n) : 0.0; }
};

// What the metrics of result.json accumulate over the trials.
struct ExowheelTotals {
  Accum track[2], torque[2];
  double fault_time = -1, safe_time = -1, max_torque_after_safe = 0, bus_load_max = 0;
  double torque_after_fault = 0;  // max |applied torque| from 50 ms after the first fault on
  int final_state = 0;
  uint64_t frames_total = 0, frames_dropped = 0, error_frames = 0;
  size_t samples = 0;
};

// One trial of the EXOwheel on the rig: plant (shared across trials), joint modules, the subject
// (muscles, behaviour, surface EMG), faults, logs and the metrics' accumulation.
class ExowheelTrial : public CosimDevice {
 public:
  ExowheelTrial(const Scenario& s, const RunOptions& opt, const LegParams& truth, Plant& plant,
                const CosimSchedule& schedule, int trial, CandumpWriter* can_log, RunBag* bag, RunResult* result,
                ExowheelTotals* totals)
      : s_(s), opt_(opt), plant_(plant), bag_(bag), schedule_(schedule), result_(result), totals_(totals), trial_(trial),
        seed_(result->seed * 7919ull + static_cast<uint64_t>(trial)),
        trajectory_(BuildTrajectory(s, trial)),
        rig_(BusConfigOf(s.hardware, seed_), can_log, TrialEpoch(s, trial)),  // trials follow each other
        ctrl_ep_(rig_.bus().AddNode("controller", {msg::kIdJointStatusHip, msg::kIdJointStatusKnee, msg::kIdEmgSamples})),
        emg_ep_(rig_.bus().AddNode("emg_amplifier", {0x7FF})),  // sends only
        hip_(JointModuleSpecOf(s.hardware, 0, plant.effects().sensor[0], plant.timestep(), s.plant_effects_source),
             rig_.bus().AddNode("hip_module", {msg::kIdJointCommandHip}), seed_ + 1),
        knee_(JointModuleSpecOf(s.hardware, 1, plant.effects().sensor[1], plant.timestep(), s.plant_effects_source),
              rig_.bus().AddNode("knee_module", {msg::kIdJointCommandKnee}), seed_ + 2),
        ctrl_cfg_(ControllerConfig(s, truth)),
        ctrl_(ctrl_cfg_, trajectory_, ctrl_ep_),
        human_(truth.human.has_value()),
        emg_on_(human_ && s.human.emg) {
    trajectory_->Sample(0.0, &h0_, &k0_);
    const MuscleParams mp = SubjectMuscles(s, {h0_.q, k0_.q});
    muscles_ = std::make_unique<MuscleModel>(mp, plant.timestep());
    behaviour_ = BuildBehaviour(s, mp, trajectory_, seed_ + 3);
    emg_ = std::make_unique<SyntheticEmg>(ExowheelSyntheticEmgConfig(), seed_ + 4);
    if (emg_on_) rig_.AttachEmg(emg_ep_, muscles_.get(), emg_.get());
    for (const FaultSpec& f : s.faults) faults_.push_back({f, false});
    OpenLogs(truth, trial);
    plant.Reset({h0_.q, k0_.q}, {h0_.qd, k0_.qd}, 0.0);
    if (!opt.video_path.empty() && trial == 0) {
      RenderOptions ro;
      if (emg_on_) ro.emg_names = EmgChannelNames();  // the EMG panel's traces by muscle
      video_ = OpenVideo(plant.model(), opt.video_path, ro);
      const double dt = plant.timestep();
      envelope_.assign(5, dsp::SosFilter(dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1.0 / dt, 3.0)));
    }
    events_seen_ = result->events.size();
  }

  // The trial in parts (ExowheelSession): Begin sets the rig at t = 0; Advance runs up to `steps`
  // physics steps, the controller's ticks in them given `command` (hip, knee N m; null: its own law);
  // once the rig finished, Conclude adds the bus statistics and the final state to the totals and
  // returns the stop request that ended the trial early (its trial field left to the caller), if any.
  void Begin() {
    if (opt_.remote) opt_.remote->BeginTrial(trial_, ctrl_ep_, &result_->events);
    rig_.Begin(schedule_, *this);
  }
  long Advance(long steps, const double* command, const CosimProgress& progress) {
    command_ = command;
    const long ran = rig_.Advance(
        steps, [this](double t) { opt_.remote ? opt_.remote->Tick(t) : ctrl_.Tick(t, command_); }, progress);
    command_ = nullptr;
    return ran;
  }
  bool finished() const { return rig_.finished(); }
  std::optional<RunInterruption> Conclude() {
    const double t_end = rig_.time();
    if (video_) {
      video_->Finish(t_end);
      result_->files.push_back(opt_.video_path);
    }
    totals_->final_state = std::max(totals_->final_state, static_cast<int>(Telemetry().safety.state));
    const hwsim::CanBusStatistics st = rig_.bus().Statistics();
    totals_->frames_total += st.frames;
    totals_->frames_dropped += st.drops;
    totals_->error_frames += st.error_frames;
    totals_->bus_load_max = std::max(totals_->bus_load_max, st.mean_load_percent);
    if (!rig_.stopped_by()) return std::nullopt;
    return RunInterruption{rig_.stopped_by(), t_end, 0};
  }

  // The columns of measured.csv and truth.csv, and their rows at the last step's end (t).
  std::vector<std::string> MeasuredColumns() const {
    std::vector<std::string> c = {"t",       "q_hip",    "q_knee",  "tau_hip",  "tau_knee",
                                  "cmd_hip", "cmd_knee", "ref_hip", "ref_knee", "state"};
    if (emg_on_) c.insert(c.end(), {"emg_GMAX", "emg_VM", "emg_RF", "emg_ST", "emg_GAS"});
    return c;
  }
  static std::vector<std::string> TruthColumns() {
    return {"t", "q_hip", "q_knee", "qd_hip", "qd_knee", "tau_R_hip", "tau_R_knee", "tau_M_hip", "tau_M_knee"};
  }
  size_t MeasuredRow(double t, double* row) const {
    const auto& tel = Telemetry();
    const double r[] = {t, tel.est[0].q, tel.est[1].q, tel.tau_sensor[0], tel.tau_sensor[1],
                        tel.tau_cmd[0], tel.tau_cmd[1], tel.ref[0].q, tel.ref[1].q,
                        static_cast<double>(tel.safety.state), tel.emg[0], tel.emg[1], tel.emg[2],
                        tel.emg[3], tel.emg[4]};
    const size_t n = emg_on_ ? 15 : 10;
    std::copy(r, r + n, row);
    return n;
  }
  size_t TruthRow(double t, double* row) const {
    const Eigen::Vector2d qd = plant_.qd();
    const double r[] = {t, q_[0], q_[1], qd[0], qd[1], applied_[0], applied_[1], tau_M_[0], tau_M_[1]};
    std::copy(r, r + 9, row);
    return 9;
  }
  double time() const { return rig_.time(); }
  controller::SafetyState safety_state() const { return Telemetry().safety.state; }

  void BeginStep(double t) override {
    ApplyFaults(faults_, t, modules_, rig_.bus(), ctrl_ep_, s_.hardware, &result_->events);
    if (totals_->fault_time < 0) {
      for (const auto& f : faults_)
        if (f.active) totals_->fault_time = t;
    }
  }

  double StepPlant(double t) override {
    tau_M_ = Eigen::Vector2d::Zero();
    if (human_) {
      muscles_->Step(behaviour_->Excitation(t, plant_.q(), plant_.qd()));
      tau_M_ = muscles_->Torques(plant_.q(), plant_.qd()).total();
    }
    // The torques of this step, for the metrics and truth.csv (row t + dt: the state at t + dt and
    // the actuator and muscle torques held over [t, t + dt], the step that ended there).
    applied_[0] = tau_[0], applied_[1] = tau_[1];
    plant_.Step({tau_[0], tau_[1]}, tau_M_);  // the drivers' output at t, held over [t, t + dt]
    return plant_.time();
  }

  void LatchDrivers(double t, double dt) override {
    for (int j = 0; j < 2; ++j) tau_[j] = modules_[j]->Applied(t, dt);
  }

  void SampleNodes(double t) override {
    q_ = plant_.q();
    hip_.Sample(t, q_[0], tau_[0]);  // one instant: q(t) and the torque held from t
    knee_.Sample(t, q_[1], tau_[1]);
  }

  void EndStep(double t) override {
    const auto& tel = Telemetry();
    ExowheelTotals& m = *totals_;
    const bool after_ramp = t >= s_.protocol.ramp;
    if (tel.safety.state != controller::SafetyState::kRunning && m.safe_time < 0) m.safe_time = t;
    for (int j = 0; j < 2; ++j) {
      if (after_ramp && m.fault_time < 0) m.track[j].Add(Deg(tel.ref[j].q - q_[j]));
      m.torque[j].Add(applied_[j]);
      if (m.safe_time >= 0 && t > m.safe_time + 0.05)
        m.max_torque_after_safe = std::max(m.max_torque_after_safe, std::abs(applied_[j]));
      // Torque on the faulted joints from 50 ms after the fault on (the damping of a safe state on
      // the other joint is bounded separately by torque_max_after_safe).
      bool faulted_joint = false;
      for (const auto& f : faults_)
        faulted_joint |= f.active && FaultActsOn(f.spec, j);
      if (m.fault_time >= 0 && t > m.fault_time + 0.05 && faulted_joint)
        m.torque_after_fault = std::max(m.torque_after_fault, std::abs(applied_[j]));
    }
  }

  void LogSample(double t) override {
    ++totals_->samples;
    if (logs_.measured) {
      double row[15], trow[9];
      const auto& tel = Telemetry();
      // The bag's JointState velocity: the controller's estimate (a controller in another process does
      // not send it over the link: unknown, NaN).
      const double qd[2] = {tel.est[0].qd, tel.est[1].qd};
      logs_.measured->Row(row, MeasuredRow(t, row), opt_.remote ? nullptr : qd);
      logs_.truth->Row(trow, TruthRow(t, trow));
    }
    if (video_) AddVideoSample(t);
    if (opt_.on_sample) {
      const double qa[2] = {q_[0], q_[1]};
      opt_.on_sample(t, qa, applied_);
    }
  }

 private:
  // What the controller's tick saw and did: the in-process loop's, or the remote controller's telemetry.
  const controller::ControllerTelemetry& Telemetry() const {
    return opt_.remote ? opt_.remote->telemetry() : ctrl_.telemetry();
  }

  // measured[_trialN].csv and truth[_trialN].csv (logs.measured_csv).
  void OpenLogs(const LegParams& truth, int trial) {
    if (!s_.log_measured_csv) return;
    logs_ = OpenTrialLogs(
        opt_.out_dir, trial, s_.protocol.trials, MeasuredColumns(), TruthColumns(),
        {"exotwin run " + s_.name + " trial " + std::to_string(trial + 1) + " seed " + std::to_string(result_->seed),
         "subject truth: L1 " + std::to_string(truth.L1) + (truth.human ? " with human" : " exo only")},
        &result_->files, opt_.capture, schedule_.LogRows(), bag_, TrialEpoch(s_, trial));
  }

  void AddVideoSample(double t) {
    const auto& tel = Telemetry();
    OverlaySample os;
    os.t = t;
    os.q_hip = q_[0];
    os.q_knee = q_[1];
    // The twin's estimate: the controller's own model on its estimated state.
    const Eigen::Vector2d est =
        -ActuatorTorque(ctrl_cfg_.model, {tel.est[0].q, tel.est[1].q}, {tel.est[0].qd, tel.est[1].qd},
                        {tel.est[0].qdd, tel.est[1].qdd});
    for (int j = 0; j < 2; ++j) {
      os.tau_meas[j] = std::isfinite(tel.tau_sensor[j]) ? tel.tau_sensor[j] : 0.0;
      os.tau_est[j] = est[j];
    }
    if (emg_on_)
      for (int c = 0; c < 5; ++c) os.emg.push_back(envelope_[c].Step(std::abs(tel.emg[c])));
    if (result_->events.size() > events_seen_) os.event = result_->events[events_seen_++];
    video_->AddSample(plant_.data(), os);
  }

  const Scenario& s_;
  const RunOptions& opt_;
  Plant& plant_;
  RunBag* bag_;
  const CosimSchedule schedule_;
  RunResult* result_;
  ExowheelTotals* totals_;
  const int trial_;
  const uint64_t seed_;
  const std::shared_ptr<const controller::LegTrajectory> trajectory_;
  controller::JointSetpoint h0_, k0_;  // the reference at t = 0: the start pose
  CosimRig rig_;
  hwsim::VirtualCanBus::Endpoint* ctrl_ep_;
  CanBus* emg_ep_;
  hwsim::JointModule hip_, knee_;
  hwsim::JointModule* modules_[2] = {&hip_, &knee_};
  const controller::ExoControllerConfig ctrl_cfg_;
  controller::ExoController ctrl_;
  const bool human_, emg_on_;
  std::unique_ptr<MuscleModel> muscles_;
  std::unique_ptr<Behaviour> behaviour_;
  std::unique_ptr<SyntheticEmg> emg_;
  std::vector<FaultSwitch> faults_;
  TrialLogs logs_;
  std::unique_ptr<VideoSink> video_;
  std::vector<dsp::SosFilter> envelope_;
  size_t events_seen_ = 0;
  const double* command_ = nullptr;  // the command of Advance's ticks (null: the controller's own law)
  double tau_[2] = {0, 0};      // the drivers' output at t (at t = 0: no command yet)
  double applied_[2] = {0, 0};  // the drivers' output held over the last step
  Eigen::Vector2d tau_M_ = Eigen::Vector2d::Zero();  // muscle torque of the last step
  Eigen::Vector2d q_ = Eigen::Vector2d::Zero();      // plant angles at the last sampling instant
};

}  // namespace

// The run's state between Advance calls (exowheel_runner.h).
struct ExowheelSession::State {
  State(const Scenario& scenario, const RunOptions& options)
      : s(scenario), opt(options), truth(ResolveSubject(s)),
        plant(ExowheelMjcfPath(s.device != Device::kExowheelExoOnly)) {}
  const Scenario s;
  const RunOptions opt;
  RunResult result;
  const LegParams truth;
  Plant plant;
  CosimSchedule schedule;
  std::unique_ptr<CandumpWriter> can_log;
  std::unique_ptr<RunBag> bag;  // closed after the trial (declared before it)
  ExowheelTotals totals;
  std::chrono::steady_clock::time_point wall0;
  std::unique_ptr<ProgressBar> bar;
  std::unique_ptr<ExowheelTrial> trial;  // the trial running; null once the run ended
  int trial_index = 0;
  bool finished = false;

  void StartTrial() {
    trial = std::make_unique<ExowheelTrial>(s, opt, truth, plant, schedule, trial_index, can_log.get(), bag.get(), &result,
                                            &totals);
    trial->Begin();
  }
};

ExowheelSession::ExowheelSession(const Scenario& s, const RunOptions& opt) {
  RunResult& result = (st_ = std::make_unique<State>(s, opt))->result;
  result.scenario = s.name;
  result.seed = opt.seed ? *opt.seed : s.seed;
  CreateOutputFolder(opt.out_dir);

  Plant& plant = st_->plant;
  plant.SetParams(st_->truth);
  if (!s.plant_effects.empty()) {  // the scenario's plant: the rigid twin plus the effects it carries
    LegParams carried = st_->truth;
    carried.effects = s.plant_effects;
    plant.CarryEffects(ToPlantEffects(carried, s.plant_effects_source));  // sensor effects: the joint modules
  }
  st_->schedule = ScheduleOf(s, plant.timestep());

  if (!opt.can_log.empty()) st_->can_log = std::make_unique<CandumpWriter>(opt.can_log, "can0");
  if (!opt.mcap.empty()) st_->bag = std::make_unique<RunBag>(opt.mcap, s, result.seed);

  if (opt.remote)  // the controller in another process runs the scenario's controller file (ControllerNode)
    opt.remote->SetConfiguration(controller::ControllerFileYaml(
        ControllerFileOf(s, st_->truth), "the controller file of " + s.source + " (" + s.name + ")"));
  st_->wall0 = std::chrono::steady_clock::now();
  st_->bar = std::make_unique<ProgressBar>(static_cast<size_t>(s.protocol.trials * st_->schedule.steps), s.name,
                                           opt.progress);
  if (s.protocol.trials > 0) st_->StartTrial();
  else st_->finished = true;
}

ExowheelSession::~ExowheelSession() = default;

long ExowheelSession::Advance(long steps, const double* command) {
  State& st = *st_;
  long ran = 0;
  while (ran < steps && !st.finished) {
    if (st.trial->finished()) {  // concluded at its last step's end (its rows stay readable till now)
      st.trial.reset();          // closes (flushes) the trial's logs before the next trial opens its own
      ++st.trial_index;
      st.StartTrial();
    }
    ran += st.trial->Advance(steps - ran, command,
                             {st.bar.get(), static_cast<size_t>(st.trial_index * st.schedule.steps)});
    if (!st.trial->finished()) continue;
    if ((st.result.interrupted = st.trial->Conclude())) {
      st.result.interrupted->trial = st.trial_index + 1;
      st.finished = true;
    } else {
      st.finished = st.trial_index + 1 >= st.s.protocol.trials;
    }
  }
  return ran;
}

bool ExowheelSession::done() const { return st_->finished; }

int ExowheelSession::steps_per_tick() const { return st_->schedule.steps_per_tick; }

int ExowheelSession::trial() const { return st_->trial_index; }

double ExowheelSession::time() const { return st_->trial ? st_->trial->time() : 0.0; }

std::vector<std::string> ExowheelSession::MeasuredColumns() const {
  return st_->trial ? st_->trial->MeasuredColumns() : std::vector<std::string>{};
}

std::vector<std::string> ExowheelSession::TruthColumns() const { return ExowheelTrial::TruthColumns(); }

size_t ExowheelSession::MeasuredRow(double* row) const {
  return st_->trial ? st_->trial->MeasuredRow(st_->trial->time(), row) : 0;
}

size_t ExowheelSession::TruthRow(double* row) const {
  return st_->trial ? st_->trial->TruthRow(st_->trial->time(), row) : 0;
}

int ExowheelSession::safety_state() const {
  return st_->trial ? static_cast<int>(st_->trial->safety_state()) : st_->totals.final_state;
}

RunResult ExowheelSession::Finish() {
  State& st = *st_;
  st.trial.reset();
  if (st.bag) {
    st.bag->Close();
    st.result.files.push_back(st.opt.mcap);
  }
  if (!st.result.interrupted) st.bar->Update(static_cast<size_t>(st.s.protocol.trials * st.schedule.steps));
  st.bar->Finish();

  const ExowheelTotals& totals = st.totals;
  RunResult& result = st.result;
  auto& m = result.metrics;
  m["samples"] = static_cast<double>(totals.samples);
  m["tracking_rms_hip_deg"] = totals.track[0].rms();
  m["tracking_rms_knee_deg"] = totals.track[1].rms();
  m["tracking_max_hip_deg"] = totals.track[0].max;
  m["tracking_max_knee_deg"] = totals.track[1].max;
  m["torque_max_hip"] = totals.torque[0].max;
  m["torque_max_knee"] = totals.torque[1].max;
  m["torque_rms_hip"] = totals.torque[0].rms();
  m["torque_rms_knee"] = totals.torque[1].rms();
  m["bus_load_pct"] = totals.bus_load_max;
  m["frames"] = static_cast<double>(totals.frames_total);
  m["frames_dropped"] = static_cast<double>(totals.frames_dropped);
  m["error_frames"] = static_cast<double>(totals.error_frames);
  const double fault_time = totals.fault_time, safe_time = totals.safe_time;
  m["fault_time_s"] = fault_time;
  m["safe_state_time_s"] = safe_time;
  m["safe_reaction_s"] = (fault_time >= 0 && safe_time >= fault_time) ? safe_time - fault_time : -1;
  m["torque_max_after_safe"] = totals.max_torque_after_safe;
  m["torque_max_50ms_after_fault"] = totals.torque_after_fault;
  m["safe_state_entered"] = safe_time >= 0 ? 1.0 : 0.0;
  m["final_state"] = totals.final_state;
  if (st.opt.remote) st.opt.remote->AddMetrics(&m);
  m["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - st.wall0).count();

  FinishRun(st.s, result, st.opt.out_dir + "/result.json");
  return result;
}


RunResult RunExowheelScenario(const Scenario& s, const RunOptions& opt) {
  ExowheelSession session(s, opt);
  session.Advance(std::numeric_limits<long>::max(), nullptr);
  return session.Finish();
}

}  // namespace exotwin
