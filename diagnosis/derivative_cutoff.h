// The cutoff of the zero-phase derivative filter (DeriveKinematics), chosen from the data.
//
// Differentiating a measured angle twice multiplies its noise by (2 pi f)^2: on a rig with a coarse
// encoder at 500 Hz the 20 Hz filter of Hwang & Jeon sec. 3.2 leaves more noise in qdd than the
// effects have signal (shared/data/real_rig/README.md), while on a clean 1 kHz record a low cutoff
// distorts the motion itself. The choice is the classic bias-variance trade-off, settled by held-out
// prediction error of the pipeline that will use the cutoff (CutoffUse):
//   for each candidate cutoff fc (1.5 .. 50 Hz, below fs / 4), a generic linear model of the joint
//   torques is fitted by least squares on the first 70 % (in time) of every record: the rigid
//   two-link regressor in the lumped parameters (FullRegressor: M qdd + V + G, any device with that
//   structure), plus per joint a torque offset, Coulomb (sign qd) and viscous (qd) friction.
//   kDerivatives (predict, identify): the angles differentiated at fc, the torque as measured.
//   kParallel (diagnose; parallel filtering, as in robot identification practice): the angles
//   differentiated at DerivativeCutoffHz(fc) (flat where fc passes), the regressor's columns and the
//   torque both low-passed at fc. Its prediction is scored on the last 30 % against the raw,
//   unfiltered measured torque, whose own noise is the same for every fc. The score is the sum over joints of the
//   held-out mean square error divided by that joint's torque variance. The chosen cutoff is the
//   lowest (the most filtering, the most regularized model) whose score is within one standard
//   error of the best: the one-standard-error rule of cross-validation (Hastie, Tibshirani &
//   Friedman, The Elements of Statistical Learning, sec. 7.10), the standard error taken of the
//   paired row-by-row differences to the best (their spread and autocorrelation length), so that
//   what every fit misses alike cancels.
// Model-free apart from L1 and g (the fitted parameters absorb the device), so `identify`, `predict`
// and `diagnose` share it.
#pragma once
#include <string>
#include <vector>

#include "formats/measured_data.h"

namespace exotwin {

struct CutoffChoice {
  double hz = 20.0;                     // chosen cutoff
  bool from_columns = false;            // every record has qd_* and qdd_* columns: no filter used
  std::vector<double> candidates_hz;    // scored cutoffs, ascending
  std::vector<double> heldout_rmse[2];  // N m, per candidate, hip / knee, against the raw torque
  std::vector<double> score;            // the criterion per candidate (lower is better)
  std::vector<double> score_se;         // standard error of score - best score (paired rows)
  std::string why;                      // one sentence for the report
};

// Chooses the cutoff for records of one device (each at least 200 samples). L1 (m) and g (m/s^2)
// enter the regressor's coupling and gravity columns. Throws InputError when no candidate fits the
// records' sample rate (fs / 4 <= 1.5 Hz). threads: the candidates' rates, regressor and low-passes on
// up to that many threads (0: every core, at most 2 used); the same choice, bit for bit, on any count.
enum class CutoffUse { kDerivatives, kParallel };
CutoffChoice ChooseCutoff(const std::vector<const MeasuredData*>& records, double L1, double g,
                          CutoffUse use, int threads = 0);

// The angles' derivative cutoff under a residual low-pass at fc: 4 fc (the zero-phase 2nd-order
// Butterworth then passes 99 % at fc, so measured and predicted torque see one filter), at most
// 0.4 fs.
constexpr double kDerivativeCutoffFactor = 4.0;
double DerivativeCutoffHz(double fc, double fs);

// Parses a `--cutoff` value: "auto" gives 0 (choose from the data), else a frequency in Hz > 0.
// Throws InputError naming `what` (the option) otherwise.
double ParseCutoffOption(const std::string& value, const std::string& what);

// The derivative cutoff (Hz) a `--cutoff` value asks for on `records`: a frequency as given, "auto"
// through ChooseCutoff(kDerivatives) (20 Hz, unused, when the records carry their own qd/qdd
// columns). *why (optional) says how it was chosen.
double ResolveCutoffOption(const std::string& value, const std::string& what,
                           const std::vector<const MeasuredData*>& records, double L1, double g,
                           std::string* why = nullptr);

}  // namespace exotwin
