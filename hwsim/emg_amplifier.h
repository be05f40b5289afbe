// EMG amplifier node physics (Delsys Bagnoli-like, as in Hwang & Jeon sec. 3.2): gain 1000,
// 4th-order Butterworth band-pass 20-450 Hz, 1 kHz ADC, 5 channels (GMAX, VM, RF, ST, GAS).
#pragma once
#include <array>
#include <vector>

#include "dsp/butterworth.h"

namespace exotwin::hwsim {

struct EmgAmplifierSpec {
  double gain = 1000.0;
  double f_low = 20.0, f_high = 450.0;  // Hz, band-pass corners
  int order = 4;                        // Butterworth order (per band edge, as scipy's butter)
  double fs = 1000.0;                   // Hz, ADC rate
  double full_scale = 5.0;              // V, output saturates at +-full_scale
  int adc_bits = 16;                    // quantization over [-full_scale, full_scale]
};

class EmgAmplifier {
 public:
  static constexpr int kChannels = 5;
  explicit EmgAmplifier(const EmgAmplifierSpec& spec = {});
  // One ADC sample of all channels from the electrode voltages (V) at that instant; returns the
  // amplified, band-passed, saturated and quantized output (V).
  std::array<double, kChannels> Sample(const std::array<double, kChannels>& electrode_v);
  double lsb() const;
  const EmgAmplifierSpec& spec() const { return spec_; }

 private:
  EmgAmplifierSpec spec_;
  std::vector<dsp::SosFilter> filters_;
};

}  // namespace exotwin::hwsim
