// MVC normalization of EMG linear envelopes (Hwang & Jeon 2015 sec. 4.3: LE = envelope / MVC, the
// MVC "the average of the three highest EMG peaks" of three maximum voluntary contraction trials).
#pragma once
#include <cstddef>
#include <utility>
#include <vector>

namespace exotwin::dsp {

// MVC value (unit of env, V for an envelope): the mean over the trials of the maximum of env inside
// each trial's sample window [start, end). Throws std::invalid_argument when trials is empty or a
// window is empty or reaches past env.
double MvcOfTrials(const std::vector<double>& env, const std::vector<std::pair<size_t, size_t>>& trials);

// Normalized envelope (fraction of MVC): (env - rest) / (mvc - rest), env, rest, mvc in one unit
// (V). rest = 0 gives the paper's env / MVC; rest, the relaxed level, removes an electrode /
// amplifier floor. Precondition: mvc > rest.
inline double NormalizeToMvc(double env, double rest, double mvc) { return (env - rest) / (mvc - rest); }

}  // namespace exotwin::dsp
