// The forward plant with effects against the inverse form (predict), the replay's sensor model, and
// the replay of a record the forward plant made (known ground truth: the same twin reproduces it).
#include "diagnosis/replay.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>

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
  std::vector<double> inner[2];  // internal hinge angle at each step's start (0 without one)
};

// `seconds` of the plant carrying p's effects driven by Drive, from rest at (0.2, -0.3).
// `slow` stretches the drive in time (2 = half its frequencies).
ForwardRun Simulate(const LegParams& p, double seconds, double slow = 1) {
  Plant plant(ExowheelMjcfPath(false));
  plant.SetParams(p);
  plant.CarryEffects(ToPlantEffects(p, "test"));
  plant.FreeJointsAndTorque();
  plant.Reset({0.2, -0.3}, {0, 0});
  ForwardRun r;
  const double dt = plant.timestep();
  const int n = static_cast<int>(std::lround(seconds / dt));
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d q = plant.q(), qd = plant.qd(), inner = plant.internal_q();
    const Eigen::Vector2d u = Drive((plant.time() + 0.5 * dt) / slow);
    r.kin.t.push_back(plant.time());
    plant.Step(u);
    for (int j = 0; j < 2; ++j) {
      r.kin.q[j].push_back(q[j]);
      r.kin.qd[j].push_back(qd[j]);
      r.kin.qdd[j].push_back((plant.qd()[j] - qd[j]) / dt);
      r.tau_R[j].push_back(u[j]);
      r.inner[j].push_back(inner[j]);
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

// The internal hinges (backlash, series compliance) against the inverse forms (diagnosis/effects.h),
// driven as above: the torque a forward run needed, fed back through predict with the same effect.
// The drive is stretched in time (quasi-static motions, as both inverse forms assume). Backlash:
// compared where the link rests on one flank from 50 ms before to 20 ms after and the
// rigid torque exceeds 3 kBacklashTorqueWidth (the tanh within 0.5 % of its flank);
// while the band is open the rotor crosses it freely and closes it with an impact, which the tanh
// form smooths over. Compliance: compared after 0.2 s (the strap's start-up transient, damped at half
// its critical value, has decayed); the quasi-static form neglects the deflection's rates (sim/
// plant_effects.h): the link's J times the deflection's acceleration, which the tolerance covers (at
// the hip the knee's share of it too).
TEST(PlantAgainstPredict, BacklashAndComplianceAgreeAwayFromTheReversal) {
  struct Case {
    Effect e;
    double tolerance;  // N m, RMS over the samples compared
    double felt;       // the rigid twin's RMS error at least this many times the tolerance's measure
    double slow;       // the drive stretched in time
  };
  // Measured (RMS forward vs inverse / rigid twin): backlash knee 3.6e-5 / 1.9e-2, hip 3.2e-5 / 6.5e-2
  // N m; compliance knee 3.8e-4 / 2.5e-3, hip 1.9e-3 / 6.0e-3 N m.
  const std::vector<Case> cases = {{MakeEffect("backlash", "knee", 0.04), 2e-4, 50, 4},
                                   {MakeEffect("backlash", "hip", 0.03), 2e-4, 50, 4},
                                   {MakeEffect("series_compliance", "knee", 100), 1e-3, 4, 8},
                                   {MakeEffect("series_compliance", "hip", 500), 3e-3, 2.5, 8}};
  for (const Case& c : cases) {
    LegParams p = RealRigModel();
    p.effects = {c.e};
    const ForwardRun r = Simulate(p, 4.0, c.slow);
    Plant inverse(ExowheelMjcfPath(false));
    inverse.SetParams(p);
    const Prediction pred = PredictTorque(inverse, r.kin);
    Plant rigid_plant(ExowheelMjcfPath(false));
    rigid_plant.SetParams(RealRigModel());
    const Prediction rigid = PredictTorque(rigid_plant, r.kin);
    const int j = EffectJoint(c.e);
    double sse = 0, sse_rigid = 0, worst = 0;
    size_t used = 0;
    const size_t n = r.kin.t.size();
    std::vector<int> flank(n);  // the link on a flank (within 0.1 mrad: the flank constraint's softness)
    for (size_t i = 0; i < n; ++i)
      flank[i] = std::abs(r.inner[j][i]) > 0.5 * c.e.value - 1e-4 ? (r.inner[j][i] > 0 ? 1 : -1) : 0;
    for (size_t i = 0; i < n; ++i) {
      if (r.kin.t[i] < 0.2) continue;
      if (c.e.name == "backlash") {
        bool steady = i >= 50 && i + 20 < n && flank[i] != 0;
        for (size_t k = i - std::min<size_t>(i, 50); steady && k <= std::min(n - 1, i + 20); ++k)
          steady = flank[k] == flank[i];
        // ... and the inverse form picks that flank (the link lags the motor against the torque: the
        // forward plant's rotor takes its own share J_r qdd, so at a strong acceleration against the
        // load the transmitted torque and the whole chain's can differ in sign).
        if (!steady || std::abs(rigid.tau_R[j][i]) < 3 * kBacklashTorqueWidth ||
            (rigid.tau_R[j][i] > 0) == (flank[i] > 0)) {
          continue;
        }
      }
      const double d = pred.tau_R[j][i] - r.tau_R[j][i];
      sse += d * d;
      sse_rigid += (rigid.tau_R[j][i] - r.tau_R[j][i]) * (rigid.tau_R[j][i] - r.tau_R[j][i]);
      worst = std::max(worst, std::abs(d));
      ++used;
    }
    const double rms = std::sqrt(sse / used), rms_rigid = std::sqrt(sse_rigid / used);
    std::printf("%s %s %g: %zu samples, forward vs inverse RMS %.2e N m (worst %.2e), rigid twin %.2e N m\n",
                c.e.name.c_str(), c.e.joint.c_str(), c.e.value, used, rms, worst, rms_rigid);
    EXPECT_GT(used, r.kin.t.size() / 5) << c.e.name;
    EXPECT_LT(rms, c.tolerance) << c.e.name << " " << c.e.joint;
    EXPECT_GT(rms_rigid, c.felt * rms) << c.e.name << " " << c.e.joint;  // the effect is felt
  }
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

Effect TermEffect(const char* joint, double value, const char* expr, const char* stage = "") {
  Effect e = MakeEffect("term", joint, value);
  e.expr = expr, e.stage = stage;
  return e;
}

// Sensor-stage terms inverted with the other sensor effects (fixed point on tau_R): a load-dependent
// reading error, one reading the motion, after a gain; a term whose iteration cannot contract
// (|value d expr / d tau_R| >= 1) is refused.
TEST(ReplaySensor, InvertsSensorTerms) {
  LegParams p = RealRigModel();
  p.effects = {MakeEffect("sensor_gain", "hip", 0.05), TermEffect("hip", -0.02, "tau_R * abs(tau_R)", "sensor"),
               TermEffect("knee", 0.3, "sin(q) * tau_R + t", "sensor"), MakeEffect("sensor_offset", "knee", 0.1)};
  ReplaySeries motion;
  Kinematics kin;
  std::vector<double> tau_R[2], tau_S[2];
  for (int i = 0; i < 2000; ++i) {
    const double t = 1e-3 * i;
    kin.t.push_back(t);
    for (int j = 0; j < 2; ++j) {
      kin.q[j].push_back(0.4 * std::sin(1.3 * t + j)), kin.qd[j].push_back(0), kin.qdd[j].push_back(0);
      motion.q[j].push_back(kin.q[j].back());
    }
    tau_R[0].push_back(Drive(t)[0]);
    tau_R[1].push_back(Drive(t)[1]);
  }
  motion.t = kin.t;
  std::vector<double> applied[2] = {tau_R[0], tau_R[1]};
  ApplyEffects(p, kin, tau_R, tau_S);
  std::vector<double> back[2];
  ActuatorTorqueFromReading(ToPlantEffects(p, "test"), kin.t, tau_S, back, &motion);
  for (int j = 0; j < 2; ++j)
    for (size_t i = 0; i < kin.t.size(); ++i) ASSERT_NEAR(back[j][i], applied[j][i], 1e-9) << j << " " << i;
  // The motion is needed where a term reads it.
  EXPECT_THROW(ActuatorTorqueFromReading(ToPlantEffects(p, "test"), kin.t, tau_S, back), InputError);
  p.effects = {TermEffect("knee", 2.0, "tau_R", "sensor")};
  try {
    ActuatorTorqueFromReading(ToPlantEffects(p, "test"), kin.t, tau_S, back);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not invertible"), std::string::npos) << e.what();
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
  // A part [begin, end) keeps its own samples only (first = begin); by index outside it: NaN, -1.
  const size_t begin = s.t.size() / 3;
  const ReplayRecord part = Replay(twin, s, 0.5, begin, s.t.size());
  EXPECT_EQ(part.first, begin);
  ASSERT_EQ(part.window.size(), s.t.size() - begin);
  EXPECT_TRUE(std::isnan(part.Sim(0, begin - 1)));
  EXPECT_EQ(part.Window(begin - 1), -1);
  EXPECT_EQ(part.Window(begin), -1);  // a window's restart sample is not scored
  EXPECT_EQ(part.Window(begin + 1), 0);
  EXPECT_EQ(part.Sim(1, begin + 1), part.sim[1][1]);
  EXPECT_TRUE(std::isnan(part.Sim(1, s.t.size())));
  // Another input given beside the series: the replay of a series holding that input, bit for bit.
  std::vector<double> other_input[2];
  ReplaySeries s2 = s;
  for (int j = 0; j < 2; ++j) {
    other_input[j] = s.tau_R[j];
    for (double& v : other_input[j]) v = 0.9 * v + 0.05;
    s2.tau_R[j] = other_input[j];
  }
  const ReplayRecord given = Replay(twin, s, 0.5, 0, s.t.size(), other_input);
  const ReplayRecord held = Replay(twin, s2, 0.5);
  EXPECT_EQ(given.score.sse[0], held.score.sse[0]);
  EXPECT_EQ(given.score.sse[1], held.score.sse[1]);
  EXPECT_NE(given.score.sse[1], same.score.sse[1]);
  // A horizon longer than the part replayed is an input error.
  EXPECT_THROW(Replay(twin, s, 5.0), InputError);
  EXPECT_THROW(Replay(twin, s, 0.0), InputError);
}

// The series of the twin's own record r: its exact angles, each torque held over its step as the
// twin's joint modules log it (the restart state is the caller's).
ReplaySeries ExactRecord(const ForwardRun& r) {
  ReplaySeries s;
  s.source = "sim";
  s.t = r.kin.t;
  for (int j = 0; j < 2; ++j) {
    s.q[j] = r.kin.q[j];
    s.tau_R[j] = r.tau_R[j];
  }
  s.hold = true;
  return s;
}

// The shipped two-link plant with p, its joints and torque free (as replay's).
std::unique_ptr<Plant> FreeTwin(const LegParams& p) {
  auto twin = std::make_unique<Plant>(ExowheelMjcfPath(false));
  twin->SetParams(p);
  twin->FreeJointsAndTorque();
  return twin;
}

// The restart velocity handed to the integrator is half a step behind the derived one (replay.h):
// semi-implicit Euler's velocity state is the mean over the step before. The twin's own record (the
// real rig's double pendulum swung by sums of sines, each torque held over its step as the twin's
// joint modules log it), its angles exact and derived at a cutoff far above the motion's (200 Hz: the
// filter leaves the motion as it is). Against the plant's own velocity state at every sample: the
// derived velocity runs dt/2 qdd ahead of it, the half step behind matches it to O(dt^2). Replayed,
// the twin follows its own record several times closer restarted half a step behind (the residue:
// the pendulum's sensitivity to the O(dt^2) rest over a window).
TEST(Replay, TheRestartVelocityIsTheIntegratorsHalfStepBehind) {
  const LegParams p = RealRigModel();
  const ForwardRun r = Simulate(p, 3.0);
  ReplaySeries s = ExactRecord(r);
  SetRestartState(200, &s);
  const std::unique_ptr<Plant> free_twin = FreeTwin(p);
  Plant& twin = *free_twin;
  const double dt = twin.timestep();
  for (int j = 0; j < 2; ++j) {
    double ahead = 0, behind = 0;
    for (size_t i = 10; i + 10 < s.t.size(); ++i) {  // away from the filter's edges
      ahead += std::pow(s.qd0[j][i] - r.kin.qd[j][i], 2);
      behind += std::pow(s.qd0[j][i] - 0.5 * dt * s.qdd0[j][i] - r.kin.qd[j][i], 2);
    }
    std::printf("joint %d: velocity error %.3g rad/s derived, %.3g rad/s half a step behind (RMS)\n", j,
                std::sqrt(ahead / s.t.size()), std::sqrt(behind / s.t.size()));
    EXPECT_LT(behind, 1e-3 * ahead);
  }
  const ReplayRecord half_step = Replay(twin, s, 0.5);
  ReplaySeries derived_series = s;
  for (auto& a : derived_series.qdd0) a.clear();  // no acceleration: the derived velocity itself
  const ReplayRecord derived = Replay(twin, derived_series, 0.5);
  for (int j = 0; j < 2; ++j) {
    std::printf("joint %d: RMS angle error %.3g rad restarted half a step behind, %.3g rad at the derived velocity\n",
                j, half_step.score.Rmse(j), derived.score.Rmse(j));
    EXPECT_LT(half_step.score.Rmse(j), 0.25 * derived.score.Rmse(j));
  }
  EXPECT_THROW(SetRestartState(600, &s), InputError);  // not below half the sample rate
}

// The restart angle is the measured one (replay.h): low-passed at the velocity's cutoff it is biased
// wherever the motion has content near the cutoff, and that bias is held over the whole window. The
// same exact record of the twin swung by sums of sines, its restart velocity derived at the default
// 10 Hz: restarted from the measured angle it follows its record closer than from that angle
// low-passed at 10 Hz (zero-phase, as the velocity's filter).
TEST(Replay, TheRestartAngleIsTheMeasuredOne) {
  const LegParams p = RealRigModel();
  ReplaySeries s = ExactRecord(Simulate(p, 3.0));
  SetRestartState(kReplayCutoffHz, &s);
  for (int j = 0; j < 2; ++j) EXPECT_EQ(s.RestartAngle(j), s.q[j]);
  const std::unique_ptr<Plant> free_twin = FreeTwin(p);
  Plant& twin = *free_twin;
  const ReplayRecord measured = Replay(twin, s, 0.5);
  ReplaySeries filtered = s;
  for (int j = 0; j < 2; ++j) filtered.q0[j] = LowPassOnTimeBase(s.t, s.q[j], kReplayCutoffHz, s.source);
  const ReplayRecord low_passed = Replay(twin, filtered, 0.5);
  for (int j = 0; j < 2; ++j) {
    std::printf("joint %d: RMS angle error %.3g rad from the measured angle, %.3g rad from it low-passed at 10 Hz\n", j,
                measured.score.Rmse(j), low_passed.score.Rmse(j));
    EXPECT_LT(measured.score.Rmse(j), low_passed.score.Rmse(j));
  }
}

// Each window restarts from the series' restart state, so the windows shared between two plants alike
// (ReplayOnTwoPlants, the motion fit's serial rollouts) give the one plant's record bit for bit: angles,
// windows and score, on a whole series and on a part, with a dead band and a strap's run-in (a
// window's start state from samples before it) among the effects.
TEST(Replay, TwoPlantsAlikeGiveTheOnePlantsRecordBitForBit) {
  LegParams p = RealRigModel();
  p.effects = LinkEffects();
  p.effects.push_back(MakeEffect("backlash", "knee", 0.01));
  p.effects.push_back(MakeEffect("series_compliance", "hip", 3000));
  ReplaySeries s = ExactRecord(Simulate(p, 3.0));
  SetRestartState(kReplayCutoffHz, &s);
  const std::unique_ptr<Plant> one = MakeReplayPlant(p, "test");
  ASSERT_GT(one->InternalSettlingTime(), 0.0);
  std::unique_ptr<Plant> other;
  int built = 0;
  const std::function<Plant&()> second = [&]() -> Plant& {
    if (!other) {
      other = MakeReplayPlant(p, "test");
      ++built;
    }
    return *other;
  };
  for (const size_t begin : {size_t{0}, s.t.size() / 3}) {
    const ReplayRecord a = Replay(*one, s, 0.5, begin);
    const ReplayRecord b = ReplayOnTwoPlants(*one, second, s, 0.5, begin);
    ASSERT_GE(a.score.windows, 3u);
    EXPECT_EQ(b.score.windows, a.score.windows);
    EXPECT_EQ(b.score.count, a.score.count);
    EXPECT_EQ(b.score.sse[0], a.score.sse[0]);
    EXPECT_EQ(b.score.sse[1], a.score.sse[1]);
    EXPECT_EQ(b.window, a.window);
    for (int j = 0; j < 2; ++j) {
      ASSERT_EQ(b.sim[j].size(), a.sim[j].size());
      for (size_t k = 0; k < a.sim[j].size(); ++k) {
        if (std::isnan(a.sim[j][k]) && std::isnan(b.sim[j][k])) continue;
        ASSERT_EQ(b.sim[j][k], a.sim[j][k]) << j << " " << k;
      }
    }
    EXPECT_LT(a.score.Rmse(1), 0.02);  // the truth twin follows its record: the comparison is of real replays
  }
  EXPECT_EQ(built, 1);
}

// ReplayTwoTwins (diagnose's rigid and extended twins side by side, the one done first taking the
// other's last windows on a second plant alike) gives each twin's Replay record bit for bit: a rigid
// twin and one with a dead band and a strap (a run-in), the second on its own input, on one thread
// and on two, on a part of the series.
TEST(Replay, TwoTwinsSharingTheirWindowsGiveEachOnesRecordBitForBit) {
  LegParams rigid_params = RealRigModel();
  LegParams p = rigid_params;
  p.effects = LinkEffects();
  p.effects.push_back(MakeEffect("backlash", "knee", 0.01));
  p.effects.push_back(MakeEffect("series_compliance", "hip", 3000));
  ReplaySeries s = ExactRecord(Simulate(p, 4.0));
  SetRestartState(kReplayCutoffHz, &s);
  std::vector<double> other_input[2] = {s.tau_R[0], s.tau_R[1]};
  for (double& v : other_input[0]) v *= 1.05;  // an input of its own (another twin's sensor effects)
  const std::unique_ptr<Plant> rigid = MakeReplayPlant(rigid_params, "test"), ext = MakeReplayPlant(p, "test");
  const size_t begin = s.t.size() / 4;
  const ReplayRecord ref[2] = {Replay(*rigid, s, 0.5, begin), Replay(*ext, s, 0.5, begin, static_cast<size_t>(-1), other_input)};
  ASSERT_GE(ref[0].score.windows, 4u);
  for (int threads : {1, 2}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    std::unique_ptr<Plant> second[2];
    const LegParams* model[2] = {&rigid_params, &p};
    auto Second = [&](int k) {
      return [&, k]() -> Plant& {
        if (!second[k]) second[k] = MakeReplayPlant(*model[k], "test");
        return *second[k];
      };
    };
    const ReplayTwin twins[2] = {{rigid.get(), Second(0), nullptr}, {ext.get(), Second(1), other_input}};
    const std::array<ReplayRecord, 2> got = ReplayTwoTwins(twins, s, 0.5, threads, begin);
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(got[k].score.windows, ref[k].score.windows);
      EXPECT_EQ(got[k].score.count, ref[k].score.count);
      EXPECT_EQ(got[k].score.sse[0], ref[k].score.sse[0]);
      EXPECT_EQ(got[k].score.sse[1], ref[k].score.sse[1]);
      EXPECT_EQ(got[k].window, ref[k].window);
      for (int j = 0; j < 2; ++j) {
        ASSERT_EQ(got[k].sim[j].size(), ref[k].sim[j].size());
        for (size_t i = 0; i < ref[k].sim[j].size(); ++i) {
          if (std::isnan(ref[k].sim[j][i]) && std::isnan(got[k].sim[j][i])) continue;
          ASSERT_EQ(got[k].sim[j][i], ref[k].sim[j][i]) << k << " " << j << " " << i;
        }
      }
    }
    if (threads == 1) {
      EXPECT_TRUE(!second[0] && !second[1]);  // one after the other: no second plant
    }
  }
}

// The quiet windows' schedule (replay.h "windows") on a series whose fast content is given: knocks
// (fast above the quiet level) over [1.00, 1.10] s and [2.40, 2.45] s of a 4 s series at 1 kHz,
// horizon 0.5 s. Expected by the rule (a span is the restart sample and the first sample not scored):
// 0 -> 0.5; 0.5 stops before the knock at 1.0; the one due at 1.0 (in the knock) restarts at the
// least fast sample of [1.0, 1.25] s, 1.2 s (set lowest there), and runs to 1.7; 1.7 -> 2.2; 2.2
// stops before the knock at 2.4; 2.7 -> 3.2; 3.2 -> 3.7; the one due at 3.7 would end after the
// series' last sample (3.999). Without quiet_windows: the every-horizon windows 0, 0.5, ..., 3.0.
TEST(Replay, QuietWindowsRestartAfterAKnockAndStopBeforeOne) {
  ReplaySeries s;
  s.source = "synthetic";
  for (int i = 0; i < 4000; ++i) s.t.push_back(0.001 * i);
  s.fast.assign(s.t.size(), 0.01);
  s.quiet_level = 0.1;
  for (int i = 1000; i <= 1100; ++i) s.fast[static_cast<size_t>(i)] = 1.0;
  for (int i = 1101; i < 1200; ++i) s.fast[static_cast<size_t>(i)] = 0.05;  // quiet, not the least fast
  s.fast[1200] = 0.001;
  for (int i = 2400; i <= 2450; ++i) s.fast[static_cast<size_t>(i)] = 2.0;
  auto Spans = [&](bool quiet) {
    s.quiet_windows = quiet;
    std::vector<std::pair<size_t, size_t>> out;
    for (const ReplayWindowSpan& w : ReplayWindows(s, 0.5, 0, s.t.size())) out.emplace_back(w.start, w.stop);
    return out;
  };
  const std::vector<std::pair<size_t, size_t>> quiet = {{0, 501},     {500, 1000},  {1200, 1701}, {1700, 2201},
                                                        {2200, 2400}, {2700, 3201}, {3200, 3701}};
  EXPECT_EQ(Spans(true), quiet);
  std::vector<std::pair<size_t, size_t>> every;
  for (size_t k = 0; k < 7; ++k) every.emplace_back(500 * k, 500 * k + 501);
  EXPECT_EQ(Spans(false), every);
  // A window that the knock leaves shorter than kReplayQuietShortest is not scored: a knock at 0.05 s.
  for (int i = 50; i <= 60; ++i) s.fast[static_cast<size_t>(i)] = 1.0;
  EXPECT_EQ(Spans(true).front(), (std::pair<size_t, size_t>{500, 1000}));
}

// The fast content SetRestartState derives: the angle's central difference less the restart velocity,
// summed over the joints, at most within kReplayQuietSpan either side. A ramp (the filter follows it:
// no fast content) with a step of 1 mrad at 1.0 s in the knee: the central differences at 0.999 and
// 1.000 s read 1e-3 / 2e-3 s = 0.5 rad/s above the ramp, which the 10 Hz velocity barely sees, so the
// fast content is ~0.5 rad/s from 0.979 to 1.020 s and ~0 outside; the quiet level is 10 x the ~0 floor.
TEST(Replay, TheFastContentIsWhatTheRestartVelocityMisses) {
  ReplaySeries s;
  s.source = "synthetic";
  for (int i = 0; i < 2000; ++i) {
    const double t = 0.001 * i;
    s.t.push_back(t);
    s.q[0].push_back(0.3 * t);
    s.q[1].push_back(-0.2 * t + (i >= 1000 ? 1e-3 : 0.0));
  }
  SetRestartState(kReplayCutoffHz, &s);
  ASSERT_EQ(s.fast.size(), s.t.size());
  EXPECT_NEAR(s.fast[990], 0.5, 0.05);
  EXPECT_NEAR(s.fast[1019], 0.5, 0.05);
  EXPECT_NEAR(s.fast[979], 0.5, 0.05);
  EXPECT_LT(s.fast[1100], 0.05);  // the filter's own bias 0.1 s after the step
  EXPECT_LT(s.fast[500], 1e-6);
  EXPECT_LT(s.quiet_level, 1e-5);
  EXPECT_GT(s.quiet_level, 0.0);
}

// Why the motion fit's windows are quiet: the real rig's twin with a 0.03 rad hip dead band, driven
// by sums of sines, replays its own exact 12 s record. Every 0.5 s, windows restart or run through
// knocks (the link crossing the gap, faster than the restart velocity at 10 Hz follows) and the truth
// twin misses its own motion there (measured: 8.1 deg RMS, 17.9 in the worst window); the quiet
// windows (7 of 23 windows' time, the rest of this open-loop swing knocks) 0.43 deg, 0.81 in the
// worst, where the rigid twin misses by 0.69 deg. Bounds: a tenth of the every-horizon errors, and
// the rigid twin 1.3 x the truth twin's.
TEST(Replay, QuietWindowsLetADeadBandsTruthTwinFollowItsOwnRecord) {
  LegParams p = RealRigModel();
  p.effects.push_back(MakeEffect("backlash", "hip", 0.03));
  ReplaySeries s = ExactRecord(Simulate(p, 12.0));
  SetRestartState(kReplayCutoffHz, &s);
  const std::unique_ptr<Plant> twin = MakeReplayPlant(p, "test");
  const std::unique_ptr<Plant> rigid = MakeReplayPlant(RealRigModel(), "test");
  auto WorstWindow = [&](const ReplayRecord& r) {
    std::vector<double> sse(r.score.windows, 0.0), n(r.score.windows, 0.0);
    for (size_t i = 0; i < s.t.size(); ++i) {
      const int w = r.Window(i);
      if (w < 0) continue;
      const double e = r.Sim(0, i) - s.q[0][i];
      sse[static_cast<size_t>(w)] += e * e, n[static_cast<size_t>(w)] += 1;
    }
    double worst = 0;
    for (size_t w = 0; w < sse.size(); ++w) worst = std::max(worst, std::sqrt(sse[w] / n[w]));
    return worst;
  };
  const ReplayRecord every = Replay(*twin, s, 0.5);
  s.quiet_windows = true;
  const ReplayRecord quiet = Replay(*twin, s, 0.5), quiet_rigid = Replay(*rigid, s, 0.5);
  const double deg = 180 / M_PI;
  std::printf("hip, truth twin: every 0.5 s %.3f deg (worst window %.3f) in %zu windows; quiet %.3f deg (worst %.3f) "
              "in %zu windows, %zu of %zu samples; rigid twin, quiet %.3f deg\n",
              every.score.Rmse(0) * deg, WorstWindow(every) * deg, every.score.windows, quiet.score.Rmse(0) * deg,
              WorstWindow(quiet) * deg, quiet.score.windows, quiet.score.count, every.score.count,
              quiet_rigid.score.Rmse(0) * deg);
  EXPECT_LT(quiet.score.Rmse(0), 0.1 * every.score.Rmse(0));
  EXPECT_LT(WorstWindow(quiet), 0.1 * WorstWindow(every));
  EXPECT_GT(quiet_rigid.score.Rmse(0), 1.3 * quiet.score.Rmse(0));
  EXPECT_EQ(quiet_rigid.window, quiet.window);  // the schedule is the series', whichever twin replays it
  for (size_t i = 0; i < s.t.size(); ++i) {
    if (quiet.Window(i) < 0) continue;
    ASSERT_LE(s.fast[i], s.quiet_level) << "a scored sample in a knock, t = " << s.t[i];
  }
}

// A one-joint record (the HAL-3 knee twin, examples/hal3_knee.yaml, a hidden Coulomb friction of
// 1.20 N m drawn by `generate` seed 1, 10 s at 500 Hz) replayed through the embedding's plant with
// the hip held (MakeReplayPlant): the truth twin follows the record (measured 0.30 deg, the restart
// velocity's filter and the sensor noise), the rigid HAL-3 model does not (3.15 deg). The hip is no data:
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

// A term "sgn(qd)" is carried as coulomb_friction is (the same frictionloss each step): replaying a
// record the Coulomb twin made, the two twins give the same angles.
TEST(Replay, ATermSgnReplaysAsCoulombFriction) {
  LegParams coulomb = RealRigModel(), term = RealRigModel();
  coulomb.effects = {MakeEffect("coulomb_friction", "knee", 0.145), MakeEffect("coulomb_friction", "hip", 0.13)};
  term.effects = {TermEffect("knee", 0.145, "1.0 * sgn(qd)"), TermEffect("hip", 0.13, "sgn(qd)")};
  const ForwardRun r = Simulate(coulomb, 2.0);
  ReplaySeries s = ExactRecord(r);
  for (int j = 0; j < 2; ++j) s.q0[j] = r.kin.q[j], s.qd0[j] = r.kin.qd[j];
  const ReplayRecord a = Replay(*MakeReplayPlant(coulomb, "coulomb", ""), s, 0.5);
  const ReplayRecord b = Replay(*MakeReplayPlant(term, "term", ""), s, 0.5);
  ASSERT_EQ(a.score.windows, b.score.windows);
  for (int j = 0; j < 2; ++j)
    for (size_t i = 0; i < a.sim[j].size(); ++i)
      if (!std::isnan(a.sim[j][i])) ASSERT_NEAR(b.sim[j][i], a.sim[j][i], 1e-12) << j << " " << i;
  EXPECT_LT(a.score.Rmse(1), 1e-3);  // the twin that made it
}

}  // namespace
}  // namespace exotwin
