#include "runner/remote_controller.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <unistd.h>

#include "core/error.h"
#include "core/realtime.h"
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

constexpr uint64_t kLinkFaultStream = 0x4c494e4b;  // "LINK": the link faults' draws
// A due time at or before a tick's time, with the rounding of sums of simulated times.
constexpr double kDueSlack = 1e-9;  // s

std::string At(double t) {
  std::ostringstream o;
  o << "t=" << t << " ";
  return o.str();
}

}  // namespace

LinkFaults LinkFaultsOf(double delay_ms, double jitter_ms, double loss, uint64_t seed) {
  auto check = [](const char* option, double v, double hi, const char* what) {
    if (!(v >= 0 && v <= hi))  // NaN too
      throw InputError(std::string(option) + ": expected " + what + ", got " + std::to_string(v));
  };
  check("--link-delay", delay_ms, 1000, "a delay of 0 to 1000 ms");
  check("--link-jitter", jitter_ms, 1000, "a jitter of 0 to 1000 ms");
  check("--link-loss", loss, 1, "a probability of loss of 0 to 1");
  LinkFaults f;
  f.delay_s = 1e-3 * delay_ms;
  f.jitter_s = 1e-3 * jitter_ms;
  f.loss = loss;
  f.seed = seed;
  return f;
}

const std::vector<double>& JitterHistogramEdgesUs() {
  static const std::vector<double> edges = {0, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000};
  return edges;
}

RemoteController::RemoteController(CanLink* link, ServeClock clock, double period_s, double timeout_s,
                                   LinkFaults faults, double spin_s)
    : link_(link), clock_(clock), period_(period_s), timeout_(timeout_s),
      starts_(static_cast<uint16_t>(static_cast<uint64_t>(MonotonicSeconds() * 1e9) ^ static_cast<uint64_t>(::getpid()))),
      faults_(faults), spin_(spin_s), fault_rng_(MixSeed(faults.seed ^ kLinkFaultStream)) {}

bool RemoteController::Pass(double t, double* last, double* due) {
  if (faults_.loss > 0 && fault_rng_.Uniform() < faults_.loss) {
    ++dropped_;
    return false;
  }
  *due = t;
  if (!faults_.any()) return true;
  *due = std::max(t + faults_.delay_s + (faults_.jitter_s > 0 ? faults_.jitter_s * fault_rng_.Uniform() : 0.0),
                  *last);  // never overtakes the frame before it
  *last = *due;
  return true;
}

void RemoteController::Release(double t) {
  while (!to_bus_.empty() && to_bus_.front().due <= t + kDueSlack) {
    if (ep_->Send(to_bus_.front().frame) != CanStatus::kOk) ++bus_refused_;
    to_bus_.pop_front();
  }
}

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
  to_controller_.clear(), to_bus_.clear();
  last_to_controller_ = last_to_bus_ = 0;
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
        link_->Hold();
        for (const CanFrame& c : link::ConfigFrames(configuration_)) link_->Send(c);
        link_->Flush();
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
  double due = 0;
  if (Pass(t, &last_to_bus_, &due)) to_bus_.push_back({due, f});
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
  if (clock_ == ServeClock::kRealtime) {  // tick k on the absolute deadline wall0 + k period
    const double due = wall0_ + static_cast<double>(ticks_) * period_;
    jitter_.push_back(WaitUntil(due, spin_) - due);
    CanFrame g;
    bool done = false;  // the last cycle's answer, after its deadline: late, applied now
    while (link_->Receive(&g) == CanStatus::kOk) Take(g, t, &done);
    if (done) ++late_;
    if (awaiting_) ++missed_;
    awaiting_ = false;
  }
  ++ticks_;
  Release(t);  // commands delayed by the link's faults, due by now
  CanFrame f;
  CanStatus st;
  while ((st = ep_->Receive(&f)) != CanStatus::kNoFrame) {
    double due = 0;
    if (st == CanStatus::kOk && present_ && Pass(f.t, &last_to_controller_, &due)) to_controller_.push_back({due, f});
  }  // error frames: the in-process controller skips them too
  if (!present_) return;
  const uint64_t absent = link_->statistics().peer_absent;
  link_->Hold();  // the tick's frames and SYNC: one datagram
  while (!to_controller_.empty() && to_controller_.front().due <= t + kDueSlack) {
    link_->Send(link::DoubleFrame(link::kIdRxStamp, to_controller_.front().due));
    link_->Send(to_controller_.front().frame);
    to_controller_.pop_front();
  }
  link_->Send(link::DoubleFrame(link::kIdSync, t));
  link_->Flush();
  if (link_->statistics().peer_absent != absent) {
    Lost(t, "(its socket refuses frames: process gone)");
    return;
  }
  awaited_ = t;
  awaiting_ = true;
  const double wait = clock_ == ServeClock::kLockstep ? timeout_ : 0.5 * period_;
  const double deadline = MonotonicSeconds() + wait;
  bool done = false;
  while (!done) {  // poll first: the answer is rarely there before it (a read would be a wasted call)
    const double left = deadline - MonotonicSeconds();
    if (left <= 0) break;
    if (!link_->WaitInput(std::min(left, 0.1))) {
      if (link_->PeerAlive()) continue;
      Lost(t, "(its socket is gone: process gone)");
      return;
    }
    while (!done && link_->Receive(&f) == CanStatus::kOk) Take(f, t, &done);
  }
  Release(t);
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
  (*m)["link_frames_dropped"] = static_cast<double>(dropped_);
  if (clock_ == ServeClock::kRealtime) {
    (*m)["link_jitter_p50_us"] = 1e6 * Percentile(jitter_, 0.5);
    (*m)["link_jitter_p99_us"] = 1e6 * Percentile(jitter_, 0.99);
    (*m)["link_jitter_max_us"] = 1e6 * Percentile(jitter_, 1.0);
    (*m)["link_late_cycles"] = static_cast<double>(late_);
    (*m)["link_missed_cycles"] = static_cast<double>(missed_ + (awaiting_ ? 1 : 0));
  }
}

nlohmann::ordered_json RemoteController::JitterHistogram() const {
  if (clock_ != ServeClock::kRealtime) return nullptr;
  const std::vector<double>& edges = JitterHistogramEdgesUs();
  std::vector<uint64_t> counts(edges.size(), 0);
  for (double j : jitter_) {
    const double us = 1e6 * j;
    const auto above = std::upper_bound(edges.begin(), edges.end(), us);  // first edge > us
    ++counts[static_cast<size_t>(std::max<std::ptrdiff_t>(0, above - edges.begin() - 1))];
  }
  return nlohmann::ordered_json{{"edges_us", edges}, {"counts", counts}};
}

}  // namespace exotwin
