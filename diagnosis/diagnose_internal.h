// The torque fit's internal parts shared by its files (diagnose.cc, diagnose_ceiling.cc).
#pragma once
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/diagnose_columns.h"

namespace exotwin {

// Held-out scores from the sums of squares before / after over `count` samples.
JointScore ScoreOf(double sse_before, double sse_after, double count);

// Stage 3d: every record's ceiling (RecordScore::ceiling): all candidate columns at once fitted on
// that record's bank alone, each effect's value of the sign its range allows (coulomb, viscous,
// backlash, series_compliance's 1/k, sensor_delay, joint_stiffness >= 0; the others free: a
// relaxation of DESIGN.md's ranges, so the ceiling bounds any in-range combination), scored on its
// fit rows against the residual of the model given (weights undone; a joint of weight 0, a
// one-joint device's held hip, scores 0). Also its null level (RecordScore::ceiling_null): the same
// fit against the residual shifted circularly in time by kNullShifts of the record's rows (every
// joint alike), the after-error's sum of squares averaged over the shifts: a circular-shift
// permutation test of "the residual is no function of the motion", its spectrum kept.
struct CeilingScores {
  JointScore ceiling[2], null[2];
};
std::vector<CeilingScores> Ceilings(const std::vector<ColumnBank>& banks, const double w[2]);

}  // namespace exotwin
