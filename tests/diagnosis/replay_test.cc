// The forward plant with effects against the inverse form (predict), the replay's sensor model, and
// the replay of a record the forward plant made (known ground truth: the same twin reproduces it).
#include "diagnosis/replay.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "tests/real_rig_model.h"
#include "diagnosis/effects.h"
#include "diagnosis/generate.h"
#include "formats/model_file.h"
#include "diagnosis/predict.h"

namespace exotwin {
namespace {

// Every link effect the plant carries at once.
std::vector<Effect> LinkEffects() {
  Effect stiff = MakeEffect("joint_stiffness", "hip", 0.3);
  stiff.fields["q0"] = 0.2;
  Effect grav = MakeEffect("gravity_error", "knee", 0.01);
  grav.axis = "X";
  Effect ripple = MakeEffect("torque_ripple", "knee", 0.03);
  ripple.fields["cycles_per_rad"] = 2.0;
  ripple.fields["phase"] = 0.5;
  return {MakeEffect("coulomb_friction", "hip", 0.13), MakeEffect("coulomb_friction", "knee", 0.145),
          MakeEffect("viscous_friction", "hip", 0.01), MakeEffect("viscous_friction", "knee", 0.002),
          MakeEffect("inertia_error", "hip", 0.003),   MakeEffect("inertia_error", "knee", 0.0031),
          stiff, grav, ripple};
}

// The actuator torque of the exciting trajectory: sums of sines (N m), evaluated mid-step.
Eigen::Vector2d Drive(double t) {
  return {0.9 * std::sin(2 * M_PI * 0.7 * t) + 0.4 * std::sin(2 * M_PI * 1.9 * t + 1.0),
          0.35 * std::sin(2 * M_PI * 1.1 * t + 0.3) + 0.15 * std::sin(2 * M_PI * 2.7 * t)};
}

struct ForwardRun {
  Kinematics kin;                // q, qd at each step's start, qdd the step's velocity change / dt
  std::vector<double> tau_R[2];  // the torque applied over the step
};

// `seconds` of the plant carrying p's effects driven by Drive, from rest at (0.2, -0.3).
ForwardRun Simulate(const LegParams& p, double seconds) {
  Plant plant(ExowheelMjcfPath(false));
  plant.SetParams(p);
  plant.CarryEffects(ToPlantEffects(p, "test"));
  plant.FreeJointsAndTorque();
  plant.Reset({0.2, -0.3}, {0, 0});
  ForwardRun r;
  const double dt = plant.timestep();
  const int n = static_cast<int>(std::lround(seconds / dt));
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d q = plant.q(), qd = plant.qd();
    const Eigen::Vector2d u = Drive(plant.time() + 0.5 * dt);
    r.kin.t.push_back(plant.time());
    plant.Step(u);
    for (int j = 0; j < 2; ++j) {
      r.kin.q[j].push_back(q[j]);
      r.kin.qd[j].push_back(qd[j]);
      r.kin.qdd[j].push_back((plant.qd()[j] - qd[j]) / dt);
      r.tau_R[j].push_back(u[j]);
    }
  }
  return r;
}

// Forward and inverse are one model: the torque a forward run needed, fed back through predict with
// the same effects on the simulated kinematics, matches it away from zero velocity (|qd| > 0.1
// rad/s at that joint: near rest frictionloss holds the joint or steers it to rest, where the
// table's sign(qd) is not defined; sim/plant_effects.h). Tolerance 2e-3 N m: MuJoCo's Euler
// integrates damping implicitly (M qdd + b qd_next), b dt qdd < 1e-3 N m here; the frictionloss
// constraint saturates exactly while sliding.
TEST(PlantAgainstPredict, TheTorqueAForwardRunNeededIsWhatPredictGives) {
  LegParams p = RealRigModel();
  p.effects = LinkEffects();
  const ForwardRun r = Simulate(p, 4.0);
  Plant inverse(ExowheelMjcfPath(false));
  inverse.SetParams(p);
  const Prediction pred = PredictTorque(inverse, r.kin);
  double worst[2] = {0, 0};
  size_t used[2] = {0, 0};
  for (int j = 0; j < 2; ++j)
    for (size_t i = 0; i < r.kin.t.size(); ++i) {
      if (std::abs(r.kin.qd[j][i]) < 0.1) continue;
      worst[j] = std::max(worst[j], std::abs(pred.tau_R[j][i] - r.tau_R[j][i]));
      ++used[j];
    }
  for (int j = 0; j < 2; ++j) {
    EXPECT_GT(used[j], r.kin.t.size() / 2) << j;
    EXPECT_LT(worst[j], 2e-3) << "joint " << j;
  }
  // And the rigid twin does not explain the run: the effects are felt.
  LegParams rigid = RealRigModel();
  Plant rigid_plant(ExowheelMjcfPath(false));
  rigid_plant.SetParams(rigid);
  const Prediction rp = PredictTorque(rigid_plant, r.kin);
  EXPECT_GT(Rmse(rp.tau_R[1], r.tau_R[1]), 0.1);
}

TEST(ReplaySensor, InvertsOffsetGainAndDelayOfTheReading) {
  LegParams p = RealRigModel();
  p.effects = {MakeEffect("sensor_offset", "hip", 0.2), MakeEffect("sensor_gain", "hip", 0.05), MakeEffect("sensor_delay", "knee", 0.004)};
  Kinematics kin;
  std::vector<double> tau_R[2], tau_S[2];
  for (int i = 0; i < 2000; ++i) {
    const double t = 1e-3 * i;
    kin.t.push_back(t);
    for (int j = 0; j < 2; ++j) kin.q[j].push_back(0), kin.qd[j].push_back(0), kin.qdd[j].push_back(0);
    tau_R[0].push_back(Drive(t)[0]);
    tau_R[1].push_back(Drive(t)[1]);
  }
  std::vector<double> applied[2] = {tau_R[0], tau_R[1]};
  ApplyEffects(p, kin, tau_R, tau_S);  // the reading the sensor effects make (diagnosis/effects.h)
  std::vector<double> back[2];
  ActuatorTorqueFromReading(ToPlantEffects(p, "test"), kin.t, tau_S, back);
  for (size_t i = 0; i + 5 < kin.t.size(); ++i) {  // the delay's last 4 ms are held
    EXPECT_NEAR(back[0][i], applied[0][i], 1e-12);
    if (i > 4) {
      EXPECT_NEAR(back[1][i], applied[1][i], 1e-12);  // whole-ms delay: exact samples
    }
  }
}

// A record the forward plant made, replayed by the same twin from its exact state: the simulated
// angles are the record's (the input is interpolated mid-step, as the record's was applied: error
// O(dt^2 u'') per step); the rigid twin drifts away from it.
TEST(Replay, TheTwinThatMadeARecordReplaysIt) {
  LegParams p = RealRigModel();
  p.effects = LinkEffects();
  const ForwardRun r = Simulate(p, 3.0);
  ReplaySeries s;
  s.source = "sim";
  s.t = r.kin.t;
  for (int j = 0; j < 2; ++j) {
    s.q[j] = s.q0[j] = r.kin.q[j];
    s.qd0[j] = r.kin.qd[j];
    s.tau_R[j].resize(s.t.size());
    for (size_t i = 0; i < s.t.size(); ++i) s.tau_R[j][i] = Drive(s.t[i])[j];  // sampled at the record's times
  }
  Plant twin(ExowheelMjcfPath(false));
  twin.SetParams(p);
  twin.CarryEffects(ToPlantEffects(p, "test"));
  twin.FreeJointsAndTorque();
  const ReplayRecord same = Replay(twin, s, 0.5);
  EXPECT_EQ(same.score.windows, 5u);  // 3 s minus the last sample: five whole windows
  EXPECT_LT(same.score.Rmse(0), 1e-3);
  EXPECT_LT(same.score.Rmse(1), 1e-3);
  Plant rigid(ExowheelMjcfPath(false));
  rigid.SetParams(RealRigModel());
  rigid.FreeJointsAndTorque();
  const ReplayRecord other = Replay(rigid, s, 0.5);
  EXPECT_GT(other.score.Rmse(1), 20 * same.score.Rmse(1));
  // A horizon longer than the part replayed is an input error.
  EXPECT_THROW(Replay(twin, s, 5.0), InputError);
  EXPECT_THROW(Replay(twin, s, 0.0), InputError);
}

// A one-joint record (the HAL-3 knee twin, examples/hal3_knee.yaml, a hidden Coulomb friction of
// 1.20 N m drawn by `generate` seed 1, 10 s at 500 Hz) replayed through the embedding's plant with
// the hip held (MakeReplayPlant): the truth twin follows the record (measured 0.30 deg, the restart
// state's filter and the sensor noise), the rigid HAL-3 model does not (3.17 deg). The hip is no data:
// its simulated angle is the held 0 of the record's embedded column.
TEST(Replay, AOneJointRecordIsReplayedByItsTruthTwin) {
  const LegParams base = ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/hal3_knee.yaml");
  GenerateOptions g;
  g.seed = 1;
  g.effects = 1;
  g.allowed = {"coulomb_friction"};
  g.duration = 10;
  g.rate = 500;
  const GeneratedData rec = GenerateMeasured(base, g);
  ASSERT_TRUE(rec.data.one_joint);
  ASSERT_EQ(rec.truth.effects.back().name, "coulomb_friction");
  EXPECT_NEAR(rec.truth.effects.back().value, 1.1988, 1e-3);
  auto Run = [&](const LegParams& p) {
    PlantEffects fx;
    const std::unique_ptr<Plant> plant = MakeReplayPlant(p, "test", "", &fx);
    EXPECT_TRUE(plant->hip_held());
    return Replay(*plant, ReplaySeriesOf(rec.data, fx, ReplayInput::kTorque, kReplayCutoffHz), 0.5);
  };
  const ReplayRecord rigid = Run(base), truth = Run(rec.truth);
  std::printf("knee: rigid %.3f deg, truth %.3f deg\n", rigid.score.Rmse(1) * 180 / M_PI, truth.score.Rmse(1) * 180 / M_PI);
  EXPECT_EQ(truth.score.windows, 20u);  // t = 0 .. 10 s inclusive
  EXPECT_EQ(truth.score.Rmse(0), 0.0);
  EXPECT_LT(truth.score.Rmse(1), 0.01);           // rad
  EXPECT_LT(truth.score.Rmse(1), 0.25 * rigid.score.Rmse(1));
}

}  // namespace
}  // namespace exotwin
