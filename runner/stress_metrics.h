// Physical-stress metrics of LS05 eq. 12-18 for sweeps of the virtual impedance.
// Records are sampled every dt (s); integrals by the rectangle rule (sum |x| dt).
#pragma once
#include <cstddef>
#include <vector>

namespace exotwin {

// LS05 eq. 12: mean musculoskeletal moment J_tau = (1/t_f) int_0^tf |tau_m| dt (N m); t_f = n dt.
double MeanAbsMoment(const std::vector<double>& tau_m, double dt);

// LS05 eq. 15/16: integrated myoelectricity J = int_0^tf |m| dt (V s).
double IntegratedMyoelectricity(const std::vector<double>& m, double dt);

// LS05 eq. 13/14 with (17)/(18): each trial's J divided by the maximum over the trials (0..1].
// Precondition: non-empty, max > 0.
std::vector<double> NormalizeByMax(const std::vector<double>& J);

// Index of the smallest value (the "lowest point" Lee & Sankai read off their Fig. 9). Non-empty.
std::size_t ArgMin(const std::vector<double>& v);

}  // namespace exotwin
