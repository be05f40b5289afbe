#include "runner/remote_controller.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "protocol/link_frames.h"
#include "protocol/messages.h"

namespace exotwin {
namespace {

// The frames a controller may put on the bus (the in-process controller's sends).
bool ControllerFrameId(uint16_t id) {
  return id == msg::kIdControllerHeartbeat || id == msg::kIdJointCommandHip || id == msg::kIdJointCommandKnee ||
         id == msg::kIdHalKneeCommand;
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(std::min<double>(v.size() - 1, std::floor(p * (v.size() - 1) + 0.5)))];
}

std::string At(double t) {
  std::ostringstream o;
  o << "t=" << t << " ";
  return o.str();
}

}  // namespace

RemoteController::RemoteController(CanLink* link, ServeClock clock, double period_s, double timeout_s)
    : link_(link), clock_(clock), period_(period_s), timeout_(timeout_s),
      starts_(static_cast<uint16_t>(static_cast<uint64_t>(MonotonicSeconds() * 1e9) ^ static_cast<uint64_t>(::getpid()))) {}

void RemoteController::BeginTrial(int trial, CanBus* ep, std::vector<std::string>* events) {
  ep_ = ep;
  events_ = events;
  tel_ = controller::ControllerTelemetry{};
  tel_.tau_sensor[0] = tel_.tau_sensor[1] = std::nan("");
  hal_tel_ = controller::HalTelemetry{};
  hal_I_hat_ = 0;
  awaiting_ = false;
  ticks_ = 0;
  present_ = false;
  const double start = MonotonicSeconds();
  const uint16_t sequence = starts_++;
  double last_nmt = -1;
  CanFrame f;
  while (!present_ && MonotonicSeconds() - start < timeout_) {
    if (MonotonicSeconds() - last_nmt >= 0.1) {
      link_->Send(link::NmtFrame(link::kNmtStart, trial, sequence));
      last_nmt = MonotonicSeconds();
    }
    link_->WaitInput(0.02);
    while (link_->Receive(&f) == CanStatus::kOk) {
      if (f.id == link::kIdReady && f.dlc >= 2 && f.data[1] == static_cast<uint8_t>(trial) &&
          link::StartSequence(f) == sequence)
        present_ = true;
      if (f.id == link::kIdConfigRequest && !configuration_.empty()) {
        for (const CanFrame& c : link::ConfigFrames(configuration_)) link_->Send(c);
        last_nmt = -1;  // the next NMT start right after the configuration
      }
    }
  }
  if (!present_) Lost(0.0, "controller did not answer the NMT start of trial " + std::to_string(trial + 1) +
                             " within " + std::to_string(timeout_) + " s");
  wall0_ = MonotonicSeconds();
}

void RemoteController::Lost(double t, const std::string& why) {
  if (lost_at_ < 0) lost_at_ = t;
  deterministic_ = false;
  present_ = false;
  events_->push_back(At(t) + "controller_lost " + why + ": the twin runs on without it (run not deterministic)");
}

void RemoteController::Take(const CanFrame& f, double t, bool* done) {
  double v = 0;
  if (f.id >= link::kIdTelemetryBase && f.id < link::kIdTelemetryBase + link::kTelemetryValues) {
    if (!link::FrameDouble(f, &v)) return;
    const int i = f.id - link::kIdTelemetryBase;
    TakeHal(i, v);
    if (i >= link::kTelCount) return;
    if (i == link::kTelEstQHip || i == link::kTelEstQKnee) tel_.est[i - link::kTelEstQHip].q = v;
    else if (i == link::kTelTauSensorHip || i == link::kTelTauSensorKnee) tel_.tau_sensor[i - link::kTelTauSensorHip] = v;
    else if (i == link::kTelTauCmdHip || i == link::kTelTauCmdKnee) tel_.tau_cmd[i - link::kTelTauCmdHip] = v;
    else if (i == link::kTelRefQHip || i == link::kTelRefQKnee) tel_.ref[i - link::kTelRefQHip].q = v;
    else if (i == link::kTelState) tel_.safety.state = static_cast<controller::SafetyState>(static_cast<int>(v));
    else tel_.emg[i - link::kTelEmg0] = v;
    return;
  }
  if (f.id == link::kIdCycleDone) {
    if (!link::FrameDouble(f, &v)) return;
    if (v == awaited_ && awaiting_) {
      *done = true;
      awaiting_ = false;
    } else {
      ++late_;  // the answer of a missed cycle
    }
    return;
  }
  if (link::IsLinkFrameId(f.id)) return;  // a ready frame answering a repeated NMT start
  if (!ControllerFrameId(f.id)) {
    if (unexpected_++ == 0)
      events_->push_back(At(t) + "link_frame_refused id " + std::to_string(f.id) +
                         ": not a controller frame, dropped (further ones counted in link_frames_unexpected)");
    return;
  }
  if (ep_->Send(f) != CanStatus::kOk) ++bus_refused_;
}

