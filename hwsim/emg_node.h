// EMG amplifier node (Hayashi Fig. 2: electrodes + instrumentation amplifier; hwsim/emg_amplifier.h
// physics: gain 1000, 20-450 Hz, 1 kHz ADC): electrode voltages in, one EmgSamples frame (0x200) per
// ADC sample out. Channels in DESIGN.md order GMAX, VM, RF, ST, GAS. hwsim does not know sim/: the
// runner passes the electrode voltages as plain numbers.
#pragma once
#include <array>
#include <cstdint>

#include "hwsim/emg_amplifier.h"
#include "protocol/can_bus.h"
#include "protocol/messages.h"

namespace exotwin::hwsim {

class EmgNode {
 public:
  // bus: this node's endpoint (not owned, outlives the node).
  EmgNode(const EmgAmplifierSpec& spec, CanBus* bus);
  // One ADC sample at time t (s) of the electrode voltages (V, before the amplifier): amplifies,
  // filters, quantizes and sends one EmgSamples frame. Call at spec.fs (1 kHz).
  CanStatus Sample(double t, const std::array<double, EmgAmplifier::kChannels>& electrode_v);
  const std::array<double, EmgAmplifier::kChannels>& last_output() const { return out_; }  // V
  uint32_t frames_sent() const { return sent_; }

 private:
  EmgAmplifier amp_;
  CanBus* bus_;
  std::array<double, EmgAmplifier::kChannels> out_{};
  uint8_t counter_ = 0;
  uint32_t sent_ = 0;
};

}  // namespace exotwin::hwsim
