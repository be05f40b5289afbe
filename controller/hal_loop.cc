// HAL-3 knee control loop: see hal_loop.h.
#include "controller/hal_loop.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "protocol/messages.h"

namespace exotwin::controller {

const char* HalModeName(HalMode m) {
  switch (m) {
    case HalMode::kNone: return "none";
    case HalMode::kImpedance: return "impedance";
    case HalMode::kAssist: return "assist";
  }
  return "?";
}

void SetRateAndLimit(HalLoopConfig* c, double rate_hz) {
  c->rate_hz = rate_hz;
  c->velocity.sample_rate_hz = rate_hz;
  c->assist.dt = 1.0 / rate_hz;
  c->assist.rls.dt = c->assist.dt;
  c->assist.tau_max = c->tau_max;
}

namespace {
HalLoopConfig Checked(const HalLoopConfig& c) {
  if (!(c.rate_hz > 0) || !(c.tau_max > 0) || !(c.status_timeout > 0) ||
      c.extensor_channel < 0 || c.extensor_channel >= msg::kEmgChannels || c.flexor_channel < 0 ||
      c.flexor_channel >= msg::kEmgChannels)
    throw std::invalid_argument("HalLoop: rate_hz, tau_max, status_timeout > 0 and EMG channels 0..4 expected");
  return c;
}
}  // namespace

HalLoop::HalLoop(const HalLoopConfig& cfg, CanBus* bus)
    : cfg_(Checked(cfg)), bus_(bus), assist_(cfg.assist), rms_e_(cfg.emg_fs, cfg.rms_window),
      rms_f_(cfg.emg_fs, cfg.rms_window), est_(cfg.velocity) {}

void HalLoop::Tick(double t) {
  tel_.t = t;
  new_status_ = false;
  CanFrame f;
  CanStatus st;
  while ((st = bus_->Receive(&f)) != CanStatus::kNoFrame) {
    if (st != CanStatus::kOk) continue;
    msg::HalKneeStatus s;
    msg::EmgSamples e;
    if (msg::Decode(f, &s)) {
      tel_.th = s.angle;
      tel_.strain = s.torque;
      last_status_t_ = f.t;
      tel_.have_status = true;
      new_status_ = true;
      ++tel_.status_frames;
    } else if (msg::Decode(f, &e)) {
      if (emg_started_ && e.counter != ((emg_counter_ + 1) & 0x0f)) ++tel_.emg_gaps;
      emg_counter_ = e.counter;
      emg_started_ = true;
      tel_.E_e = rms_e_.Step(e.volts[cfg_.extensor_channel]);  // HKS05 eq. 1
      tel_.E_f = rms_f_.Step(e.volts[cfg_.flexor_channel]);
      ++tel_.emg_frames;
    }
  }
  if (new_status_) est_.Update(tel_.th);
  else if (tel_.have_status) est_.Hold();
  tel_.thd = est_.estimate().qd;
  tel_.thdd = est_.estimate().qdd;

  const bool alive = tel_.have_status && t - last_status_t_ <= cfg_.status_timeout;
  double tau = 0;
  HalAssistOutput out;
  if (alive && cfg_.mode != HalMode::kNone) {
    const double tau_c = CompensationTorque(cfg_.impedance, tel_.th, tel_.thd, tel_.thdd);
    if (cfg_.mode == HalMode::kAssist) {
      out = assist_.Step(tel_.th, tel_.E_e, tel_.E_f, tau_c);  // HKS05 eq. 6
    } else {
      out.tau_c = tau_c;
      out.tau = tau_c;
    }
    tau = std::clamp(out.tau, -cfg_.tau_max, cfg_.tau_max);
    if (!std::isfinite(tau)) tau = 0;
  }
  tel_.assist = out;
  tel_.tau_cmd = tau;
  tel_.enabled = alive;
  msg::HalKneeCommand c;
  c.torque = tau;
  c.enable = alive;
  c.counter = tx_counter_++;
  if (bus_->Send(msg::Encode(c)) != CanStatus::kOk) ++tel_.send_failures;
}

}  // namespace exotwin::controller
