// Table 5 of Hwang & Jeon 2015 reproduced by the twin: RMS error (HJ15 eq. 22) between the measured torque
// of relaxed passive-mode gait and the torque predicted with identified, De Leva and Dempster human
// parameters (the exoskeleton identified in all three), plus Tables 3-4 (identified against the
// twin's ground truth), and their side-by-side text next to the paper's numbers.
// The run of the protocol itself (scenarios through the closed loop) is scenarios/table5_protocol.h.
#pragma once
#include <string>
#include <vector>

#include "formats/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

// RMS error (N m) of one joint with the three parameter sets.
struct Table5JointRmse {
  double identified = 0, deleva = 0, dempster = 0;
};

// One subject: the twin's RMS errors, and the ground truth vs the identified parameters.
struct Table5Entry {
  std::string subject;            // "S1".."S10"
  Table5JointRmse hip, knee;      // N m
  LegParams truth, identified;    // exo + human (identified: exo from steps 1-2, human from 3-4)
  double gait_samples = 0;        // samples after the ramp used for the RMS errors
};

// RMS error (HJ15 eq. 22) of the measured torque-sensor readings against the reading predicted for the
// measured kinematics (derivatives: zero-phase Butterworth 20 Hz) with `params`, over t in [t_from,
// t_to]. Leave ~0.1 s of recording outside the window at the ends: the derivatives of the filter's
// edges are wrong (a 0.1 s tail of gait otherwise adds ~4 N m to the hip RMS error).
// The prediction is the closed-form rigid dynamics + passive torque (model/leg_dynamics.h), which
// equals `exotwin predict` (MuJoCo inverse dynamics) to round-off and needs no realization.
// Returns {hip, knee}; throws InputError if no sample is in the window.
std::pair<double, double> GaitTorqueRmse(const MeasuredData& gait, const LegParams& params, double t_from,
                                         double t_to);

// The three parameter sets of Table 5 for a subject with body weight (kg) and lower-leg length L2 (m):
// `identified` as is, and its human replaced by Table4AnthropometricLumped De Leva / Dempster (Y = 0);
// passive riener1999 in all three.
std::vector<LegParams> Table5ParameterSets(const LegParams& identified, double weight, double L2);

// Fills entry->hip and entry->knee from the gait recording (t in [t_from, t_to]) with the three sets.
void ComputeTable5Rmse(const MeasuredData& gait, double t_from, double t_to, double weight, double L2,
                       Table5Entry* entry);

// Human-readable side-by-side text (Markdown tables): Table 5 twin vs paper per subject with the ratio
// twin / paper of each set, the means and the mean ratios anthropometric / identified; Tables 3-4
// identified vs truth per subject.
std::string Table5Markdown(const std::vector<Table5Entry>& entries, const std::string& header);

// CSV of Table 5: subject, then twin_* and paper_* RMS errors per joint and parameter set.
std::string Table5Csv(const std::vector<Table5Entry>& entries);

}  // namespace exotwin
