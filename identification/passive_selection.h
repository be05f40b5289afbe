// Selection of passive samples by EMG, HJ15 eq. 13 of Hwang & Jeon 2015: a sample is passive when every
// channel's full-wave rectified, band-passed EMG chi_ch(k) is below its threshold Z_ch = mean + 3 SD
// of chi_ch while the muscle is relaxed.
//
// The emg_* columns of the measured CSV are the amplifier output (DESIGN.md: V, after the amplifier,
// i.e. already band-passed 20-450 Hz), so chi = |emg|. The relaxed reference is the first
// `reference_s` seconds of each file (the subject is asked to relax before the motion starts) unless
// a threshold is given. The paper applies the rule per sample (envelope_s = 0, the default); a
// moving-average envelope of width envelope_s (applied to the reference statistics and to the signal
// alike) makes the rule reject whole bursts of activity instead of their loud samples only.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "formats/measured_data.h"

namespace exotwin {

struct PassiveSelectionOptions {
  double reference_s = 2.0;  // s, length of the relaxed reference at the start of each file (> 0)
  double envelope_s = 0.0;   // s, moving-average window of the rectified EMG (0 = per sample, HJ15 eq. 13)
  double n_sd = 3.0;         // Z = mean + n_sd * SD (HJ15 eq. 13: 3)
  // Given thresholds Z_ch (V of the rectified amplifier output) by channel name ("VM" or "emg_VM");
  // key "*" applies to every channel without its own entry. They replace the reference statistics.
  std::map<std::string, double> thresholds;
};

struct PassiveSelection {
  std::vector<char> passive;             // per sample: 1 = every channel below threshold (A_ch = 0)
  std::vector<std::string> channels;     // emg_* columns used; empty = no EMG, every sample passive
  std::vector<double> thresholds;        // Z_ch per channel (V)
  size_t kept = 0;                       // number of passive samples
};

// Applies HJ15 eq. 13 to one file. Without emg_* columns every sample is passive. Throws InputError
// (naming data.source) if the reference window holds fewer than 10 samples.
PassiveSelection SelectPassiveSamples(const MeasuredData& data, const PassiveSelectionOptions& opt = {});

}  // namespace exotwin
