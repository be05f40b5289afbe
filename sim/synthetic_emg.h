// Synthetic surface EMG of the five channels GMAX, VM, RF, ST, GAS (issue 6, item 2): the RAW
// electrode voltage (V, before the amplifier), for the hwsim EMG amplifier to apply gain 1000,
// band-pass 20-450 Hz and the 1 kHz ADC.
//
// Model per channel c (amplitude-modulated noise, as Hogan & Mann 1980 / Clancy & Hogan 1999):
//   x_c(t) = sum_m X(c, m) e_m(t) A_m n_m(t)  +  B_c b_c(t)  +  M sin(2 pi f_mains t + phi)
// n_m: unit-variance Gaussian noise shaped by a band-pass (high-pass 2nd order f_hp, low-pass 2nd
//      order f_lp) so that the power spectrum resembles surface EMG (median frequency ~ 75 Hz);
// e_m: the muscle's ELECTRICAL activation (MuscleModel::electrical_activation). The electromechanical
//      delay lives in MuscleModel (force follows e by emd), so this EMG leads the torque by emd;
// A_m: RMS at full activation (MVC), V; B_c: RMS of the relaxed baseline (noise band-limited 20-450
//      Hz), V; X: crosstalk matrix (X(c, c) = 1, X(c, m) the share of muscle m seen on channel c);
// mains: optional interference (amplitude M = 0 by default).
// Every draw comes from the seed (MuscleRng: std::mt19937_64 raw bits, core/rng.h); same seed, same bits.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "dsp/butterworth.h"
#include "sim/muscles.h"

namespace exotwin {

struct SyntheticEmgConfig {
  double fs = 1000.0;   // generator sample rate, Hz (one sample per Sample() call)
  double f_hp = 20.0;   // spectral shaping of the muscle signal: high-pass corner, Hz
  double f_lp = 110.0;  // low-pass corner, Hz (2nd-order each; MDF about 75 Hz at fs = 1 kHz)
  MuscleVec mvc_rms = MuscleVec::Constant(1.0e-3);  // V at the electrode, RMS at full activation
  // Relaxed baseline RMS, V at the electrode: Hayashi et al. report relaxed "myoelectric activity"
  // of about 0.1 V (extensor) and 0.04 V (flexor) after gain 1000 -> 0.1 mV and 0.04 mV here. We
  // give the knee extensors VM, RF 0.1 mV and GMAX, ST, GAS 0.04 mV.
  MuscleVec baseline_rms = (MuscleVec() << 0.04e-3, 0.1e-3, 0.1e-3, 0.04e-3, 0.04e-3).finished();
  Eigen::Matrix<double, kNumMuscles, kNumMuscles> crosstalk =
      Eigen::Matrix<double, kNumMuscles, kNumMuscles>::Identity();
  double mains_amplitude = 0.0;  // V at the electrode (0 = off)
  double mains_freq = 50.0;      // Hz (50 or 60)
};

// Defaults: MVC RMS GMAX 1.5 mV, VM 3.0, RF 2.5, ST 2.5, GAS 2.5 mV. Our choice, from Hayashi's own
// figures: a relaxed level of 0.1 V / 0.04 V and a flexor level of ~0.8 V in swing-down (gain 1000)
// put the MVC at a few mV; the relaxed baseline is then 1.6-4 % of MVC, as usual for surface EMG, and
// within De Luca's (1997) 0-10 mV peak-to-peak. (With MVC ~ 1 mV, Hayashi's 0.1 mV baseline would be
// 10-12 % of MVC and bias every calibration.) Crosstalk VM<->RF 0.15, ST<->GAS 0.08, GMAX<->ST 0.05 (our choice,
// of the order reported for adjacent thigh muscles); mains off.
SyntheticEmgConfig DefaultSyntheticEmgConfig();

// The EXOwheel's recording set-up (Hwang & Jeon 2015 sec. 2.3: Delsys Bagnoli-8, gain 1000,
// 20-450 Hz): the default muscles and crosstalk with a relaxed baseline of 3 uV RMS on every channel
// (the Bagnoli DE-2.1 sensor's input noise is about 1.2 uV RMS; a relaxed muscle adds a few uV), i.e.
// 0.1-0.2 % of MVC. HAL's bioelectrical sensors (Hayashi) keep the default's 0.1 / 0.04 mV: that
// level is the relaxed activity of HAL's operator as printed, not a property of the EXOwheel's
// amplifier. With HAL's level on the EXOwheel (3-4 % of MVC), the envelope at 5 % MVC is
// sqrt(5^2 + 3.3^2) = 6 % and Table 6's 10-subject mean R^2 fell to 0.886 (paper 0.951-0.976).
SyntheticEmgConfig ExowheelSyntheticEmgConfig();

class SyntheticEmg {
 public:
  // Throws std::invalid_argument if fs <= 2 f_lp or a corner is not positive.
  SyntheticEmg(const SyntheticEmgConfig& config, uint64_t seed);
  // Next raw sample (V) of every channel for electrical activations e (0..1, clipped).
  MuscleVec Sample(const MuscleVec& e);
  // Samples for a whole activation record (rows = time, one per 1/fs). Convenience for tests.
  std::vector<MuscleVec> Generate(const std::vector<MuscleVec>& e);
  double time() const { return t_; }
  const SyntheticEmgConfig& config() const { return cfg_; }
  // Unit-variance shaping filter of the muscle signal (for spectra in tests).
  const std::vector<dsp::Biquad>& shaping() const { return shape_sos_; }
  double shaping_gain() const { return shape_gain_; }

 private:
  SyntheticEmgConfig cfg_;
  std::vector<dsp::Biquad> shape_sos_, base_sos_;
  double shape_gain_ = 1, base_gain_ = 1;  // 1 / RMS of the filters' output for unit white input
  std::vector<dsp::SosFilter> shape_, base_;
  std::vector<MuscleRng> z_muscle_, z_base_;
  double mains_phase_ = 0;
  double t_ = 0;
  long k_ = 0;
};

}  // namespace exotwin
