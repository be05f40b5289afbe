// Residual tests of a model's completeness (DESIGN.md "Terms beyond the table": `completeness`): does
// a model's held-out residual hold structure, or only noise?
//
// The residual of diagnose's torque fit is the measured minus the predicted torque, both low-passed at
// the cutoff (parallel filtering): a correct model leaves coloured noise, not white. The tests read it
// on rows decimated to a spacing at which that noise is near-independent (CompletenessStep: the
// filter's own autocorrelation, not a threshold tuned to a record); at that spacing, under the
// hypothesis "the model is complete" (the residual is white and independent of the motion), every
// statistic below has a known distribution, whatever the autocorrelation of the signals it is
// correlated with (Bartlett: var r_ue(k) = (1/N) sum_tau rho_u(tau) rho_e(tau) = 1/N for white e).
//
// The tests, each over one joint's segments (one per record; no correlation crosses a segment's
// boundary), e the residual standardized per segment, u a signal standardized per segment, ' the mean
// removed (and standardized), lags k in decimated rows:
//   whiteness   Ljung & Box (1978) Q = sum over segments of n (n + 2) sum_(k=1..m) r_ee(k)^2 / (n - k),
//               chi-square with the summed m under the hypothesis;
//   xcorr_<u>   linear cross-correlation phi_ue(k), k = -L..L (Billings & Voon 1986, eq. 3b), for u in
//               q, qd, qdd, tau_R (the joint's), q_other, qd_other (the other joint's), t, and
//               sgn(qd), |tau_R|: a friction that switches with the direction or grows with the load
//               leaves a residual of the form f(|tau_R|) sgn(qd), which correlates with these two at
//               lag 0 where its correlation with qd and tau_R themselves can vanish;
//   e_e2        phi_(e e^2')(k), k = 1..L (Billings & Zhu 1994): an error whose size follows its past
//               (a model's nonlinearity in its own output);
//   u2_e_<u>    phi_(u^2' e)(k), k = -L..L (Billings & Voon 1986, eq. 3d): an even function of u
//               left over (e.g. a friction growing with |qd| beyond the viscous line);
//   u2_e2_<u>   phi_(u^2' e^2')(k), k = -L..L (ibid. eq. 3e): the residual's size following u;
//   e_eu_<u>    phi_(e (e u))(k) = E[e(i) e(i-1-k) u(i-1-k)], k = 0..L (ibid. eq. 3c);
// for the nonlinear tests u in q, qd, qdd, tau_R, q_other, qd_other (e_eu: q, qd, tau_R). Each
// correlation statistic is z(k) = sum_segments sum_i a_i b_(i+k) / sqrt(count), N(0, 1) under the
// hypothesis; a test's statistic is max_k |z(k)|, its p-value Bonferroni over its lags. A test fails
// when its p-value is below alpha / (number of tests) (Bonferroni over the tests: family-wise level
// alpha, default 1 %, so a correct model is called complete with probability >= 99 %) and the
// structure it found is material: its size, the RMS of the part of the residual its correlation
// accounts for (first order: |r| RMS(e) at the test's largest |z|; whiteness: sqrt(sum_k r_ee(k)^2)
// RMS(e), the part its own past predicts), is at least the joint's material floor (the caller's:
// diagnose gives core/materiality.h's share of the measured torque's RMS, the floor below which the
// selection names no effect). A correct twin's residual holds, besides the sensor's noise, structure
// of the derivative filter's own (the predicted torque sees its attenuation of the motion, about
// (f / f_c)^4, f_c = 4 times the cutoff); on records of many thousand rows the tests see it, but it
// lies far below that floor. The model is complete when every test passes.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace exotwin {

constexpr double kCompletenessAlpha = 0.01;  // family-wise level of the verdict
constexpr size_t kCompletenessLags = 5;       // L, decimated rows each side
constexpr size_t kWhitenessLags = 10;         // m of Ljung-Box (fewer on a segment of < 4 m rows)
constexpr size_t kMinSegmentRows = 20;        // a shorter segment is left out of the tests

// One record's held-out rows of one joint, sampled every CompletenessStep rows, in time order: the
// residual (N m) and the signals on the same rows.
struct ResidualSegment {
  std::vector<double> e;
  std::vector<double> q, qd, qdd, tau_R;  // the joint's: rad, rad/s, rad/s^2, the rigid twin's actuator torque N m
  std::vector<double> q_other, qd_other;  // the other joint's angle and velocity
  std::vector<double> t;                  // s from the record's start
};

struct CompletenessTest {
  std::string name;        // e.g. "whiteness", "xcorr_qd", "u2_e2_tau_R"
  double statistic = 0;    // Q (whiteness) or max_k |z(k)|
  double threshold = 0;    // the statistic's critical value at the family-wise level
  double p_value = 1;      // Bonferroni over the test's lags (whiteness: the chi-square tail)
  double size = 0;         // the structure's size, the residual's unit (above)
  bool pass = true;        // p_value >= alpha / tests, or size < the material floor
};

struct JointCompleteness {
  bool assessed = false;   // false: no segment of kMinSegmentRows rows (then complete stays true)
  bool complete = true;
  size_t rows = 0;         // decimated rows tested, over the segments
  size_t step = 1;         // the decimation, in the records' rows
  double alpha = kCompletenessAlpha;
  double floor = 0;        // the material floor (the residual's unit)
  double rms = 0;          // the residual's RMS about each segment's mean, over the tested rows
  std::vector<CompletenessTest> tests;
};

// The residual tests of one joint's segments at the family-wise level alpha (0 < alpha < 1), structure
// below `material_floor` (>= 0, the residual's unit) passing. `step` is recorded in the result only.
JointCompleteness AssessCompleteness(const std::vector<ResidualSegment>& segments, size_t step,
                                     double material_floor, double alpha = kCompletenessAlpha);

// The smallest lag k >= 1 from which |acf(j)| <= tol for every j >= k, acf[j] the autocorrelation
// at lag j (acf[0] = 1); acf.size() when there is none.
size_t DecimationStep(const std::vector<double>& acf, double tol);

// The decimation of a residual sampled at fs (Hz) and low-passed by the zero-phase 2nd-order
// Butterworth at cutoff_hz (LowPassOnTimeBase; <= 0: not filtered, step 1): DecimationStep of the
// autocorrelation of white noise through that filter (the autocorrelation of its impulse response),
// tol kCompletenessAcfTol.
constexpr double kCompletenessAcfTol = 0.05;
size_t CompletenessStep(double fs, double cutoff_hz);

}  // namespace exotwin
