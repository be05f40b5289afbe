// The effects the forward plant carries (sim/plant_effects.h), checked against the closed form
// (model/leg_dynamics.h, HJ15 eq. 5-7): the forward acceleration MuJoCo computes with an effect
// carried equals (M + diag(armature))^-1 (tau - V - G - effect torques).
#include "sim/plant_effects.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include <Eigen/Dense>
#include <mujoco/mujoco.h>

#include "core/error.h"
#include "tests/real_rig_model.h"
#include "model/leg_dynamics.h"
#include "model/one_joint.h"
#include "model/passive_torque.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

// Forward acceleration of the plant at (q, qd) under tau with the effects of p carried (one step
// from the state: MuJoCo's qacc of that step).
Eigen::Vector2d PlantAcceleration(const LegParams& p, const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                                  const Eigen::Vector2d& tau) {
  Plant plant(ExowheelMjcfPath(false));
  plant.SetParams(p);
  plant.CarryEffects(ToPlantEffects(p, "test"));
  plant.FreeJointsAndTorque();
  plant.Reset(q, qd);
  plant.Step(tau);
  return plant.qdd();
}

// The closed form with the table's effect torques (DESIGN.md "Effects": what the actuator needs in
// addition), sliding (qd != 0).
Eigen::Vector2d ClosedFormAcceleration(const LegParams& p, const Eigen::Vector2d& q, const Eigen::Vector2d& qd,
                                       const Eigen::Vector2d& tau) {
  Eigen::Matrix2d M = MassMatrix(p.exo, p.L1, q[1]);
  Eigen::Vector2d f = tau - CoriolisCentrifugal(p.exo, p.L1, q, qd) - GravityTorque(p.exo, p.g, q);
  for (const Effect& e : p.effects) {
    const int j = e.joint == "hip" ? 0 : 1;
    if (e.name == "coulomb_friction") f[j] -= e.value * (qd[j] > 0 ? 1 : -1);
    if (e.name == "viscous_friction") f[j] -= e.value * qd[j];
    if (e.name == "inertia_error") M(j, j) += e.value;
    if (e.name == "joint_stiffness") f[j] -= e.value * (q[j] - e.fields.at("q0"));
    if (e.name == "gravity_error") f -= GravityErrorTorque(e, p.g, q);
    if (e.name == "torque_ripple") f[j] -= TorqueRippleTorque(e, q[j]);
    // Riener & Edrich 1999 in degrees, mapped as model/passive_torque.h states: P1 = -M_H, P2 = +M_K.
    const double H = q[0] * 180.0 / M_PI, K = -q[1] * 180.0 / M_PI;
    if (e.name == "passive_moment") f[j] -= e.value * (j == 0 ? -RienerHipMoment(H, K) : RienerKneeMoment(0, K, H));
  }
  return M.ldlt().solve(f);
}

TEST(PlantEffects, EachCarriedEffectMatchesTheClosedForm) {
  Effect stiff = MakeEffect("joint_stiffness", "knee", 0.8);
  stiff.fields["q0"] = 0.2;
  Effect grav = MakeEffect("gravity_error", "knee", 0.02);
  grav.axis = "X";
  Effect gravy = MakeEffect("gravity_error", "hip", -0.03);
  gravy.axis = "Y";
  Effect ripple = MakeEffect("torque_ripple", "hip", 0.05);
  ripple.fields["cycles_per_rad"] = 3.0;
  ripple.fields["phase"] = 0.4;
  const std::vector<std::vector<Effect>> cases = {
      {MakeEffect("viscous_friction", "hip", 0.05)}, {MakeEffect("viscous_friction", "knee", 0.02)},
      {MakeEffect("inertia_error", "hip", 0.01)},    {MakeEffect("inertia_error", "knee", 0.0028)},
      {MakeEffect("inertia_error", "knee", -0.005)}, {stiff},
      {grav},                                {gravy},
      {ripple},                              {MakeEffect("coulomb_friction", "hip", 0.15), MakeEffect("coulomb_friction", "knee", 0.12)},
      {MakeEffect("passive_moment", "hip", 0.004)}, {MakeEffect("passive_moment", "knee", -0.003)}};
  const Eigen::Vector2d q(0.7, -1.1), qd(1.5, -2.0), tau(0.4, -0.3);
  for (const auto& fx : cases) {
    LegParams p = RealRigModel();
    p.effects = fx;
    const Eigen::Vector2d a = PlantAcceleration(p, q, qd, tau);
    const Eigen::Vector2d b = ClosedFormAcceleration(p, q, qd, tau);
    // Damping is integrated implicitly by MuJoCo's Euler (qacc is the explicit one); the
    // realization of the lumped parameters is exact to round-off.
    EXPECT_LT((a - b).norm(), 1e-8 * (1 + b.norm())) << fx[0].name << " " << fx[0].joint << ": " << a.transpose()
                                                      << " vs " << b.transpose();
    // The effect is felt: the rigid twin accelerates differently.
    LegParams rigid = RealRigModel();
    EXPECT_GT((a - ClosedFormAcceleration(rigid, q, qd, tau)).norm(), 1e-4) << fx[0].name;
  }
}

