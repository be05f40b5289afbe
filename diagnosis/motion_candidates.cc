// The motion fit's effect candidates (motion_fit.h "Candidates"): which effects are candidates, their
// parameters, boxes and secant steps, the effects a parameter vector stands for, and the torque fit's
// effects as parameter values. The code of the motion fit that branches on effect names lives here.
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

constexpr double kNoBacklash = 1e-5;    // rad: a narrower dead band is none (the hinge is not built)
constexpr double kNoCompliance = 1e-7;  // rad/(N m): a stiffer strap is none

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
  const double v = e.value;
  if (e.name == "series_compliance") {
    (*theta)[cand.cols[0]] = v > 0 ? 1 / v : 0;
  } else if (e.name == "joint_stiffness") {
    (*theta)[cand.cols[0]] = v;
    (*theta)[cand.cols[1]] = v * (e.fields.count("q0") ? e.fields.at("q0") : 0.0);
  } else if (e.name == "torque_ripple") {
    const double ph = e.fields.count("phase") ? e.fields.at("phase") : 0.0;
    (*theta)[cand.cols[0]] = v * std::cos(ph);
    (*theta)[cand.cols[1]] = v * std::sin(ph);
  } else {
    (*theta)[cand.cols[0]] = v;
  }
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
  auto Add = [&](const std::string& kind, int j, double lo, double hi, double step, double f = 0) {
    kind_.push_back(kind), joint_.push_back(j), lo_.push_back(lo), hi_.push_back(hi), step_.push_back(step);
    ripple_f_.push_back(f);
    return static_cast<int>(lo_.size()) - 1;
  };
  auto Has = [&](const std::string& name, int j) { return CarriedByModel(params, name, kJoint[j]) != nullptr; };
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
    auto Cand = [&](const std::string& name, std::vector<int> cols, const std::string& axis = "") {
      Candidate c;
      c.name = name, c.joint = j, c.axis = axis, c.cols = std::move(cols);
      c.ripple_f = ripple_f_[static_cast<size_t>(c.cols[0])];
      candidates_.push_back(c);
    };
    const int off = Add("offset", j, -0.5 * tau, 0.5 * tau, 0.02 * tau);
    // The families linear in their value (FitFamily::motion_box). Friction and inertia are summed by
    // the plant (sim/plant_effects.h: frictionloss, damping, armature): candidates on top of the model's
    // own (a one-joint device's R and C are its knee's frictions, model/one_joint.h); any other family
    // the model carries at the joint is no candidate.
    const MotionScale ms{tau, M, qd_rms, grav};
    for (const FitFamily& ff : FitFamilies()) {
      if (!ff.motion_box || (ff.candidate_for && !ff.candidate_for(params))) continue;
      const PlantCarrier carrier = ff.family->carrier;
      const bool summed = carrier == PlantCarrier::kFrictionLoss || carrier == PlantCarrier::kDamping ||
                          carrier == PlantCarrier::kArmature;
      if (!summed && Has(ff.family->name, j)) continue;
      const MotionBox box = ff.motion_box(ms);
      for (const std::string& axis : ff.axes.empty() ? std::vector<std::string>{""} : ff.axes) {
        const std::string kind = std::string(ff.family->name) + (axis.empty() ? "" : "." + axis);
        Cand(ff.family->name, {Add(kind, j, box.lo, box.hi, box.step)}, axis);
      }
    }
    if (!Has("joint_stiffness", j))
      Cand("joint_stiffness", {Add("joint_stiffness", j, 0, 100 * tau / qdev, 0.02 * tau / qdev), off});
    if (!Has("backlash", j)) Cand("backlash", {Add("backlash", j, 0, 0.1, 0.005)});
    if (!Has("series_compliance", j) && !(j == 0 && params.human)) {
      const double tc = std::max(scale_.tau_C_max[j], 1e-3);
      Cand("series_compliance", {Add("series_compliance", j, 0, 0.5 * range / tc, 0.005 / tc)});
    }
    for (const DiagnosedEffect& d : torque_named)
      if (d.effect.name == "torque_ripple" && d.effect.joint == kJoint[j] && !Has("torque_ripple", j)) {
        const double f = d.effect.fields.at("cycles_per_rad");
        const int a = Add("torque_ripple.sin", j, -0.5 * tau, 0.5 * tau, 0.02 * tau, f);
        Cand("torque_ripple", {a, Add("torque_ripple.cos", j, -0.5 * tau, 0.5 * tau, 0.02 * tau, f)});
      }
    if (reading_input_) {
      if (!Has("sensor_offset", j)) Cand("sensor_offset", {off});
      if (!Has("sensor_gain", j)) Cand("sensor_gain", {Add("sensor_gain", j, -0.25, 0.25, 0.02)});
      if (!Has("sensor_delay", j)) Cand("sensor_delay", {Add("sensor_delay", j, 0, 0.05, 0.002)});
    }
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
  if (e.name == "series_compliance" && e.joint == "hip" && params_.human)
    return "the plant carries a strap with a human at the knee only";
  if (e.name == "passive_moment") return "no passive moment in this model (a two-joint model with a human carries it)";
  if (params_.one_joint && e.joint == "hip") return "a one-joint model has no hip";
  return "no candidate of the motion fit";
}

