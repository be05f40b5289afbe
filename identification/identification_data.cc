#include "identification/identification_data.h"

#include <algorithm>
#include <cmath>

#include "formats/csv_table.h"
#include "core/error.h"
#include "core/rng.h"
#include "model/leg_dynamics.h"
#include "sim/plant.h"
#include "sim/realization.h"

namespace exotwin {

namespace {

const char* const kEmgNames[5] = {"emg_GMAX", "emg_VM", "emg_RF", "emg_ST", "emg_GAS"};

double Quantize(double v, double step) { return step > 0 ? std::round(v / step) * step : v; }

LumpedParams Scaled(const LumpedParams& p, double s) {
  LumpedParams r;
  r.J1 = s * p.J1;
  r.J2 = s * p.J2;
  r.X1 = s * p.X1;
  r.X2 = s * p.X2;
  r.Y1 = s * p.Y1;
  r.Y2 = s * p.Y2;
  return r;
}

MeasuredData SimulateTrial(Plant& plant, const LegParams& ff, bool knee_swing, int trial,
                           const ProtocolOptions& opt) {
  // Sensor and EMG noise of this (configuration, trial).
  NormalRng<NormalBoxMullerPair<BoxMullerU1::kMidpoint>> rng(
      MixSeed(opt.seed * 1000003ULL + (knee_swing ? 0 : 500) + static_cast<uint64_t>(trial)));
  const double dt = plant.timestep();
  const size_t n = static_cast<size_t>(std::llround(opt.trial_s / dt));
  const int m = knee_swing ? 1 : 0;  // moving joint
  const HarmonicTrajectory& tr = knee_swing ? opt.knee_traj : opt.hip_traj;
  const bool emg = opt.emg_rms > 0 && plant.params().human.has_value();
  const double enc = opt.encoder_bits > 0 ? 2.0 * M_PI / std::ldexp(1.0, opt.encoder_bits) : 0.0;
  const TorqueSensorModel& sm = opt.sensor;

  CsvTable tab;
  tab.names = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "cmd_hip", "cmd_knee"};
  if (emg)
    for (const char* e : kEmgNames) tab.names.push_back(e);
  tab.columns.assign(tab.names.size(), std::vector<double>(n));
  tab.line_of_row.resize(n);

  Eigen::Vector2d q_ref(opt.hold_hip, opt.hold_knee), qd_ref = Eigen::Vector2d::Zero(),
      qdd_ref = Eigen::Vector2d::Zero();
  tr.Eval(0.0, &q_ref[m], &qd_ref[m], &qdd_ref[m]);
  plant.Reset(q_ref, qd_ref, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    tr.Eval(t, &q_ref[m], &qd_ref[m], &qdd_ref[m]);
    const Eigen::Vector2d q = plant.q(), qd = plant.qd();
    const Eigen::Vector2d q_enc(Quantize(q[0], enc), Quantize(q[1], enc));
    Eigen::Vector2d tau = Eigen::Vector2d::Zero();
    if (opt.ff_scale > 0) tau = ActuatorTorque(ff, q_ref, qd_ref, qdd_ref);
    tau += opt.kp.cwiseProduct(q_ref - q_enc) + opt.kd.cwiseProduct(qd_ref - qd);
    // Actuator ctrlrange of the MJCF: +-150 N m. The held joint's torque beyond it is carried by a
    // support (in the knee swing the subject sits: the seat carries the thigh, sec. 3.1); it acts on
    // the held joint only, so the moving joint's row (the one identified) is untouched.
    Eigen::Vector2d tau_ext = Eigen::Vector2d::Zero();
    const double held_cmd = tau[1 - m];
    tau = tau.cwiseMax(-150.0).cwiseMin(150.0);
    tau_ext[1 - m] = held_cmd - tau[1 - m];
    double emg_rms = opt.emg_rms;
    if (plant.params().human)
      for (const ActivityBurst& b : opt.bursts)
        if (t >= b.t0 && t < b.t1) {
          tau_ext += b.tau_M;
          emg_rms = b.emg_rms;
        }
    tab.line_of_row[i] = static_cast<int>(i) + 2;
    tab.columns[0][i] = t;
    tab.columns[1][i] = q_enc[0];
    tab.columns[2][i] = q_enc[1];
    for (int j = 0; j < 2; ++j) {
      const double v = std::clamp(-tau[j] + sm.offset + sm.noise_sd * rng.Normal(), -sm.range, sm.range);
      tab.columns[3 + j][i] = Quantize(v, sm.resolution);  // tau_S = -tau_R, HJ15 eq. 8
      tab.columns[5 + j][i] = tau[j];
    }
    if (emg)
      for (int c = 0; c < 5; ++c) tab.columns[7 + c][i] = emg_rms * rng.Normal();
    plant.Step(tau, tau_ext);
  }
  const std::string name = std::string(knee_swing ? "knee_" : "hip_") + std::to_string(trial + 1);
  return MakeMeasuredData(std::move(tab), name);
}

}  // namespace