TEST(PlantEffects, NoEffectsLeaveThePlantBitIdentical) {
  LegParams p = RealRigModel();
  Plant a(ExowheelMjcfPath(false)), b(ExowheelMjcfPath(false));
  a.SetParams(p);
  b.SetParams(p);
  b.CarryEffects(ToPlantEffects(p, "test"));
  a.Reset({0.3, -0.4}, {0.1, 0.2});
  b.Reset({0.3, -0.4}, {0.1, 0.2});
  for (int i = 0; i < 500; ++i) {
    a.Step({0.2 * std::sin(0.01 * i), 0.1});
    b.Step({0.2 * std::sin(0.01 * i), 0.1});
  }
  EXPECT_EQ(a.q()[0], b.q()[0]);
  EXPECT_EQ(a.q()[1], b.q()[1]);
  EXPECT_EQ(a.qd()[1], b.qd()[1]);
}

TEST(PlantEffects, InverseDynamicsStaysTheRigidTwins) {
  LegParams p = RealRigModel();
  Plant rigid(ExowheelMjcfPath(false));
  rigid.SetParams(p);
  Effect stiff = MakeEffect("joint_stiffness", "hip", 0.5);
  stiff.fields["q0"] = 0.1;
  p.effects = {MakeEffect("viscous_friction", "knee", 0.03), MakeEffect("inertia_error", "hip", 0.01), stiff,
               MakeEffect("coulomb_friction", "knee", 0.1)};
  Plant carried(ExowheelMjcfPath(false));
  carried.SetParams(p);
  carried.CarryEffects(ToPlantEffects(p, "test"));
  const Eigen::Vector2d q(0.4, -0.9), qd(1.2, -0.7), qdd(3.0, -5.0);
  EXPECT_LT((rigid.InverseDynamics(q, qd, qdd) - carried.InverseDynamics(q, qd, qdd)).norm(), 1e-12);
}

// passive_moment's torque pinned to Riener & Edrich's magnitudes (../shared/papers/README.md: hip 0 and
// knee 0 give M_K = +10.4 N m, M_H = +8.6 N m): value P_j(q), P1 = -M_H, P2 = +M_K.
TEST(PlantEffects, PassiveMomentIsAFactorOnRienerEdrich) {
  const Eigen::Vector2d q0(0.0, 0.0);
  EXPECT_NEAR(PassiveMomentTorque(MakeEffect("passive_moment", "knee", 0.5), q0), 0.5 * 10.4, 0.03);
  EXPECT_NEAR(PassiveMomentTorque(MakeEffect("passive_moment", "hip", -0.3), q0), -0.3 * -8.6, 0.03);
  // The plant carries it as an applied force of minus that torque, at the human's angles (where P^
  // acts), apart from the joint's applied forces; out of (0, 3] times Riener's: refused.
  LegParams p = RealRigModel();
  p.effects = {MakeEffect("passive_moment", "knee", 0.5)};
  EXPECT_NEAR(ToPlantEffects(p, "m.yaml").SubjectPassiveForce(q0)[1], -5.2, 0.03);
  EXPECT_EQ(ToPlantEffects(p, "m.yaml").AppliedForce(q0, Eigen::Vector2d::Zero())[1], 0.0);
  for (double v : {-1.0, 2.5}) {
    p.effects = {MakeEffect("passive_moment", "hip", v)};
    EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError) << v;
  }
  // A one-joint device's knee is not HJ15's two-joint leg: refused.
  OneJointModel one;
  one.device = {0.2, 1.5};
  one.human = OneJointLink{0.43, 11.0};
  const LegParams embedded = EmbedOneJointModel(one, 9.81, {MakeEffect("passive_moment", "knee", 0.2)});
  EXPECT_THROW(ToPlantEffects(embedded, "m.yaml"), InputError);
}

