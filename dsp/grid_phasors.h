// The phasors exp(i 2 pi f x_k) of points x_k (times, angles) on a frequency grid f_g = f_0 + g df:
// a direct DFT, or a sinusoid's least-squares fit scanned over frequency, at one complex product per
// point and frequency instead of a cosine and a sine. Each phasor is stepped from one grid frequency
// to the next by the constant factor exp(i 2 pi df x_k) and taken afresh by cos/sin every `anchor`
// grid frequencies, so that the rounding of the products stays near `anchor` ulps.
#pragma once
#include <cstddef>
#include <vector>

namespace exotwin::dsp {

class GridPhasors {
 public:
  // x: the points; df: the grid step (in 1 / the unit of x); anchor >= 1.
  GridPhasors(std::vector<double> x, double df, int anchor);
  // The phasors at f, directly: cos and sin of 2 pi f x_k.
  void At(double f);
  // The phasors at grid frequency g, f: directly where g % anchor == 0, else one step from the
  // previous call's (grid frequency g - 1; g counts up by one from 0).
  void AtGrid(int g, double f);
  size_t size() const { return x_.size(); }
  const std::vector<double>& re() const { return re_; }
  const std::vector<double>& im() const { return im_; }

 private:
  std::vector<double> x_, re_, im_, step_re_, step_im_;
  int anchor_;
};

}  // namespace exotwin::dsp
