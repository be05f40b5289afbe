#include "analysis/effects.h"

#include <cmath>

#include "model/input_error.h"

namespace exotwin {

int EffectJoint(const Effect& e) { return e.joint == "hip" ? 0 : 1; }

namespace {

double Sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

// Value of signal x at times t - delay (linear interpolation, held at the first sample).
std::vector<double> Delayed(const std::vector<double>& t, const std::vector<double>& x, double delay) {
  std::vector<double> tq(t.size());
  for (size_t i = 0; i < t.size(); ++i) tq[i] = t[i] - delay;
  return Interpolate(t, x, tq);
}

}  // namespace

void ApplyEffects(const LegParams& params, const Kinematics& kin, std::vector<double> tau_R[2],
                  std::vector<double> tau_S[2]) {
  const size_t n = kin.t.size();
  for (const Effect& e : params.effects) {
    const int j = EffectJoint(e);
    auto& tr = tau_R[j];
    if (e.name == "coulomb_friction") {
      for (size_t i = 0; i < n; ++i) tr[i] += e.value * Sign(kin.qd[j][i]);
    } else if (e.name == "viscous_friction") {
      for (size_t i = 0; i < n; ++i) tr[i] += e.value * kin.qd[j][i];
    } else if (e.name == "inertia_error") {
      for (size_t i = 0; i < n; ++i) tr[i] += e.value * kin.qdd[j][i];
    } else if (e.name == "joint_stiffness") {
      const double q0 = e.fields.at("q0");
      for (size_t i = 0; i < n; ++i) tr[i] += e.value * (kin.q[j][i] - q0);
    } else if (e.name == "torque_ripple") {
      const double k = e.fields.at("cycles_per_rad"), ph = e.fields.at("phase");
      for (size_t i = 0; i < n; ++i) tr[i] += e.value * std::sin(2 * M_PI * k * kin.q[j][i] + ph);
    } else if (e.name == "gravity_error") {
      // The lumped X (or Y) of the segment distal to joint j is off by value: its gravity torque
      // changes by g dX sin(angle) (or g dY cos(angle)) at that joint and every proximal joint
      // (eq. 7); for the thigh (j = 0) only the hip row changes.
      for (size_t i = 0; i < n; ++i) {
        const double ang = j == 0 ? kin.q[0][i] : kin.q[0][i] + kin.q[1][i];
        const double dG = params.g * e.value * (e.axis == "Y" ? std::cos(ang) : std::sin(ang));
        tau_R[0][i] += dG;
        if (j == 1) tau_R[1][i] += dG;
      }
    }
  }
  for (int j = 0; j < 2; ++j) {
    tau_S[j].resize(n);
    for (size_t i = 0; i < n; ++i) tau_S[j][i] = -tau_R[j][i];
  }
  for (const Effect& e : params.effects) {
    const int j = EffectJoint(e);
    if (e.name == "sensor_offset") {
      for (double& v : tau_S[j]) v += e.value;
    } else if (e.name == "sensor_gain") {
      for (double& v : tau_S[j]) v *= 1.0 + e.value;
    } else if (e.name == "sensor_delay") {
      tau_S[j] = Delayed(kin.t, tau_S[j], e.value);
    } else if (e.name == "backlash" || e.name == "series_compliance" || e.name == "muscle_activity") {
      throw InputError("effect '" + e.name + "' is not supported by this build's predict");
    }
  }
}

}  // namespace exotwin
