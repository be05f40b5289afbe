#include "dsp/grid_phasors.h"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace exotwin::dsp {

GridPhasors::GridPhasors(std::vector<double> x, double df, int anchor)
    : x_(std::move(x)), re_(x_.size()), im_(x_.size()), step_re_(x_.size()), step_im_(x_.size()), anchor_(anchor) {
  if (anchor < 1) throw std::invalid_argument("GridPhasors: anchor below 1");
  for (size_t i = 0; i < x_.size(); ++i) {
    const double a = 2 * M_PI * df * x_[i];
    step_re_[i] = std::cos(a), step_im_[i] = std::sin(a);
  }
}

void GridPhasors::At(double f) {
  for (size_t i = 0; i < x_.size(); ++i) {
    const double a = 2 * M_PI * f * x_[i];
    re_[i] = std::cos(a), im_[i] = std::sin(a);
  }
}

void GridPhasors::AtGrid(int g, double f) {
  if (g % anchor_ == 0) return At(f);
  for (size_t i = 0; i < x_.size(); ++i) {
    const double r = re_[i] * step_re_[i] - im_[i] * step_im_[i];
    im_[i] = re_[i] * step_im_[i] + im_[i] * step_re_[i];
    re_[i] = r;
  }
}

}  // namespace exotwin::dsp
