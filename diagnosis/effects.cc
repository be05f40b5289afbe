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

namespace {

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

namespace {

// The forms that need more than one sample's state (no EffectFamily::link_torque): added to tau_R.
// backlash: the link's dynamics at q_link,j = q_j - (b/2) s(tau_rigid,j) (header); series_compliance:
// the compliant part at its quasi-static angle (CompliantAngle); muscle_activity: the EMG envelopes.
void AddRecordForm(const EffectFamily& f, const Effect& e, const LegParams& rigid, const Kinematics& kin,
                   const std::vector<double> tau_rigid[2], std::vector<double> tau_R[2]) {
  const size_t n = kin.t.size();
  const int j = EffectJoint(e);
  if (f.carrier == PlantCarrier::kDeadBandHinge) {
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d q = At(kin.q, i), qd = At(kin.qd, i), qdd = At(kin.qdd, i);
      Eigen::Vector2d ql = q;
      ql[j] -= 0.5 * e.value * std::tanh(tau_rigid[j][i] / kBacklashTorqueWidth);
      const Eigen::Vector2d d = ActuatorTorque(rigid, ql, qd, qdd) - ActuatorTorque(rigid, q, qd, qdd);
      tau_R[0][i] += d[0];
      tau_R[1][i] += d[1];
    }
  } else if (f.carrier == PlantCarrier::kStrapHinge) {
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d q = At(kin.q, i), qd = At(kin.qd, i), qdd = At(kin.qdd, i);
      const Eigen::Vector2d qc = CompliantAngle(rigid, j, e.value, q, qd, qdd);
      const Eigen::Vector2d d = CompliantPartTorque(rigid, qc, qd, qdd) - CompliantPartTorque(rigid, q, qd, qdd);
      tau_R[0][i] += d[0];
      tau_R[1][i] += d[1];
    }
  } else if (f.carrier == PlantCarrier::kNotCarried) {
    bool any = false;
    for (const auto& w : e.fields) {
      if (w.first.rfind("w_", 0) != 0) continue;
      const std::string ch = w.first.substr(2);
      const auto it = kin.emg.find(ch);
      if (it == kin.emg.end())
        throw InputError("effect " + e.name + " (" + e.joint + "): weight for channel '" + ch +
                         "' but the measured data have no column 'emg_" + ch + "'");
      const std::vector<double> env = EmgEnvelope(kin.t, it->second);
      for (size_t i = 0; i < n; ++i) tau_R[j][i] += e.value * w.second * env[i];
      any = true;
    }
    if (!any)
      throw InputError("effect " + e.name + " (" + e.joint +
                       "): expected weights {channel: N m per V} for at least one EMG channel");
  } else {
    throw std::logic_error("effect family " + std::string(f.name) + ": no closed form on the link");
  }
}

}  // namespace

void ApplyEffects(const LegParams& params, const Kinematics& kin, std::vector<double> tau_R[2],
                  std::vector<double> tau_S[2]) {
  const size_t n = kin.t.size();
  LegParams rigid = params;
  rigid.effects.clear();
  // The rigid torque, for the forms that depend on it (the dead band; a term's tau_R).
  std::vector<double> tau_rigid[2];
  for (const Effect& e : params.effects)
    if (FamilyOf(e).carrier == PlantCarrier::kDeadBandHinge || FamilyOf(e).carries_expr) {
      tau_rigid[0] = tau_R[0], tau_rigid[1] = tau_R[1];
      break;
    }
  // Sample i's state; a term's t from the record's first sample.
  const double t0 = std::isnan(kin.t_start) ? (n ? kin.t[0] : 0.0) : kin.t_start;
  EffectState s;
  s.g = params.g;
  auto state_at = [&](size_t i) -> const EffectState& {
    s.q = At(kin.q, i), s.qd = At(kin.qd, i), s.qdd = At(kin.qdd, i);
    if (!tau_rigid[0].empty()) s.tau_R = At(tau_rigid, i);
    s.t = kin.t[i] - t0;
    return s;
  };
  for (const Effect& e : params.effects) {
    const EffectFamily& f = FamilyOf(e);
    if (StageOf(e) != EffectStage::kLink) continue;
    if (!f.link_torque) {
      AddRecordForm(f, e, rigid, kin, tau_rigid, tau_R);
      continue;
    }
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d d = f.link_torque(e, state_at(i));
      tau_R[0][i] += d[0];
      tau_R[1][i] += d[1];
    }
  }
  for (int j = 0; j < 2; ++j) {
    tau_S[j].resize(n);
    for (size_t i = 0; i < n; ++i) tau_S[j][i] = -tau_R[j][i];
  }
  // The sensor effects in the order listed: a family's form on the reading, or a sample's closed
  // form (a sensor-stage term) added to it.
  for (const Effect& e : params.effects) {
    const EffectFamily& f = FamilyOf(e);
    if (StageOf(e) != EffectStage::kSensor) continue;
    const int j = EffectJoint(e);
    if (f.on_reading) {
      f.on_reading(e, kin.t, &tau_S[j]);
      continue;
    }
    for (size_t i = 0; i < n; ++i) tau_S[j][i] += f.link_torque(e, state_at(i))[j];
  }
}

}  // namespace exotwin