TEST(PlantEffects, RefusesWhatThePlantCannotCarryNamingTheEffect) {
  for (const char* name : {"muscle_activity"}) {  // backlash, series_compliance: tests/sim/internal_joints_test.cc
    LegParams p = RealRigModel();
    p.effects = {MakeEffect("viscous_friction", "hip", 0.01), MakeEffect(name, "knee", 0.05)};
    try {
      ToPlantEffects(p, "m.yaml");
      ADD_FAILURE() << name << " accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("m.yaml: effects[1] (" + std::string(name) + ", knee)"), std::string::npos) << msg;
      EXPECT_NE(msg.find("cannot carry"), std::string::npos) << msg;
    }
  }
  // A negative inertia larger than the knee's own (J2 = 0.0239 kg m^2) is refused; -0.005 is carried.
  LegParams p = RealRigModel();
  p.effects = {MakeEffect("inertia_error", "knee", -0.03)};
  EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError);
  p.effects = {MakeEffect("inertia_error", "knee", -0.005)};
  EXPECT_NO_THROW(ToPlantEffects(p, "m.yaml"));
  // The sensor effects are for the reader, not the link.
  p.effects = {MakeEffect("sensor_offset", "hip", 0.1), MakeEffect("sensor_gain", "knee", 0.05)};
  const PlantEffects fx = ToPlantEffects(p, "m.yaml");
  EXPECT_TRUE(fx.link_empty());
  EXPECT_FALSE(fx.empty());
  ASSERT_EQ(fx.sensor[1].size(), 1u);
  EXPECT_EQ(fx.sensor[1][0].name, "sensor_gain");
}

// The plant's applied generalized force is each applied family's own closed form (issue 62's second
// defect: every applied effect but gravity and the passive moment was taken for a torque ripple). For
// every family the registry applies as a force, with the fields it needs, at several angles: minus the
// torque its closed form needs, and nothing of the others'; an effect of no family is refused, not
// simulated as a ripple.
TEST(PlantEffects, AppliedForceIsEachAppliedFamilysClosedForm) {
  for (const EffectFamily& f : EffectFamilies()) {
    if (f.carrier != PlantCarrier::kAppliedForce) continue;
    for (const char* joint : {"hip", "knee"}) {
      Effect e;
      e.name = f.name, e.joint = joint, e.value = 0.3, e.axis = "Y", e.expr = "q_hip - 0.5 * qd";  // expr: a term's
      for (const std::string& field : f.fields) e.fields[field] = 0.7;
      PlantEffects fx;
      fx.g = 9.81;
      fx.applied = {e};
      for (double a : {-0.9, 0.2, 1.1}) {
        EffectState s;
        s.q = {a, -0.5 * a}, s.qd = {0.3 * a, -a}, s.qdd.setZero(), s.g = 9.81;
        EXPECT_EQ(fx.AppliedForce(s.q, s.qd), -f.link_torque(e, s)) << f.name << " " << joint;
      }
    }
  }
  // torque_ripple and gravity_error against the table's formulas written out (DESIGN.md "Effects").
  Effect r, g;
  r.name = "torque_ripple", r.joint = "knee", r.value = 0.4, r.fields = {{"cycles_per_rad", 3.0}, {"phase", 0.5}};
  g.name = "gravity_error", g.joint = "hip", g.value = 0.2, g.axis = "X";
  PlantEffects fx;
  fx.g = 9.81;
  fx.applied = {r, g};
  const Eigen::Vector2d q(0.3, -0.6);
  const Eigen::Vector2d f = fx.AppliedForce(q, Eigen::Vector2d(0.4, -0.2));
  EXPECT_NEAR(f[0], -9.81 * 0.2 * std::sin(0.3), 1e-14);
  EXPECT_NEAR(f[1], -0.4 * std::sin(2 * M_PI * 3.0 * -0.6 + 0.5), 1e-14);
  Effect unknown = r;
  unknown.name = "gear_friction";
  fx.applied = {unknown};
  EXPECT_THROW(fx.AppliedForce(q, Eigen::Vector2d::Zero()), std::invalid_argument);
  LegParams p;
  p.effects = {unknown};
  EXPECT_THROW(ToPlantEffects(p, "m.yaml"), InputError);
}

