#include "model/one_joint.h"

#include <algorithm>

#include "model/effect_families.h"

namespace exotwin {

LumpedParams OneJointLumped(const OneJointLink& link, double g) {
  LumpedParams p;
  p.J2 = link.I;
  p.X2 = g > 0 ? link.mgl / g : 0.0;
  p.Y2 = 0;
  // Lower leg: Iz2 = J2 - X2^2 / m2 > 0 needs m2 > X2^2 / J2; twice that leaves Iz2 = J2 / 2.
  p.m2 = std::max(link.I > 0 ? 2 * p.X2 * p.X2 / link.I : 0.0, 0.1);
  // Thigh: m1 = 1 kg at a1 = L1 / 2, Iz1 = m1 L1^2 / 12 (a uniform rod), HJ15 eq. 4.
  const double m1 = 1.0, a1 = kOneJointL1 / 2, Iz1 = m1 * kOneJointL1 * kOneJointL1 / 12;
  p.m1 = m1;
  p.J1 = Iz1 + m1 * a1 * a1 + p.J2 + p.m2 * kOneJointL1 * kOneJointL1;
  p.X1 = m1 * a1 + p.m2 * kOneJointL1;
  p.Y1 = 0;
  return p;
}

LegParams EmbedOneJointModel(const OneJointModel& m, double g, const std::vector<Effect>& effects) {
  LegParams p;
  p.L1 = kOneJointL1;
  p.g = g;
  p.exo = OneJointLumped(m.device, g);
  if (m.human) p.human = OneJointLumped(*m.human, g);
  p.passive = PassiveModel::kNone;
  p.one_joint = m;
  p.one_joint->device_effects = 0;
  if (m.R != 0) p.effects.push_back({kViscousFriction, "knee", m.R, FindFamily(kViscousFriction)->unit, {}, ""});
  if (m.C != 0) p.effects.push_back({kCoulombFriction, "knee", m.C, FindFamily(kCoulombFriction)->unit, {}, ""});
  p.one_joint->device_effects = p.effects.size();
  p.effects.insert(p.effects.end(), effects.begin(), effects.end());
  return p;
}

}  // namespace exotwin
