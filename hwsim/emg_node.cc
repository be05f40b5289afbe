// EMG amplifier node: see emg_node.h.
#include "hwsim/emg_node.h"

namespace exotwin::hwsim {

EmgNode::EmgNode(const EmgAmplifierSpec& spec, CanBus* bus) : amp_(spec), bus_(bus) {}

CanStatus EmgNode::Sample(double, const std::array<double, EmgAmplifier::kChannels>& electrode_v) {
  out_ = amp_.Sample(electrode_v);
  msg::EmgSamples m;
  for (int c = 0; c < msg::kEmgChannels; ++c) m.volts[c] = out_[c];
  m.counter = static_cast<uint8_t>(counter_++ & 0x0f);
  const CanStatus st = bus_->Send(msg::Encode(m));
  if (st == CanStatus::kOk) ++sent_;
  return st;
}

}  // namespace exotwin::hwsim