Effect TermEffect(const char* joint, double value, const char* expr, const char* stage = "") {
  Effect e = MakeEffect("term", joint, value);
  e.expr = expr, e.stage = stage;
  return e;
}

// The shipped two-link plant carrying p's effects, its joints and torque free.
std::unique_ptr<Plant> FreePlant(const LegParams& p) {
  auto plant = std::make_unique<Plant>(ExowheelMjcfPath(false));
  plant->SetParams(p);
  plant->CarryEffects(ToPlantEffects(p, "test"));
  plant->FreeJointsAndTorque();
  return plant;
}

int Dof(const Plant& plant, const char* joint) {
  return plant.model()->jnt_dofadr[mj_name2id(plant.model(), mjOBJ_JOINT, joint)];
}

// Terms in the forward plant (DESIGN.md "Terms beyond the table"): sorted by stage and friction
// likeness; a friction-like term is that step's frictionloss |value f| from the actuator torque of the
// step; an applied term is minus its closed form at the step's state (qdd the last step's, t from the
// origin set), and the acceleration is the closed form's with it.
TEST(PlantEffects, TermsAreFrictionBoundsAppliedForcesOrReadings) {
  LegParams p = RealRigModel();
  p.effects = {TermEffect("knee", 0.05, "abs(tau_R) * sgn(qd)"), TermEffect("hip", 2.0, "sin(q)"),
               TermEffect("knee", -0.01, "tau_R", "sensor")};
  const PlantEffects fx = ToPlantEffects(p, "test");
  ASSERT_EQ(fx.friction_terms.size(), 1u);
  EXPECT_EQ(fx.friction_terms[0].joint, 1);
  EXPECT_EQ(fx.friction_terms[0].f.text(), "abs(tau_R)");
  ASSERT_EQ(fx.applied.size(), 1u);
  EXPECT_EQ(fx.applied[0].expr, "sin(q)");
  ASSERT_EQ(fx.sensor[1].size(), 1u);
  EXPECT_EQ(fx.sensor[1][0].expr, "tau_R");
  EXPECT_FALSE(fx.link_empty());

  // The friction bound each step: |0.05 tau_R,knee| of the torque applied at that step.
  LegParams friction = RealRigModel();
  friction.effects = {p.effects[0]};
  const std::unique_ptr<Plant> plant_owned = FreePlant(friction);
  Plant& plant = *plant_owned;
  const int knee = Dof(plant, "knee"), hip = Dof(plant, "hip");
  const double base = plant.model()->dof_frictionloss[knee];
  EXPECT_EQ(plant.model()->dof_solref[mjNREF * knee], 2 * plant.timestep());
  plant.Reset({0.3, -0.6}, {0.5, -1.0});
  for (double tau : {-4.0, 6.0, 0.0, 2.5}) {
    plant.Step({0.3, tau});
    EXPECT_EQ(plant.model()->dof_frictionloss[knee], base + std::abs(0.05 * tau)) << tau;
    EXPECT_EQ(plant.model()->dof_frictionloss[hip], 0.0);
  }

  // A negative bound (value f < 0: a friction pushing along the motion) is no frictionloss: the applied
  // force -value f sgn(qd) instead.
  LegParams along = RealRigModel();
  along.effects = {TermEffect("hip", 0.3, "-2 * sgn(qd)")};
  const std::unique_ptr<Plant> along_owned = FreePlant(along);
  along_owned->Reset({0.3, -0.6}, {0.5, -1.0});
  along_owned->Step({0.3, 0.0});
  EXPECT_EQ(along_owned->model()->dof_frictionloss[Dof(*along_owned, "hip")], 0.0);
  EXPECT_EQ(along_owned->data()->qfrc_applied[Dof(*along_owned, "hip")], 0.6);

  // An applied term 2 sin(q) at the hip: the force and the acceleration against the closed form.
  LegParams applied = RealRigModel();
  applied.effects = {p.effects[1]};
  const Eigen::Vector2d q(0.7, -1.1), qd(1.5, -2.0), tau(0.4, -0.3);
  const std::unique_ptr<Plant> a_owned = FreePlant(applied);
  Plant& a = *a_owned;
  a.Reset(q, qd);
  a.Step(tau);
  EXPECT_EQ(a.data()->qfrc_applied[Dof(a, "hip")], -2.0 * std::sin(q[0]));
  EXPECT_EQ(a.data()->qfrc_applied[Dof(a, "knee")], 0.0);
  const Eigen::Vector2d closed = ClosedFormAcceleration(RealRigModel(), q, qd, tau - Eigen::Vector2d(2.0 * std::sin(q[0]), 0));
  EXPECT_NEAR((a.qdd() - closed).norm(), 0.0, 1e-9 * closed.norm());

  // qdd the last step's (0 after a reset), tau_R the step's torque, t from the origin set.
  LegParams reads = RealRigModel();
  reads.effects = {TermEffect("knee", 0.5, "qdd + 0.1 * tau_R + t")};
  const std::unique_ptr<Plant> b_owned = FreePlant(reads);
  Plant& b = *b_owned;
  b.SetTermTimeOrigin(1.5);
  b.Reset(q, qd, 2.0);
  b.Step(tau);
  EXPECT_DOUBLE_EQ(b.data()->qfrc_applied[Dof(b, "knee")], -0.5 * (0.0 + 0.1 * tau[1] + 0.5));
  const double qdd1 = b.qdd()[1], t1 = b.time();
  b.Step(2 * tau);
  EXPECT_DOUBLE_EQ(b.data()->qfrc_applied[Dof(b, "knee")], -0.5 * (qdd1 + 0.1 * 2 * tau[1] + (t1 - 1.5)));

  // A bad expression: the source, the effect and the position.
  LegParams bad = RealRigModel();
  bad.effects = {TermEffect("knee", 1.0, "sgn(qd) * (1 + q")};
  try {
    ToPlantEffects(bad, "m.yaml");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("m.yaml: effects[0] (term, knee)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("position 16"), std::string::npos) << e.what();
  }
}

// A term-free plant steps exactly as before terms existed: its frictionloss is the carried one.
TEST(PlantEffects, ATermFreePlantKeepsItsFrictionloss) {
  LegParams p = RealRigModel();
  p.effects = {MakeEffect("coulomb_friction", "knee", 0.12)};
  Plant plant(ExowheelMjcfPath(false));
  plant.SetParams(p);
  plant.CarryEffects(ToPlantEffects(p, "test"));
  const double fl = plant.model()->dof_frictionloss[Dof(plant, "knee")];
  plant.Reset({0.3, -0.6}, {0.5, -1.0});
  plant.Step({0.3, -4.0});
  EXPECT_EQ(plant.model()->dof_frictionloss[Dof(plant, "knee")], fl);
}

}  // namespace
}  // namespace exotwin