std::vector<Effect> MotionProblem::EffectsOf(const Eigen::VectorXd& theta) const {
  std::vector<Effect> link, sensor;
  auto Make = [](const std::string& name, int j, double v) {
    Effect e;
    e.name = name, e.joint = kJoint[j], e.value = v, e.unit = FindFamily(name)->unit;
    return e;
  };
  for (int k = 0; k < parameters(); ++k) {
    const double v = theta[k];
    const int j = joint_[k];
    const std::string& kind = kind_[k];
    if (v == 0) continue;
    {  // a family linear in its value: name[.axis]; a box from 0 names positive values only
      const size_t dot = kind.find('.');
      const std::string name = kind.substr(0, dot);
      const FitFamily* ff = FindFitFamily(name);
      if (ff && ff->motion_box && (v > 0 || lo_[k] < 0)) {
        Effect e = Make(name, j, v);
        if (dot != std::string::npos) e.axis = kind.substr(dot + 1);
        link.push_back(e);
      }
    }
    if (kind == "joint_stiffness" && v > 0) {  // its constant part k q0 is the offset parameter
      Effect e = Make(kind, j, v);
      e.fields["q0"] = 0;
      link.push_back(e);
    }
    if (kind == "backlash" && v > kNoBacklash) link.push_back(Make(kind, j, v));
    if (kind == "series_compliance" && v > kNoCompliance) link.push_back(Make(kind, j, 1 / v));
    if (kind == "torque_ripple.sin") {
      const double b = theta[k + 1];
      Effect e = Make("torque_ripple", j, std::hypot(v, b));
      e.fields["cycles_per_rad"] = ripple_f_[k];
      e.fields["phase"] = std::atan2(b, v);
      link.push_back(e);
    }
    // The input's constant torque: a sensor offset where the reading drives (tau_R = -(reading - offset)).
    if (kind == "offset" && reading_input_) sensor.push_back(Make("sensor_offset", j, v));
    if (kind == "sensor_gain") sensor.push_back(Make(kind, j, v));
    if (kind == "sensor_delay" && v > 0) sensor.push_back(Make(kind, j, v));
  }
  for (int k = 0; k < parameters(); ++k)  // a ripple whose sine part is 0
    if (kind_[k] == "torque_ripple.cos" && theta[k] != 0 && theta[k - 1] == 0) {
      Effect e = Make("torque_ripple", joint_[k], std::abs(theta[k]));
      e.fields["cycles_per_rad"] = ripple_f_[k];
      e.fields["phase"] = std::atan2(theta[k], 0.0);
      link.push_back(e);
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
    if (from.name != "viscous_friction" && from.name != "coulomb_friction") continue;
    const bool to_coulomb = from.name == "viscous_friction";
    const int to = P.CandidateIndex(to_coulomb ? "coulomb_friction" : "viscous_friction", kJoint[from.joint]);
    if (to < 0 || std::find(chosen.begin(), chosen.end(), to) != chosen.end()) continue;
    std::vector<int> set = chosen;
    set[i] = to;
    const int kf = from.cols[0], kt = cands[static_cast<size_t>(to)].cols[0];
    const double v = theta[kf], speed = P.qd_rms(from.joint);
    std::vector<Eigen::VectorXd> starts(1, theta);
    starts[0][kf] = 0;
    starts[0][kt] = std::clamp(to_coulomb ? v * speed : v / speed, P.lower(kt), P.upper(kt));
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
