// MVC normalization: see mvc.h.
#include "dsp/mvc.h"

#include <algorithm>
#include <stdexcept>

namespace exotwin::dsp {

double MvcOfTrials(const std::vector<double>& env, const std::vector<std::pair<size_t, size_t>>& trials) {
  if (trials.empty()) throw std::invalid_argument("MvcOfTrials: no trials");
  double s = 0;
  for (const auto& [a, b] : trials) {
    if (!(b > a) || b > env.size()) throw std::invalid_argument("MvcOfTrials: bad window");
    s += *std::max_element(env.begin() + a, env.begin() + b);
  }
  return s / trials.size();
}

}  // namespace exotwin::dsp
