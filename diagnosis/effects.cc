#include "diagnosis/effects.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "dsp/butterworth.h"
#include "dsp/emg_envelope.h"
#include "model/leg_dynamics.h"
#include "model/passive_torque.h"
#include "sim/plant_effects.h"

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

Eigen::Vector2d At(const std::vector<double> v[2], size_t i) { return {v[0][i], v[1][i]}; }

}  // namespace

std::vector<double> EmgEnvelope(const std::vector<double>& t, const std::vector<double>& emg) {
  return std::move(EmgEnvelopes(t, {&emg})[0]);
}

std::vector<std::vector<double>> EmgEnvelopes(const std::vector<double>& t,
                                              const std::vector<const std::vector<double>*>& emg) {
  for (const std::vector<double>* x : emg)
    if (t.size() < 2 || x->size() != t.size())
      throw InputError("EMG envelope: expected an EMG column with one value per sample");
  const double fs = 1.0 / MedianStep(t);
  if (!(fs > 40.0))
    throw InputError("EMG envelope: sample rate " + std::to_string(fs) +
                     " Hz, expected above 40 Hz for the 20 Hz high-pass");
  static thread_local double cached_fs = -1;
  static thread_local std::vector<dsp::Biquad> hp, lp;
  if (fs != cached_fs) {
    hp = dsp::DesignButterworth(2, dsp::BandType::kHighPass, fs, 20.0);
    lp = dsp::EnvelopeLowPassDesign(fs, 2.0);
    cached_fs = fs;
  }
  // Odd reflection of up to 1 s at both ends before filtering keeps the start-up transients of
  // the 2 Hz low-pass out of the record.
  const size_t pad = std::min(t.size() - 1, static_cast<size_t>(fs));
  return dsp::ZeroPhaseEnvelopes(hp, lp, emg, pad);
}

void ApplyEffects(const LegParams& params, const Kinematics& kin, std::vector<double> tau_R[2],
                  std::vector<double> tau_S[2]) {
  const size_t n = kin.t.size();
  LegParams rigid = params;
  rigid.effects.clear();
  std::vector<double> tau_rigid[2];  // the rigid torque, for the effects that depend on it (backlash)
  for (const Effect& e : params.effects)
    if (e.name == "backlash") {
      tau_rigid[0] = tau_R[0], tau_rigid[1] = tau_R[1];
      break;
    }
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
      for (size_t i = 0; i < n; ++i) tr[i] += TorqueRippleTorque(e, kin.q[j][i]);
    } else if (e.name == "passive_moment") {
      for (size_t i = 0; i < n; ++i) tr[i] += PassiveMomentTorque(e, At(kin.q, i));
    } else if (e.name == "gravity_error") {
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector2d dG = GravityErrorTorque(e, params.g, At(kin.q, i));
        tau_R[0][i] += dG[0];
        if (j == 1) tau_R[1][i] += dG[1];
      }
    } else if (e.name == "backlash") {
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector2d q = At(kin.q, i), qd = At(kin.qd, i), qdd = At(kin.qdd, i);
        Eigen::Vector2d ql = q;
        ql[j] -= 0.5 * e.value * std::tanh(tau_rigid[j][i] / kBacklashTorqueWidth);
        const Eigen::Vector2d d = ActuatorTorque(rigid, ql, qd, qdd) - ActuatorTorque(rigid, q, qd, qdd);
        tau_R[0][i] += d[0];
        tau_R[1][i] += d[1];
      }
    } else if (e.name == "series_compliance") {
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector2d q = At(kin.q, i), qd = At(kin.qd, i), qdd = At(kin.qdd, i);
        const Eigen::Vector2d qc = CompliantAngle(rigid, j, e.value, q, qd, qdd);
        const Eigen::Vector2d d =
            CompliantPartTorque(rigid, qc, qd, qdd) - CompliantPartTorque(rigid, q, qd, qdd);
        tau_R[0][i] += d[0];
        tau_R[1][i] += d[1];
      }
    } else if (e.name == "muscle_activity") {
      bool any = false;
      for (const auto& f : e.fields) {
        if (f.first.rfind("w_", 0) != 0) continue;
        const std::string ch = f.first.substr(2);
        const auto it = kin.emg.find(ch);
        if (it == kin.emg.end())
          throw InputError("effect muscle_activity (" + e.joint + "): weight for channel '" + ch +
                           "' but the measured data have no column 'emg_" + ch + "'");
        const std::vector<double> env = EmgEnvelope(kin.t, it->second);
        for (size_t i = 0; i < n; ++i) tr[i] += e.value * f.second * env[i];
        any = true;
      }
      if (!any)
        throw InputError("effect muscle_activity (" + e.joint +
                         "): expected weights {channel: N m per V} for at least one EMG channel");
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
    }
  }
}

}  // namespace exotwin
