// Identification of a one-joint device (DESIGN.md "One-joint devices"): least squares of HKS05
// eq. 4 (Lee & Sankai), tau_R = I thdd + mgl sin th [+ R thd + C sgn(thd)], from swings of the joint,
// with standard errors.
#pragma once
#include <string>
#include <vector>

#include "formats/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

struct OneJointEstimate {
  std::vector<std::string> names;  // "I", "mgl" [, "R", "C"]
  std::vector<double> value, se;   // kg m^2, N m, N m s/rad, N m; standard errors
  double rmse = 0;                 // N m, residual of the fit
  double condition = 0;            // of the column-normalized regressor
  double autocorrelation_rows = 1; // residual autocorrelation length: the standard errors' inflation^2
  size_t samples = 0;
};

// Fits the records (one-joint records, data.one_joint; each at least 200 samples): the angle
// differentiated at `cutoff_hz` (DeriveKinematics), the torque as measured (tau_R = -tau_S), `trim_s`
// dropped at both ends of every record. Standard errors from the residual variance with the effective
// sample size n / (residual autocorrelation length). `friction`: R and C too. Throws InputError for a
// record of two joints, too short records, or a regressor without rank (a joint that does not swing).
OneJointEstimate IdentifyOneJoint(const std::vector<MeasuredData>& records, double cutoff_hz, double trim_s,
                                  bool friction);

// The model file of the estimate (device {I, mgl, R, C}, g 9.81) and its `identification:` block.
LegParams OneJointParamsOf(const OneJointEstimate& e);
std::string OneJointIdentificationYaml(const OneJointEstimate& e, double cutoff_hz);

}  // namespace exotwin
