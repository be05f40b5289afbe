// The sensor families' fit rows (diagnosis/family_sensors.cc): a sensor offset beside a Coulomb
// friction at the same joint has its equivalent reading, a direction-dependent friction, among its
// aliases (FitFamily::equivalent).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "diagnosis/diagnose.h"
#include "diagnosis/effects.h"
#include "model/leg_dynamics.h"
#include "tests/diagnosis/hidden_effect_util.h"

namespace exotwin {
namespace {

using testing_hidden::CleanRecord;
using testing_hidden::Hide;
using testing_hidden::S1;
using testing_hidden::TorqueOnly;

// The link torque 1.5 N m while the knee flexes one way and 0.3 N m the other (a drive's friction that
// differs by direction), hidden by hand. In the torque of a joint that moves it is exactly a Coulomb
// friction of 0.9 N m and a constant 0.6 N m: diagnose names Coulomb and a sensor offset, whose alias
// is the term 0.6 * abs(sgn(qd)); the twin with the alias in the offset's place predicts the same
// reading (1e-9 N m) on an unseen trajectory, and both predict the hidden torque.
TEST(FamilySensors, AnOffsetBesideCoulombIsADirectionDependentFriction) {
  const LegParams base = S1();
  auto directional = [](double, double qd, double, double) { return qd > 0 ? 1.5 : (qd < 0 ? -0.3 : 0.0); };
  GeneratedData rec = CleanRecord(970, 30);
  Hide(base, {1}, directional, &rec.data);
  const Diagnosis d = Diagnose(base, rec.data, TorqueOnly());
  const DiagnosedEffect *coulomb = nullptr, *offset = nullptr;
  for (const auto& e : d.effects) {
    if (e.effect.name == "coulomb_friction" && e.effect.joint == "knee") coulomb = &e;
    if (e.effect.name == "sensor_offset" && e.effect.joint == "knee") offset = &e;
  }
  ASSERT_NE(coulomb, nullptr);
  ASSERT_NE(offset, nullptr);
  EXPECT_NEAR(coulomb->effect.value, 0.9, 0.01 * 0.9);
  EXPECT_NEAR(offset->effect.value, -0.6, 0.01 * 0.6);
  ASSERT_FALSE(offset->aliases.empty());
  const EffectAlias& a = offset->aliases.front();
  ASSERT_EQ(a.effects.size(), 1u);
  EXPECT_EQ(a.effects[0].name, "term");
  EXPECT_EQ(a.effects[0].expr, "abs(sgn(qd))");
  EXPECT_DOUBLE_EQ(a.effects[0].value, -offset->effect.value);
  // The friction each way: c - o = 1.5 with qd > 0, c + o = 0.3 with qd < 0.
  std::printf("friction %.4f one way, %.4f the other\n", coulomb->effect.value - offset->effect.value,
              coulomb->effect.value + offset->effect.value);

  // The two readings on an unseen trajectory.
  LegParams with_offset = base, with_alias = base;
  with_offset.effects = {coulomb->effect, offset->effect};
  with_alias.effects = {coulomb->effect, a.effects[0]};
  const MeasuredData unseen = CleanRecord(1970, 30).data;
  const Kinematics k = DeriveKinematics(unseen, 20.0);
  std::vector<double> tr[2];
  for (int j = 0; j < 2; ++j) tr[j].resize(k.t.size());
  for (size_t i = 0; i < k.t.size(); ++i) {
    const auto tau = ActuatorTorque(base, {k.q[0][i], k.q[1][i]}, {k.qd[0][i], k.qd[1][i]}, {k.qdd[0][i], k.qdd[1][i]});
    tr[0][i] = tau[0], tr[1][i] = tau[1];
  }
  std::vector<double> a0[2] = {tr[0], tr[1]}, a1[2] = {tr[0], tr[1]}, s0[2], s1[2];
  ApplyEffects(with_offset, k, a0, s0);
  ApplyEffects(with_alias, k, a1, s1);
  double worst = 0, se = 0, ss = 0;
  for (size_t i = 0; i < k.t.size(); ++i) {
    worst = std::max(worst, std::abs(s0[1][i] - s1[1][i]));
    const double h = directional(k.q[1][i], k.qd[1][i], tr[1][i], k.t[i]);
    const double predicted = -(s1[1][i] - (-tr[1][i]));  // the link torque beyond the rigid twin's
    se += (h - predicted) * (h - predicted), ss += h * h;
  }
  EXPECT_LE(worst, 1e-9);
  EXPECT_LE(se / ss, 1e-3) << "the hidden torque predicted to 99.9 % of its mean square";
}

}  // namespace
}  // namespace exotwin
