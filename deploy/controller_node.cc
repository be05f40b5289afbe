#include "deploy/controller_node.h"

#include <cstdio>
#include <cstring>
#include <string>

#include "core/stop_signal.h"
#include "protocol/link_frames.h"
#include "protocol/messages.h"

namespace exotwin {
namespace {

const char* StateName(int s) {
  return s == 0 ? "running" : (s == 1 ? "safe_damping" : "safe_torque_off");
}

std::string Hex(uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%04x", v);
  return b;
}

}  // namespace

CanStatus ControllerNode::TickBus::Receive(CanFrame* out) {
  if (pending.empty()) return CanStatus::kNoFrame;
  *out = pending.front();
  pending.pop_front();
  return CanStatus::kOk;
}

ControllerNode::ControllerNode(const controller::ControllerFile& cfg, CanLink* link, std::ostream& log)
    : link_(link), log_(log), bus_(link) {
  Configure(cfg);
}

ControllerNode::ControllerNode(const ControllerSpec& scenario_controller, bool hal3, std::string scenario_source,
                               CanLink* link, std::ostream& log)
    : link_(link), log_(log), bus_(link) {
  scenario_mode_ = true;
  scenario_hal_ = hal3;
  scenario_controller_ = scenario_controller;
  scenario_source_ = std::move(scenario_source);
  cfg_.source = scenario_source_;
}

void ControllerNode::Configure(const controller::ControllerFile& cfg) {
  if (cfg.hal) controller::HalLoop(*cfg.hal, nullptr);  // throws on a configuration the loop cannot run
  else exo_cfg_ = controller::ExoConfigOf(cfg);
  cfg_ = cfg;
  configured_ = true;
}

// The controller file downloaded from the twin (scenario mode): complete, and with the scenario's
// controller part; else logged and the run ends with exit 2.
void ControllerNode::TakeConfiguration(const CanFrame& end) {
  uint32_t length = 0, hash = 0;
  std::string text;
  text.swap(config_text_);
  if (!link::ConfigEnd(end, &length, &hash) || length != text.size() || hash != link::ConfigHash(text)) {
    log_ << "exotwin-controller: controller file from the twin incomplete (" << text.size() << " of " << length
         << " bytes): asking again" << std::endl;
    return;  // the next NMT start asks again
  }
  const std::string source = "the twin's controller file for " + scenario_source_;
  controller::ControllerFile f;
  try {
    f = controller::ParseControllerFile(text, source);
  } catch (const std::exception& e) {
    log_ << "exotwin-controller: " << e.what() << std::endl;
    exit_code_ = 2, done_ = true;
    return;
  }
  const ControllerSpec& a = f.controller;
  const ControllerSpec& b = scenario_controller_;
  // A HAL-3 file carries the scenario's controller part except its feed-forward (the HAL loop has none).
  const bool gains_differ = a.kp[0] != b.kp[0] || a.kp[1] != b.kp[1] || a.kd[0] != b.kd[0] || a.kd[1] != b.kd[1] ||
                            (!f.hal && a.feedforward != b.feedforward);
  if (f.hal.has_value() != scenario_hal_ || a.rate_hz != b.rate_hz || a.torque_limit != b.torque_limit || gains_differ) {
    log_ << "exotwin-controller: " << scenario_source_ << ": controller: the twin serves another controller ("
         << (f.hal ? "HAL-3" : "EXOwheel") << ", rate " << a.rate_hz << " Hz, kp [" << a.kp[0] << ", " << a.kp[1]
         << "], kd [" << a.kd[0] << ", " << a.kd[1] << "], torque limit " << a.torque_limit
         << " N m): is the twin serving this scenario?" << std::endl;
    exit_code_ = 2, done_ = true;
    return;
  }
  f.source = source;
  try {
    Configure(f);
  } catch (const std::exception& e) {
    log_ << "exotwin-controller: " << e.what() << std::endl;
    exit_code_ = 2, done_ = true;
    return;
  }
  awaiting_config_ = false;
  configured_start_ = start_sequence_;
  log_ << "exotwin-controller: " << source << " received (" << length << " bytes): "
       << (cfg_.hal ? std::string("HAL-3 loop, mode ") + controller::HalModeName(cfg_.hal->mode) +
                          ", EMG calibration and tau_c"
                    : std::string("feed-forward model and reference"))
       << std::endl;
}

// A fresh control loop for trial_ (the configuration held), answered by a ready frame.
void ControllerNode::StartLoop(uint16_t sequence) {
  if (cfg_.hal) {
    ctrl_.reset();
    hal_ = std::make_unique<controller::HalLoop>(*cfg_.hal, &bus_);
  } else {
    hal_.reset();
    ctrl_ = std::make_unique<controller::ExoController>(exo_cfg_, controller::BuildReference(cfg_.reference, trial_),
                                                         &bus_);
  }
  bus_.pending.clear();
  have_stamp_ = false;
  state_ = 0;
  faults_ = 0;
  log_ << "exotwin-controller: trial " << trial_ + 1 << ": control loop started" << std::endl;
  link_->Send(link::ReadyFrame(trial_, sequence));
}

int ControllerNode::Run() {
  if (configured_ && cfg_.hal)
    log_ << "exotwin-controller: " << cfg_.source << ": HAL-3 knee loop, mode " << controller::HalModeName(cfg_.hal->mode)
         << ", rate " << cfg_.controller.rate_hz << " Hz, torque limit " << cfg_.hal->tau_max << " N m, virtual viscosity "
         << cfg_.hal->impedance.target.B << " N m s/rad; bus " << link_->Describe() << "; waiting for NMT start"
         << std::endl;
  else if (configured_)
    log_ << "exotwin-controller: " << cfg_.source << ": rate " << cfg_.controller.rate_hz << " Hz, kp ["
         << cfg_.controller.kp[0] << ", " << cfg_.controller.kp[1] << "], kd [" << cfg_.controller.kd[0] << ", "
         << cfg_.controller.kd[1] << "], torque limit " << cfg_.controller.torque_limit << " N m, feed-forward "
         << (cfg_.controller.feedforward ? "on" : "off") << "; bus " << link_->Describe() << "; waiting for NMT start"
         << std::endl;
  else
    log_ << "exotwin-controller: " << scenario_source_ << ": a " << (scenario_hal_ ? "HAL-3" : "EXOwheel")
         << " scenario: its controller part here, "
         << (scenario_hal_ ? "the EMG calibration and the HAL-3 loop's configuration" : "the feed-forward model and reference")
         << " from the twin at each trial; bus " << link_->Describe() << "; waiting for NMT start" << std::endl;
  CanFrame f;
  while (!done_) {
    if (const int sig = StopSignal()) {
      ZeroTorque();
      log_ << "exotwin-controller: " << StopSignalName(sig) << ": zero torque commanded, drives disabled" << std::endl;
      Summary("stopped");
      return 0;
    }
    // The frames of the datagrams read; the next datagram is read by the next wait (a read of an
    // empty socket here would cost a system call per cycle).
    if (!link_->WaitInput(0.1)) continue;
    while (!done_ && link_->Queued() > 0 && link_->Receive(&f) == CanStatus::kOk) Handle(f);
  }
  Summary(exit_code_ ? "configuration refused" : "run over (NMT stop)");
  return exit_code_;
}

void ControllerNode::Handle(const CanFrame& f) {
  double v = 0;
  switch (f.id) {
    case link::kIdNmt:
      if (f.dlc >= 1 && f.data[0] == link::kNmtStart) {
        trial_ = f.dlc >= 3 ? f.data[2] : 0;
        const uint16_t sequence = link::StartSequence(f);
        if (scenario_mode_ && configured_start_ != sequence) {  // this start's controller file from the twin first
          CanFrame r = link::ReadyFrame(trial_, sequence);
          r.id = link::kIdConfigRequest;
          config_text_.clear();
          awaiting_config_ = true;
          start_sequence_ = sequence;
          link_->Send(r);
          return;
        }
        StartLoop(sequence);
      } else if (f.dlc >= 1 && f.data[0] == link::kNmtStop) {
        done_ = true;
      }
      return;
    case link::kIdConfigData:
      if (awaiting_config_ && config_text_.size() < (size_t{1} << 26))
        config_text_.append(reinterpret_cast<const char*>(f.data.data()), f.dlc);
      return;
    case link::kIdConfigEnd:
      if (awaiting_config_) TakeConfiguration(f);
      return;
    case link::kIdRxStamp:
      have_stamp_ = link::FrameDouble(f, &stamp_);
      return;
    case link::kIdSync:
      if (link::FrameDouble(f, &v)) Tick(v);
      return;
    default:
      if (link::IsLinkFrameId(f.id)) return;  // another node's link frame: not for the control loop
      if (!ctrl_ && !hal_) return;
      CanFrame g = f;
      g.t = have_stamp_ ? stamp_ : last_sync_;  // the receive time on the twin's (simulated) clock
      have_stamp_ = false;
      bus_.pending.push_back(g);
  }
}

void ControllerNode::Tick(double t) {
  last_sync_ = t;
  if (!ctrl_ && !hal_) {
    if (syncs_ignored_++ == 0) log_ << "exotwin-controller: SYNC before NMT start: ignored" << std::endl;
    return;
  }
  link_->Hold();  // the cycle's commands, telemetry and done frame: one datagram
  if (hal_) {
    hal_->Tick(t);
    ++ticks_;
    SendHalTelemetry();
    link_->Send(link::DoubleFrame(link::kIdCycleDone, t));
    link_->Flush();
    return;
  }
  ctrl_->Tick(t);
  ++ticks_;
  const controller::ControllerTelemetry& tel = ctrl_->telemetry();
  const double values[link::kTelCount] = {tel.est[0].q,  tel.est[1].q,  tel.tau_sensor[0],
                                          tel.tau_sensor[1], tel.tau_cmd[0], tel.tau_cmd[1],
                                          tel.ref[0].q,  tel.ref[1].q,  static_cast<double>(tel.safety.state),
                                          tel.emg[0],    tel.emg[1],    tel.emg[2],
                                          tel.emg[3],    tel.emg[4]};
  for (int i = 0; i < link::kTelCount; ++i)
    link_->Send(link::DoubleFrame(static_cast<uint16_t>(link::kIdTelemetryBase + i), values[i]));
  link_->Send(link::DoubleFrame(link::kIdCycleDone, t));
  link_->Flush();
  const int state = static_cast<int>(tel.safety.state);
  if (state != state_ || tel.safety.fault_mask != faults_) {
    log_ << "exotwin-controller: t " << t << " s: safety " << StateName(state_) << " -> " << StateName(state)
         << ", faults " << Hex(tel.safety.fault_mask) << " (first " << static_cast<int>(tel.safety.first_fault) << ")"
         << std::endl;
    state_ = state;
    faults_ = tel.safety.fault_mask;
  }
}

void ControllerNode::SendHalTelemetry() {
  const controller::HalTelemetry& h = hal_->telemetry();
  double v[link::kHalTelCount];
  v[link::kHalTelTh] = h.th, v[link::kHalTelStrain] = h.strain, v[link::kHalTelThd] = h.thd;
  v[link::kHalTelTauCmd] = h.tau_cmd, v[link::kHalTelEe] = h.E_e, v[link::kHalTelEf] = h.E_f;
  v[link::kHalTelMuHat] = h.assist.mu_hat, v[link::kHalTelD] = h.assist.D, v[link::kHalTelK] = h.assist.K;
  v[link::kHalTelTauMu] = h.assist.tau_mu, v[link::kHalTelTauZeta] = h.assist.tau_zeta;
  v[link::kHalTelTauC] = h.assist.tau_c, v[link::kHalTelIHat] = hal_->assist().rls().I();
  v[link::kHalTelEmgGaps] = h.emg_gaps, v[link::kHalTelEnabled] = h.enabled ? 1.0 : 0.0;
  for (int i = 0; i < link::kHalTelCount; ++i)
    link_->Send(link::DoubleFrame(static_cast<uint16_t>(link::kIdTelemetryBase + i), v[i]));
}

void ControllerNode::ZeroTorque() {
  link_->Hold();
  if (cfg_.hal || scenario_hal_) {  // a HAL-3 file, or a HAL-3 scenario before its first download
    msg::HalKneeCommand c;
    c.torque = 0.0;
    c.enable = false;
    link_->Send(msg::Encode(c));
    link_->Flush();
    return;
  }
  for (int j = 0; j < 2; ++j) {
    msg::JointCommand c;
    c.joint = static_cast<msg::Joint>(j);
    c.torque = 0.0;
    c.enable = false;
    link_->Send(msg::Encode(c));
  }
  link_->Flush();
}

void ControllerNode::Summary(const char* why) {
  const CanLinkStatistics& s = link_->statistics();
  log_ << "exotwin-controller: " << why << ": " << ticks_ << " ticks, frames received " << s.received << ", sent "
       << s.sent << ", send failures " << s.send_failures + s.peer_absent
       << (s.last_send_errno ? std::string(" (last: ") + std::strerror(s.last_send_errno) + ")" : std::string())
       << ", dropped: foreign " << s.foreign
       << ", malformed " << s.malformed << std::endl;
}

}  // namespace exotwin