std::vector<MeasuredData> ProtocolData::All() const {
  std::vector<MeasuredData> all = knee;
  all.insert(all.end(), hip.begin(), hip.end());
  return all;
}

MeasuredData WithTorqueSensor(const MeasuredData& d, const TorqueSensorModel& sm, uint64_t seed) {
  const int cmd[2] = {d.table.Find("cmd_hip"), d.table.Find("cmd_knee")};
  if (cmd[0] < 0 || cmd[1] < 0)
    throw InputError(d.source + ": no cmd_hip / cmd_knee columns, expected a synthetic recording");
  NormalRng<NormalBoxMullerPair<BoxMullerU1::kMidpoint>> rng(MixSeed(seed));
  CsvTable tab = d.table;
  const int tau[2] = {tab.Find("tau_hip"), tab.Find("tau_knee")};
  for (size_t i = 0; i < tab.rows(); ++i)
    for (int j = 0; j < 2; ++j) {
      const double v = std::clamp(-tab.columns[cmd[j]][i] + sm.offset + sm.noise_sd * rng.Normal(),
                                  -sm.range, sm.range);
      tab.columns[tau[j]][i] = Quantize(v, sm.resolution);
    }
  return MakeMeasuredData(std::move(tab), d.source);
}

LegParams RegroupForRealization(const LegParams& p) {
  if (!p.human) return p;
  auto ok = [&](double dJ) {
    LumpedParams e = p.exo, h = *p.human;
    e.J1 -= dJ;
    h.J1 += dJ;
    try {
      RealizeLumped(e, p.L1, "exo");
      RealizeLumped(h, p.L1, "human");
      return true;
    } catch (const InputError&) {
      return false;
    }
  };
  for (int i = 0; i <= 200; ++i) {
    const double dJ = 0.01 * i;
    if (ok(dJ)) {
      const double shift = i == 0 ? 0.0 : dJ + 0.05;
      if (i > 0 && !ok(shift)) continue;
      LegParams r = p;
      r.exo.J1 -= shift;
      r.human->J1 += shift;
      return r;
    }
  }
  throw InputError("human: no realizable split of exo + human found (moved up to 2 kg m^2 of J1)");
}

ProtocolData SimulateProtocol(const LegParams& truth, const ProtocolOptions& opt) {
  const bool human = truth.human.has_value();
  Plant plant(ExowheelMjcfPath(human));
  plant.SetParams(RegroupForRealization(truth));
  LegParams ff = truth;
  ff.exo = Scaled(truth.exo, opt.ff_scale);
  if (human) ff.human = Scaled(*truth.human, opt.ff_scale);
  ProtocolData out;
  for (int k = 0; k < opt.trials; ++k) out.knee.push_back(SimulateTrial(plant, ff, true, k, opt));
  for (int k = 0; k < opt.trials; ++k) out.hip.push_back(SimulateTrial(plant, ff, false, k, opt));
  return out;
}

void WriteProtocolCsv(const ProtocolData& data, const std::string& dir, const std::string& prefix) {
  for (const MeasuredData& d : data.All()) {
    std::vector<const std::vector<double>*> cols;
    for (const auto& c : d.table.columns) cols.push_back(&c);
    WriteCsv(dir + "/" + prefix + d.source + ".csv", d.table.names, cols,
             {"exotwin synthetic identification recording (" + d.source +
              "): tau_* = torque-sensor reading tau_S = -tau_R (N m), q_* encoder (rad)"});
  }
}

}  // namespace exotwin
