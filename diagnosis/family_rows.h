// The fit rows of the families with their own code, each defined in its family's file, gathered by
// the registry (fit_families.cc) in the model registry's order; and what those files share with it.
//   family_stiffness.cc  joint_stiffness
//   family_hinges.cc     backlash, series_compliance (one internal hinge per joint; one column pass)
//   family_ripple.cc     torque_ripple (its frequency searched on the residual)
//   family_sensors.cc    sensor_offset, sensor_gain, sensor_delay
//   family_muscle.cc     muscle_activity (the record's EMG envelopes)
#pragma once
#include <string>

#include "core/rng.h"
#include "diagnosis/fit_families.h"

namespace exotwin {

// The row of the model family `name` with its range check and generate's draw; throws
// std::logic_error for a name of no model family.
FitFamily FitRow(const char* name, std::string (*implausible)(const Effect& e, const PhysicalScale& s),
                 Effect (*draw)(Rng& rng, int joint, bool one_joint));
// The range edge half the largest measured torque at the joint (Coulomb friction, sensor offset).
double HalfTorqueEdge(int j, const PhysicalScale& s);

FitFamily JointStiffnessRow();
FitFamily BacklashRow();
FitFamily SeriesComplianceRow();
FitFamily TorqueRippleRow();
FitFamily SensorOffsetRow();
FitFamily SensorGainRow();
FitFamily SensorDelayRow();
FitFamily MuscleActivityRow();

}  // namespace exotwin
