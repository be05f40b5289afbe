#include "hwsim/emg_amplifier.h"

#include <algorithm>
#include <cmath>

namespace exotwin::hwsim {

EmgAmplifier::EmgAmplifier(const EmgAmplifierSpec& spec) : spec_(spec) {
  const auto sos = dsp::DesignButterworth(spec.order, dsp::BandType::kBandPass, spec.fs, spec.f_low,
                                          std::min(spec.f_high, 0.499 * spec.fs));
  filters_.assign(kChannels, dsp::SosFilter(sos));
}

double EmgAmplifier::lsb() const { return 2.0 * spec_.full_scale / std::ldexp(1.0, spec_.adc_bits); }

std::array<double, EmgAmplifier::kChannels> EmgAmplifier::Sample(
    const std::array<double, kChannels>& electrode_v) {
  std::array<double, kChannels> out{};
  const double q = lsb();
  for (int c = 0; c < kChannels; ++c) {
    double v = filters_[c].Step(spec_.gain * electrode_v[c]);
    v = std::clamp(v, -spec_.full_scale, spec_.full_scale - q);
    out[c] = std::round(v / q) * q;
  }
  return out;
}

}  // namespace exotwin::hwsim
