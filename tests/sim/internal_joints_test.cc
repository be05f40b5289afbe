// Backlash and series compliance in the forward plant (sim/internal_joints.h, Plant::CarryEffects):
// the edited MJCF's structure; with the internal hinge at rest the plant is the rigid one (the
// rotor's inertia is taken out of the segment, checked against MuJoCo's own rigid model); at rest the
// strap's deflection is the quasi-static closed form (HJ15 eq. 7 gravity over k) and the dead band's
// link rests on the flank the load presses it against.
#include "sim/internal_joints.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.h"
#include "model/leg_dynamics.h"
#include "sim/mjcf_text.h"
#include "sim/plant.h"
#include "sim/subjects.h"
#include "tests/real_rig_model.h"

namespace exotwin {
namespace {

LegParams S1() { return SubjectLegParams(PresetSubject("S1")); }

std::unique_ptr<Plant> Carrying(const LegParams& p) {
  auto plant = std::make_unique<Plant>(ExowheelMjcfPath(p.human.has_value()));
  plant->SetParams(p);
  plant->CarryEffects(ToPlantEffects(p, "test"));
  return plant;
}

TEST(InternalJoints, TheEditedModelHasTheHingesWhereTheEffectsSay) {
  PlantEffects fx;
  fx.backlash[0] = 0.02;
  fx.compliance[1] = 300;
  fx.compliant_human = true;
  const InternalJoints s = InternalJointsOf(fx);
  EXPECT_EQ(s.kind[0], InternalHinge::kRotor);
  EXPECT_EQ(s.kind[1], InternalHinge::kHuman);
  const std::string path = ExowheelMjcfPath(true);
  mjModel* m = LoadMjcfText(path, AddInternalJoints(ReadMjcfText(path), path, s), "test");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->nq, 4);
  const int rotor = mj_name2id(m, mjOBJ_BODY, "hip_rotor");
  const int hip = mj_name2id(m, mjOBJ_JOINT, "hip"), dead = mj_name2id(m, mjOBJ_JOINT, "hip_backlash");
  const int strap = mj_name2id(m, mjOBJ_JOINT, "knee_compliance");
  ASSERT_GE(rotor, 0);
  ASSERT_GE(dead, 0);
  ASSERT_GE(strap, 0);
  EXPECT_EQ(m->jnt_bodyid[hip], rotor);                                          // the rotor is driven
  EXPECT_EQ(m->body_parentid[mj_name2id(m, mjOBJ_BODY, "exo_thigh")], rotor);    // the chain behind it
  EXPECT_EQ(m->jnt_bodyid[dead], mj_name2id(m, mjOBJ_BODY, "exo_thigh"));
  EXPECT_TRUE(m->jnt_limited[dead]);
  EXPECT_EQ(m->jnt_bodyid[strap], mj_name2id(m, mjOBJ_BODY, "human_shank"));     // the human follows
  mj_deleteModel(m);
  EXPECT_THROW(AddInternalJoints("<mujoco><worldbody/></mujoco>", "x.xml", s), InputError);
}

// With its internal hinge held at 0 the plant's inverse dynamics are the rigid plant's (the rotor's
// inertia and mass come out of the exoskeleton's lumped J1, J2, X1), for each structure.
TEST(InternalJoints, HeldAtRestThePlantIsTheRigidOne) {
  const Eigen::Vector2d q(0.4, -0.9), qd(1.2, -0.7), qdd(-3.0, 5.0);
  struct Case {
    LegParams p;
    std::vector<Effect> fx;
  };
  const std::vector<Case> cases = {
      {RealRigModel(), {MakeEffect("backlash", "hip", 0.03), MakeEffect("backlash", "knee", 0.02)}},
      {RealRigModel(), {MakeEffect("series_compliance", "knee", 40), MakeEffect("series_compliance", "hip", 80)}},
      {S1(), {MakeEffect("backlash", "knee", 0.03)}},
      {S1(), {MakeEffect("series_compliance", "knee", 400), MakeEffect("backlash", "hip", 0.02)}}};
  for (const Case& c : cases) {
    Plant rigid(ExowheelMjcfPath(c.p.human.has_value()));
    rigid.SetParams(c.p);
    LegParams p = c.p;
    p.effects = c.fx;
    auto plant = Carrying(p);
    EXPECT_TRUE(plant->internal_joints().any());
    const Eigen::Vector2d a = plant->InverseDynamics(q, qd, qdd), b = rigid.InverseDynamics(q, qd, qdd);
    EXPECT_LT((a - b).norm(), 1e-9 * (1 + b.norm())) << c.fx[0].name << ": " << a.transpose() << " vs " << b.transpose();
    EXPECT_GT(plant->rotor_inertia(0) + plant->rotor_inertia(1), 0.0);
  }
}

// At rest under the static torque the strap deflects by the quasi-static closed form and stays there:
// q_c = q - tau_C(q_c) / k with tau_C the gravity torque of the part behind it (HJ15 eq. 7; the
// compliant part's P(q) included for a human, and the subject's passive_moment with it: the strap
// carries the human's passive moment). The dead band's link rests on the loaded flank.
TEST(InternalJoints, AtRestTheStrapDeflectsByTheStaticTorqueOverK) {
  const Eigen::Vector2d q(0.5, -0.6), zero = Eigen::Vector2d::Zero();
  for (const int kind : {0, 1, 2}) {  // real rig; S1; S1 with its own passive moment (x 1.5 / x 0.7)
    const bool human = kind > 0;
    LegParams p = human ? S1() : RealRigModel();
    const double k = human ? 300 : 20;
    p.effects = {MakeEffect("series_compliance", "knee", k)};
    if (kind == 2)
      p.effects.insert(p.effects.end(),
                       {MakeEffect("passive_moment", "knee", 0.5), MakeEffect("passive_moment", "hip", -0.3)});
    auto plant = Carrying(p);
    plant->FreeJointsAndTorque();
    plant->Reset(q, zero);
    const double expected = CompliantAngle(p, 1, k, q, zero, zero)[1] - q[1];
    EXPECT_GT(std::abs(expected), 1e-3);
    EXPECT_NEAR(plant->internal_q()[1], expected, 1e-9);
    // The static torque: the driven part at q, the part behind the strap (with the subject's passive
    // moment) at its deflected angle.
    const Eigen::Vector2d qc = CompliantAngle(p, 1, k, q, zero, zero);
    LegParams bare = p;
    bare.effects.clear();
    const Eigen::Vector2d hold = ActuatorTorque(bare, q, zero, zero) - CompliantPartTorque(bare, q, zero, zero) +
                                 CompliantPartTorque(p, qc, zero, zero);
    for (int i = 0; i < 500; ++i) plant->Step(hold);
    EXPECT_NEAR(plant->internal_q()[1], expected, 1e-6) << kind;
    EXPECT_LT((plant->q() - q).norm(), 1e-6);
  }
  LegParams p = RealRigModel();
  p.effects = {MakeEffect("backlash", "knee", 0.04)};
  auto plant = Carrying(p);
  plant->FreeJointsAndTorque();
  const Eigen::Vector2d qb(0.5, -1.2);  // a knee load of 0.7 N m: the link on its flank (tanh 0.99999)
  plant->Reset(qb, zero);
  const double side = std::copysign(1.0, ActuatorTorque(p, qb, zero, zero)[1]);
  const Eigen::Vector2d hold = ActuatorTorque(p, qb - Eigen::Vector2d(0, 0.02 * side), zero, zero);
  ASSERT_GT(std::abs(hold[1]), 0.5);
  for (int i = 0; i < 500; ++i) plant->Step(hold);
  // The link lags the motor by half the band in the direction of the transmitted torque (within the
  // flank constraint's softness).
  EXPECT_NEAR(plant->internal_q()[1], -0.02 * side, 2e-4);
  EXPECT_LT((plant->q() - qb).norm(), 1e-3);  // the flank constraint is soft: its load moves the rest point a little
}

// A restart in motion by a run-in (Plant::Restate, as a replay window restarts, diagnosis/replay.h):
// a reference plant with a strap at S1's knee (300 N m/rad against the human shank) is driven by a
// smooth torque; at t = 1 s a second plant restarts from the reference's motor-side state and is driven
// by the same torque for 0.3 s. Reference: the reference plant itself. Restarted with its strap at rest
// at the quasi-static deflection, the strap rings and the motor angle departs; run in for
// InternalSettlingTime() before (the measured joints prescribed to the reference's motion step by
// step, the strap free), the motor angle follows the reference many times closer.
TEST(InternalJoints, ARunInAlongTheMotionCarriesTheStrapsState) {
  LegParams p = S1();
  p.effects = {MakeEffect("series_compliance", "knee", 300)};
  auto drive = [](double t) {
    return Eigen::Vector2d(4.0 * std::sin(2 * M_PI * 0.8 * t), 6.0 * std::sin(2 * M_PI * 1.3 * t + 0.4));
  };
  auto ref = Carrying(p);
  ref->FreeJointsAndTorque();
  const Eigen::Vector2d q_start(0.4, -0.8), zero = Eigen::Vector2d::Zero();
  ref->Reset(q_start, zero);
  const Eigen::Vector2d hold = ActuatorTorque(p, q_start, zero, zero);  // + the drive: stays in range
  const double dt = ref->timestep();
  const int n0 = static_cast<int>(std::lround(1.0 / dt)), n1 = n0 + 300;
  std::vector<Eigen::Vector2d> q(n1 + 1), qd(n1 + 1);
  for (int i = 0; i <= n1; ++i) {
    q[i] = ref->q(), qd[i] = ref->qd();
    if (i < n1) ref->Step(hold + drive(i * dt));
  }
  const double settle = ref->InternalSettlingTime();
  // 5 / (zeta omega), omega = sqrt(k / J), J the reduced inertia of S1's exoskeleton and human shanks.
  const double J = p.exo.J2 * p.human->J2 / (p.exo.J2 + p.human->J2);
  EXPECT_NEAR(settle, 5.0 / (0.5 * std::sqrt(300 / J)), 1e-12);
  auto departure = [&](bool run_in) {
    auto plant = Carrying(p);
    plant->FreeJointsAndTorque();
    const int r = run_in ? n0 - static_cast<int>(std::lround(settle / dt)) : n0;
    plant->Reset(q[r], qd[r], r * dt);
    for (int i = r; i < n0; ++i) {
      plant->Restate(q[i], qd[i], i * dt);
      plant->Step(hold + drive(i * dt));
    }
    plant->Restate(q[n0], qd[n0], n0 * dt);
    double sse = 0;
    for (int i = n0; i < n1; ++i) {
      plant->Step(hold + drive(i * dt));
      sse += (plant->q() - q[i + 1]).squaredNorm();
    }
    return std::sqrt(sse / (n1 - n0));
  };
  const double at_rest = departure(false), in_motion = departure(true);
  std::printf("strap restart, motor angle RMS departure over 0.3 s: at rest %.3g rad, run in %.3g rad\n", at_rest,
              in_motion);
  EXPECT_GT(at_rest, 1e-4);  // the ringing is visible (rad RMS over 0.3 s)
  EXPECT_LT(in_motion, 0.1 * at_rest) << "at rest " << at_rest << " rad, run in " << in_motion << " rad";
}

TEST(InternalJoints, WhatThePlantCannotCarryIsRefusedNamingTheEffect) {
  LegParams p = S1();
  p.effects = {MakeEffect("series_compliance", "hip", 300)};
  EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError);
  p.effects = {MakeEffect("backlash", "knee", 0.02), MakeEffect("series_compliance", "knee", 300)};
  EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError);
  p.effects = {MakeEffect("backlash", "knee", 0.2)};
  EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError);
  p.effects = {MakeEffect("muscle_activity", "knee", 1)};
  try {
    ToPlantEffects(p, "m.yaml");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("m.yaml: effects[0] (muscle_activity, knee)"), std::string::npos) << e.what();
  }
  // A strap too stiff for the step against the human's lower leg.
  p.effects = {MakeEffect("series_compliance", "knee", 1e7)};
  Plant plant(ExowheelMjcfPath(true));
  plant.SetParams(p);
  EXPECT_THROW(plant.CarryEffects(ToPlantEffects(p, "m.yaml")), InputError);
  // Back to the rigid plant: bit for bit the MJCF's structure.
  p.effects.clear();
  plant.CarryEffects(ToPlantEffects(p, "m.yaml"));
  EXPECT_EQ(plant.model()->nq, 2);
}

}  // namespace
}  // namespace exotwin
