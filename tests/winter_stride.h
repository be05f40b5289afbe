// Winter's stride as the gait scenarios play it (controller::GaitTrajectory from data/WinterTableA1.txt,
// 2 s stride, knee shifted by -3 deg as runner/exowheel_setup.cc BuildTrajectory does), sampled for
// the tests' own OpenSim motion files (tests/motion_file.h).
#pragma once
#include <vector>

#include "controller/trajectory.h"
#include "core/units.h"

namespace exotwin::testing {

struct SampledStride {
  std::vector<double> t, hip, knee;  // s (from t0), rad
};

// One stride [0, period) sampled at rate_hz (the last sample one step before the first repeats),
// times shifted by t0.
inline SampledStride WinterStride(double rate_hz = 100.0, double t0 = 0.0, double period = 2.0) {
  controller::GaitSpec g;
  g.stride_period_s = period;
  g.knee_offset = -3.0 / kDegPerRad;
  const controller::GaitTrajectory gait =
      controller::GaitTrajectory::FromWinterFile(controller::GaitTrajectory::DefaultWinterPath(), g);
  SampledStride s;
  const int n = static_cast<int>(period * rate_hz + 0.5);
  for (int i = 0; i < n; ++i) {
    controller::JointSetpoint h, k;
    gait.Sample(i / rate_hz, &h, &k);
    s.t.push_back(t0 + i / rate_hz);
    s.hip.push_back(h.q);
    s.knee.push_back(k.q);
  }
  return s;
}

}  // namespace exotwin::testing