void RemoteController::TakeHal(int i, double v) {
  controller::HalTelemetry& h = hal_tel_;
  switch (i) {
    case link::kHalTelTh: h.th = v; break;
    case link::kHalTelStrain: h.strain = v; break;
    case link::kHalTelThd: h.thd = v; break;
    case link::kHalTelTauCmd: h.tau_cmd = v; break;
    case link::kHalTelEe: h.E_e = v; break;
    case link::kHalTelEf: h.E_f = v; break;
    case link::kHalTelMuHat: h.assist.mu_hat = v; break;
    case link::kHalTelD: h.assist.D = v; break;
    case link::kHalTelK: h.assist.K = v; break;
    case link::kHalTelTauMu: h.assist.tau_mu = v; break;
    case link::kHalTelTauZeta: h.assist.tau_zeta = v; break;
    case link::kHalTelTauC: h.assist.tau_c = v; break;
    case link::kHalTelIHat: hal_I_hat_ = v; break;
    case link::kHalTelEmgGaps: h.emg_gaps = static_cast<uint32_t>(v); break;
    case link::kHalTelEnabled: h.enabled = v != 0; break;
    default: break;
  }
}

void RemoteController::Tick(double t) {
  if (clock_ == ServeClock::kRealtime) {  // pace: tick k at wall0 + k period
    const double due = wall0_ + static_cast<double>(ticks_) * period_;
    double now = MonotonicSeconds();
    if (now < due) {
      std::this_thread::sleep_for(std::chrono::duration<double>(due - now - 50e-6));
      while ((now = MonotonicSeconds()) < due) {
      }
    }
    jitter_.push_back(now - due);
    CanFrame g;
    bool done = false;  // the last cycle's answer, after its deadline: late, applied now
    while (link_->Receive(&g) == CanStatus::kOk) Take(g, t, &done);
    if (done) ++late_;
    if (awaiting_) ++missed_;
    awaiting_ = false;
  }
  ++ticks_;
  CanFrame f;
  CanStatus st;
  while ((st = ep_->Receive(&f)) != CanStatus::kNoFrame) {
    if (st != CanStatus::kOk || !present_) continue;  // error frames: the in-process controller skips them too
    link_->Send(link::DoubleFrame(link::kIdRxStamp, f.t));
    link_->Send(f);
  }
  if (!present_) return;
  const uint64_t absent = link_->statistics().peer_absent;
  link_->Send(link::DoubleFrame(link::kIdSync, t));
  if (link_->statistics().peer_absent != absent) {
    Lost(t, "(its socket refuses frames: process gone)");
    return;
  }
  awaited_ = t;
  awaiting_ = true;
  const double wait = clock_ == ServeClock::kLockstep ? timeout_ : 0.5 * period_;
  const double deadline = MonotonicSeconds() + wait;
  bool done = false;
  while (!done) {
    while (!done && link_->Receive(&f) == CanStatus::kOk) Take(f, t, &done);
    if (done) break;
    const double left = deadline - MonotonicSeconds();
    if (left <= 0) break;
    if (!link_->WaitInput(std::min(left, 0.1)) && !link_->PeerAlive()) {
      Lost(t, "(its socket is gone: process gone)");
      return;
    }
  }
  if (!done && clock_ == ServeClock::kLockstep)
    Lost(t, "(no answer within " + std::to_string(timeout_) + " s of wall clock)");
}

void RemoteController::EndRun() { link_->Send(link::NmtFrame(link::kNmtStop, 0)); }

void RemoteController::AddMetrics(std::map<std::string, double>* m) const {
  const CanLinkStatistics& s = link_->statistics();
  (*m)["link_deterministic"] = deterministic_ ? 1.0 : 0.0;
  (*m)["link_controller_lost_s"] = lost_at_;
  (*m)["link_frames_foreign"] = static_cast<double>(s.foreign);
  (*m)["link_frames_malformed"] = static_cast<double>(s.malformed);
  (*m)["link_frames_unexpected"] = static_cast<double>(unexpected_);
  (*m)["link_frames_refused_by_bus"] = static_cast<double>(bus_refused_);
  if (clock_ == ServeClock::kRealtime) {
    (*m)["link_jitter_p50_us"] = 1e6 * Percentile(jitter_, 0.5);
    (*m)["link_jitter_p99_us"] = 1e6 * Percentile(jitter_, 0.99);
    (*m)["link_jitter_max_us"] = 1e6 * Percentile(jitter_, 1.0);
    (*m)["link_late_cycles"] = static_cast<double>(late_);
    (*m)["link_missed_cycles"] = static_cast<double>(missed_ + (awaiting_ ? 1 : 0));
  }
}

}  // namespace exotwin
