// The HAL-3 knee control loop (what runs at 1 kHz on HAL's computer), over a CanBus only:
// reads HalKneeStatus (0x190: potentiometer angle, strain gauge) and EmgSamples (0x200), computes the
// RMS envelopes of the extensor and flexor channels (HKS05 eq. 1), and sends HalKneeCommand (0x110)
// with one of three laws:
//   kNone:      zero torque (HAL worn passively, its own impedance uncompensated);
//   kImpedance: tau = tau_c, the virtual-impedance compensation of Lee & Sankai (virtual_impedance.h);
//               with B_v = 0, mgl_v = mgl, I_v = I, C_v = 0 it is Hayashi's tau_c, experiment 1;
//   kAssist:    tau = tau_zeta + tau_mu + tau_c (HKS05 eq. 2-3, 5-6, RLS HKS05 eq. 8-13, observer
//               HKS05 eq. 16-17; controller/hal_assist.h), experiment 2.
// The strain gauge is logged but, as in Hayashi sec. III, never used for control. Real-time path
// (Tick) allocates nothing and throws nothing; construction throws std::invalid_argument.
#pragma once
#include <cstdint>

#include "controller/hal_assist.h"
#include "controller/state_estimator.h"
#include "controller/virtual_impedance.h"
#include "dsp/emg_envelope.h"
#include "protocol/can_bus.h"

namespace exotwin::controller {

enum class HalMode { kNone, kImpedance, kAssist };
// "none", "impedance", "assist".
const char* HalModeName(HalMode m);

struct HalLoopConfig {
  HalMode mode = HalMode::kImpedance;
  double rate_hz = 1000.0;          // Tick() rate, Hz
  HalAssistConfig assist;           // HKS05 eq. 2-17: gains, EMG coefficients, RLS, observer
  VirtualImpedanceConfig impedance; // tau_c: identified exoskeleton (actual) and virtual (target) values
  int extensor_channel = 1;         // EmgSamples channel of the extensor unit (1 = VM)
  int flexor_channel = 3;           // EmgSamples channel of the flexor unit (3 = ST)
  double rms_window = 0.1;          // s, T of HKS05 eq. 1
  double emg_fs = 1000.0;           // Hz, EMG sample rate
  EstimatorConfig velocity;         // causal velocity/acceleration for tau_c (20 Hz low-pass)
  double tau_max = 60.0;            // N m, command limit (HAL-3 actuator)
  double status_timeout = 0.02;     // s without a status frame -> torque off (enable = false)
};

// Sets the fields that follow the loop's rate and command limit: rate_hz, the velocity filter's sample
// rate, the assist's and the RLS's dt (1 / rate_hz, the T_d of HKS05 eq. 11) and assist.tau_max
// (= tau_max). The runner and the controller file's reader both derive them here.
void SetRateAndLimit(HalLoopConfig* c, double rate_hz);

// What one tick saw and did.
struct HalTelemetry {
  double t = 0;
  double th = 0, strain = 0;        // rad, N m: latest potentiometer and strain-gauge readings
  double thd = 0, thdd = 0;         // rad/s, rad/s^2: causal estimates used by tau_c
  double E_e = 0, E_f = 0;          // V: RMS envelopes (HKS05 eq. 1) of extensor and flexor
  double tau_cmd = 0;               // N m, sent
  HalAssistOutput assist;           // terms of HKS05 eq. 6 (tau_c also filled in kImpedance)
  bool have_status = false, enabled = false;
  uint32_t status_frames = 0, emg_frames = 0, emg_gaps = 0, send_failures = 0;
};

class HalLoop {
 public:
  // bus: this node's endpoint (not owned). Throws std::invalid_argument on a bad configuration.
  HalLoop(const HalLoopConfig& cfg, CanBus* bus);
  // One control period at time t (s): drain frames, envelopes, control law, send the command.
  void Tick(double t);
  const HalTelemetry& telemetry() const { return tel_; }
  const HalAssistController& assist() const { return assist_; }
  const HalLoopConfig& config() const { return cfg_; }

 private:
  HalLoopConfig cfg_;
  CanBus* bus_;
  HalAssistController assist_;
  dsp::RmsEnvelope rms_e_, rms_f_;
  JointStateEstimator est_;
  HalTelemetry tel_;
  double last_status_t_ = -1e9;
  bool new_status_ = false;
  uint8_t tx_counter_ = 0, emg_counter_ = 0;
  bool emg_started_ = false;
};

}  // namespace exotwin::controller
