// The motion fit's effect candidates (motion_fit.h "Candidates"): which effects are candidates, their
// parameters, boxes and secant steps, the effects a parameter vector stands for, and the torque fit's
// effects as parameter values; each family's part through its fit row (fit_families.h: motion_box, or
// its own motion_candidates, motion_effect, torque_values, no_motion_candidate).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "diagnosis/motion_fit.h"
#include "diagnosis/motion_fit_internal.h"
#include "formats/number_text.h"
#include "diagnosis/fit_families.h"
#include "model/effect_families.h"
#include "model/passive_torque.h"

namespace exotwin {

namespace {

// The effect of the model given that takes the place of candidate `name` at `joint` (the same effect,
// or one of its exclusive group: a dead band or a strap for either, one internal hinge per joint),
// nullptr if none.
const Effect* CarriedByModel(const LegParams& params, const std::string& name, const std::string& joint) {
  const char* group = FindFamily(name) ? FindFamily(name)->exclusive : "";
  for (const Effect& e : params.effects)
    if (e.joint == joint && (e.name == name || (*group && FindFamily(e.name) &&
                                                std::string(group) == FindFamily(e.name)->exclusive)))
      return &e;
  return nullptr;
}

}  // namespace

namespace motion {

bool TorqueValues(const MotionProblem& P, const Effect& e, Eigen::VectorXd* theta) {
  const int c = P.CandidateIndex(e.name, e.joint, e.axis);
  if (c < 0) return false;
  const Candidate& cand = P.candidates()[static_cast<size_t>(c)];
  const FitFamily* ff = FindFitFamily(e.name);
  if (ff && ff->torque_values) ff->torque_values(e, cand, theta);
  else (*theta)[cand.cols[0]] = e.value;
  return true;
}

int CandidateOf(const MotionProblem& P, const Effect& fx) {
  const FitFamily* ff = FindFitFamily(fx.name);
  return P.CandidateIndex(fx.name, fx.joint, ff && !ff->axes.empty() ? fx.axis : "");
}

void ExtendedTwin(const LegParams& params, Diagnosis* D_out) {
  Diagnosis& D = *D_out;
  std::stable_sort(D.effects.begin(), D.effects.end(), [](const DiagnosedEffect& a, const DiagnosedEffect& b) {
    const bool sa = StageOf(a.effect) == EffectStage::kSensor, sb = StageOf(b.effect) == EffectStage::kSensor;
    return sa != sb ? !sa : a.explained_pct > b.explained_pct;
  });
  D.extended = params;
  for (const auto& de : D.effects) D.extended.effects.push_back(de.effect);
  // The sensor effects in the order the rollouts applied them (the registry's: offset, gain, delay),
  // after the link effects.
  std::stable_sort(D.extended.effects.begin() + static_cast<long>(params.effects.size()), D.extended.effects.end(),
                   [](const Effect& a, const Effect& b) {
                     auto rank = [](const Effect& e) {
                       if (StageOf(e) != EffectStage::kSensor) return 0;
                       int k = 1;
                       for (const EffectFamily& f : EffectFamilies()) {
                         if (e.name == f.name) break;
                         ++k;
                       }
                       return k;
                     };
                     return rank(a) < rank(b);
                   });
}

bool TorqueValuesOfSet(const MotionProblem& P, const std::vector<DiagnosedEffect>& torque, const std::vector<int>& chosen,
                       Eigen::VectorXd* start_torque) {
  const std::vector<Candidate>& cands = P.candidates();
  bool has_torque = false;
  for (int c : chosen)
    for (const DiagnosedEffect& e : torque) {
      const Candidate& cand = cands[static_cast<size_t>(c)];
      if (e.effect.name == cand.name && e.effect.joint == kJoint[cand.joint] &&
          (cand.axis.empty() || e.effect.axis == cand.axis))
        has_torque = TorqueValues(P, e.effect, start_torque) || has_torque;
    }
  return has_torque;
}

}  // namespace motion

using motion::RmsAboutMean;
using motion::kJoint;

void MotionProblem::AddCandidates(const std::vector<Kinematics>& kins, const std::vector<DiagnosedEffect>& torque_named) {
  const LegParams& params = params_;
  const int j0 = params.one_joint ? 1 : 0;
  // Parameters, their boxes (DESIGN.md's ranges) and secant steps.
  auto Add = [&](const FitFamily* owner, const std::string& kind, int j, MotionBox box, double f = 0) {
    kind_.push_back(kind), joint_.push_back(j), lo_.push_back(box.lo), hi_.push_back(box.hi), step_.push_back(box.step);
    ripple_f_.push_back(f), owner_.push_back(owner);
    return static_cast<int>(lo_.size()) - 1;
  };
  for (int j = j0; j < 2; ++j) {
    double qd2 = 0, qdev = 0, cnt = 0;
    std::vector<double> all_q;
    for (const Kinematics& k : kins) {
      for (double v : k.qd[j]) qd2 += v * v, cnt += 1;
      all_q.insert(all_q.end(), k.q[j].begin(), k.q[j].end());
    }
    qdev = std::max(RmsAboutMean(all_q), 1e-3);
    const double qd_rms = std::max(std::sqrt(qd2 / std::max(cnt, 1.0)), 1e-3);
    qd_rms_[j] = qd_rms;
    const double tau = std::max(scale_.tau_max[j], 1e-3);
    const double M = std::max(scale_.M_jj[j], 1e-6);
    const double grav = 0.5 * scale_.distal_moment[j] + 0.05;
    const double range = scale_.q_max[j] - scale_.q_min[j];
    MotionJoint mj;
    mj.j = j, mj.params = &params, mj.reading_input = reading_input_, mj.torque_named = &torque_named;
    mj.scale = MotionScale{tau, M, qd_rms, grav, qdev, range, scale_.tau_C_max[j]};
    mj.add_parameter = [&](const FitFamily& f, const std::string& kind, MotionBox box, double freq) {
      return Add(&f, kind, j, box, freq);
    };
    mj.add_candidate = [&](const FitFamily& f, std::vector<int> cols) {
      Candidate c;
      c.name = f.family->name, c.joint = j, c.cols = std::move(cols);
      c.ripple_f = ripple_f_[static_cast<size_t>(c.cols[0])];
      candidates_.push_back(c);
    };
    mj.carried = [&](const FitFamily& f) { return CarriedByModel(params, f.family->name, kJoint[j]) != nullptr; };
    mj.own = [&](int k, const FitFamily& f) { owner_[static_cast<size_t>(k)] = &f; };
    // The joint's constant input torque (a sensor offset where the reading drives; the stiffness's k q0).
    mj.constant = Add(nullptr, "offset", j, {-0.5 * tau, 0.5 * tau, 0.02 * tau});
    // The families linear in their value (FitFamily::motion_box). Friction and inertia are summed by
    // the plant (sim/plant_effects.h: frictionloss, damping, armature): candidates on top of the model's
    // own (a one-joint device's R and C are its knee's frictions, model/one_joint.h); any other family
    // the model carries at the joint is no candidate.
    for (const FitFamily& ff : FitFamilies()) {
      if (!ff.motion_box || (ff.candidate_for && !ff.candidate_for(params))) continue;
      const PlantCarrier carrier = ff.family->carrier;
      const bool summed = carrier == PlantCarrier::kFrictionLoss || carrier == PlantCarrier::kDamping ||
                          carrier == PlantCarrier::kArmature;
      if (!summed && mj.carried(ff)) continue;
      const MotionBox box = ff.motion_box(mj.scale);
      for (const std::string& axis : ff.axes.empty() ? std::vector<std::string>{""} : ff.axes) {
        const std::string kind = std::string(ff.family->name) + (axis.empty() ? "" : "." + axis);
        mj.add_candidate(ff, {Add(&ff, kind, j, box)});
        candidates_.back().axis = axis;
      }
    }
    // Then the families with their own candidates, in the registry's order.
    for (const FitFamily& ff : FitFamilies())
      if (ff.motion_candidates && (!ff.candidate_for || ff.candidate_for(params))) ff.motion_candidates(mj, ff);
  }
}

int MotionProblem::CandidateIndex(const std::string& name, const std::string& joint, const std::string& axis) const {
  for (size_t c = 0; c < candidates_.size(); ++c)
    if (candidates_[c].name == name && kJoint[candidates_[c].joint] == joint &&
        (candidates_[c].axis.empty() || candidates_[c].axis == axis))
      return static_cast<int>(c);
  return -1;
}

std::string MotionProblem::WhyNoCandidate(const Effect& e) const {
  if (CandidateIndex(e.name, e.joint, e.axis) >= 0) return "";
  const EffectFamily* family = FindFamily(e.name);
  if (family && family->carrier == PlantCarrier::kNotCarried) return "not carried by the forward plant";
  if (family && family->stage == EffectStage::kSensor && !reading_input_) return "the commands drive the plant: no torque reading to correct";
  if (const Effect* g = CarriedByModel(params_, e.name, e.joint))
    return "the model given already carries a " + g->name + " at the " + g->joint + ": no candidate";
  const FitFamily* ff = FindFitFamily(e.name);
  const std::string why = ff && ff->no_motion_candidate ? ff->no_motion_candidate(e, params_) : "";
  if (!why.empty()) return why;
  if (params_.one_joint && e.joint == "hip") return "a one-joint model has no hip";
  return "no candidate of the motion fit";
}

std::vector<Effect> MotionProblem::EffectsOf(const Eigen::VectorXd& theta) const {
  std::vector<Effect> link, sensor;
  for (int k = 0; k < parameters(); ++k) {
    const double v = theta[k];
    const FitFamily* ff = owner_[static_cast<size_t>(k)];
    if (v == 0 || !ff) continue;
    Effect e;
    e.name = ff->family->name, e.joint = kJoint[joint_[k]], e.value = v, e.unit = ff->family->unit;
    if (ff->motion_box) {  // a family linear in its value: name[.axis]; a box from 0 names positive values only
      if (!(v > 0 || lo_[k] < 0)) continue;
      const size_t dot = kind_[k].find('.');
      if (dot != std::string::npos) e.axis = kind_[k].substr(dot + 1);
    } else if (!ff->motion_effect || !ff->motion_effect(*this, k, theta, &e)) {
      continue;
    }
    (ff->family->stage == EffectStage::kSensor ? sensor : link).push_back(e);
  }
  link.insert(link.end(), sensor.begin(), sensor.end());
  return link;
}

namespace motion {

// The friction's form on the exact plant: each named viscous friction exchanged for a Coulomb
// friction at its joint and the other way round (the linear model's ranking cannot tell the two
// apart where the joint's speed is nearly constant in magnitude; the torque fit's confusion),
// from the value dissipating the same power at the joint's RMS speed (c = b qd_rms) and from the
// torque fit's, taken where the exact fit-part BIC is lower.
void MotionFit::ExchangeFrictionForm(int round) {
  for (size_t i = 0; i < chosen.size(); ++i) {
    const Candidate& from = cands[static_cast<size_t>(chosen[i])];
    const FitFamily& ff = FitFamilyOf(from.name);
    if (!ff.exchanged_with) continue;
    const FitFamily& ft = FitFamilyOf(ff.exchanged_with);
    const int to = P.CandidateIndex(ff.exchanged_with, kJoint[from.joint]);
    if (to < 0 || std::find(chosen.begin(), chosen.end(), to) != chosen.end()) continue;
    std::vector<int> set = chosen;
    set[i] = to;
    const int kf = from.cols[0], kt = cands[static_cast<size_t>(to)].cols[0];
    const double v = theta[kf], speed = P.qd_rms(from.joint);
    std::vector<Eigen::VectorXd> starts(1, theta);
    starts[0][kf] = 0;
    starts[0][kt] = std::clamp(ft.value_at_speed(ff.torque_at_speed(v, speed), speed), P.lower(kt), P.upper(kt));
    for (const DiagnosedEffect& d : T.effects)
      if (d.effect.name == cands[static_cast<size_t>(to)].name && d.effect.joint == kJoint[from.joint]) {
        starts.push_back(starts[0]);
        starts.back()[kt] = std::clamp(d.effect.value, P.lower(kt), P.upper(kt));
      }
    const Refined rf = Refine(P, ColumnsOf(cand_bank, set), starts, kMotionLmIterations, false);
    if (!std::isfinite(rf.cost)) continue;
    const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
    const double bic_x = ExactBic(rf.cost, ParameterCount(set));
    const bool better = bic_x < bic_now;
    D.selection.push_back("round " + std::to_string(round + 1) + ": friction form " + Labels(P, chosen) + " -> " +
                          Labels(P, set) + ": exact BIC " + NumberText(bic_now, 4) + " -> " + NumberText(bic_x, 4) +
                          (better ? ", taken" : ", not taken"));
    if (!better) continue;
    MotionProblem::Rollout rx = P.Simulate(rf.theta, Part::kBoth);
    if (!rx.ok) continue;
    chosen = set, theta = rf.theta, at = std::move(rx);
  }
}

}  // namespace motion
}  // namespace exotwin
