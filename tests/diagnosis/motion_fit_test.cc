// `diagnose --fit motion` (diagnosis/motion_fit.h): the Jacobian against the closed form of a pendulum,
// bad input, and closed-loop records of the shipped gait on a plant holding a hidden effect (the
// shipped controller tracking the gait through the virtual bus, `exotwin run` with `plant: {effects}`):
// the motion fit names the effect and nothing else; on the rigid plant nothing. Records of 15 s (ASan
// runs them about 3x slower); the 60 s sweeps are `exotwin bench` rows.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "diagnosis/motion_fit.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "sim/subjects.h"
#include "tests/app/cli_test_util.h"

namespace exotwin {
namespace {

using testing::RunExotwin;
using testing::WriteText;

const std::string kSrc = EXOTWIN_SOURCE_DIR;

// A one-joint pendulum without friction hanging at rest, I = 0.5 kg m^2, mgl = 5 N m, 4 s at 1 kHz,
// no torque (commanded 0).
struct Pendulum {
  LegParams params;
  MeasuredData data;
};

Pendulum RestingPendulum(const std::string& dir) {
  WriteText(dir + "/pendulum.yaml", "joint: knee\ndevice: {I: 0.5, mgl: 5.0, R: 0, C: 0}\neffects: []\n");
  std::string csv = "t,q_knee,tau_knee,cmd_knee\n";
  for (int i = 0; i < 4000; ++i) csv += std::to_string(i * 1e-3) + ",0,0,0\n";
  WriteText(dir + "/rest.csv", csv);
  return {ReadModelFile(dir + "/pendulum.yaml"), ReadMeasuredCsv(dir + "/rest.csv")};
}

// The forward-difference Jacobian column of a constant torque (the offset parameter, a commanded
// torque here) on a pendulum at rest: linearized, I x'' + mgl x = c from rest, so
// dq/dc (tau) = (1 - cos(w tau)) / (I w^2), w^2 = mgl / I, tau the time since the window's restart.
TEST(MotionFit, JacobianOfAConstantTorqueIsThePendulumsClosedForm) {
  const testing::ScopedTempDir tmp("motion_jac");
  const Pendulum p = RestingPendulum(tmp.path());
  DiagnoseOptions opt;
  opt.threads = 2;
  const MotionProblem P(p.params, {&p.data}, opt);
  const int c = P.CandidateIndex("joint_stiffness", "knee");
  ASSERT_GE(c, 0);
  const int off = P.candidates()[static_cast<size_t>(c)].cols[1];  // k q0: the constant torque
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(P.parameters());
  const MotionProblem::Rollout at = P.Simulate(zero, MotionProblem::Part::kBoth);
  ASSERT_TRUE(at.ok);
  const Eigen::MatrixXd J = P.Jacobian(zero, at, {off}, MotionProblem::Part::kBoth);
  const std::vector<size_t>& rows = P.rows(0);
  const size_t m = rows.size();
  ASSERT_GT(m, 3000u);
  const double w = std::sqrt(5.0 / 0.5);
  double worst = 0, peak = 0;
  const std::vector<double>& t = p.data.t();
  // Windows of 0.5 s from each part's first sample (the fit part's at t = 0, the held-out part's at the
  // sample before its first row); a window's last row is the next one's restart.
  const double held_start = t[rows[P.fit_rows(0)] - 1];
  for (size_t k = 0; k < m; ++k) {
    const size_t i = rows[k];
    double tau = std::fmod(t[i] - (k < P.fit_rows(0) ? 0.0 : held_start) + 1e-9, 0.5) - 1e-9;
    if (tau < 1e-6) tau += 0.5;
    const double truth = (1 - std::cos(w * tau)) / (0.5 * w * w);
    worst = std::max(worst, std::abs(J(static_cast<Eigen::Index>(m + k), 0) - truth));
    peak = std::max(peak, truth);
  }
  std::printf("constant-torque column: worst error %.3g of peak %.3g rad/(N m)\n", worst, peak);
  EXPECT_GT(peak, 0.1);
  EXPECT_LT(worst, 0.01 * peak);
  // The hip of a one-joint device is no output (weight 0).
  EXPECT_EQ(P.weight(0), 0.0);
  // The simulation counted in replays of the record: the constructor's two fit-part rollouts (the
  // model given under each of the input's two holds, its chosen one's kept for the weights; no torque
  // fit's twin: no effects of a torque fit here), the rollout at zero and the one Jacobian column,
  // both parts each.
  const double fit_share = static_cast<double>(P.fit_rows(0)) / static_cast<double>(m);
  EXPECT_NEAR(P.ReplaysSimulated(), 2 * fit_share + 2, 1e-12);
}

// Why a torque-fit effect is no candidate (diagnosis.json torque_only[].why) agrees with the candidate
// set: "" exactly for a candidate; an effect the model given already carries, one the plant cannot
// carry, a sensor effect where the commands drive and a hip on a one-joint model each say so.
TEST(MotionFit, WhyAnEffectIsNoCandidateAgreesWithTheCandidates) {
  const testing::ScopedTempDir tmp("motion_why");
  Pendulum p = RestingPendulum(tmp.path());
  Effect stiff;
  stiff.name = "joint_stiffness", stiff.joint = "knee", stiff.value = 1.0, stiff.unit = "N m/rad";
  stiff.fields["q0"] = 0;
  p.params.effects.push_back(stiff);
  DiagnoseOptions opt;
  opt.threads = 2;
  const MotionProblem P(p.params, {&p.data}, opt);
  auto Why = [&](const std::string& name, const std::string& joint, const std::string& axis = "") {
    Effect e;
    e.name = name, e.joint = joint, e.axis = axis, e.value = 1;
    return P.WhyNoCandidate(e);
  };
  for (const char* name : {"coulomb_friction", "viscous_friction", "inertia_error", "backlash", "series_compliance"}) {
    EXPECT_GE(P.CandidateIndex(name, "knee"), 0) << name;
    EXPECT_EQ(Why(name, "knee"), "") << name;
  }
  for (const char* name : {"sensor_offset", "sensor_gain", "sensor_delay"}) {  // the record's reading is all 0
    EXPECT_EQ(P.CandidateIndex(name, "knee"), -1) << name;
    EXPECT_EQ(Why(name, "knee"), "the commands drive the plant: no torque reading to correct") << name;
  }
  EXPECT_EQ(P.CandidateIndex("joint_stiffness", "knee"), -1);
  EXPECT_EQ(Why("joint_stiffness", "knee"), "the model given already carries a joint_stiffness at the knee: no candidate");
  EXPECT_EQ(Why("muscle_activity", "knee"), "not carried by the forward plant");
  EXPECT_EQ(Why("coulomb_friction", "hip"), "a one-joint model has no hip");
  EXPECT_EQ(Why("passive_moment", "knee"), "no passive moment in this model (a two-joint model with a human carries it)");
}

// Output weights per record (motion_fit.h): two records of the pendulum swinging freely from 0.01 and
// 0.05 rad with a viscous damping b = 0.5 N m s/rad the model given lacks (the small-angle closed form
// q = A exp(-b t / 2I) cos(w_d t), w_d^2 = mgl / I - (b / 2I)^2). Each record's weight is 1 / its own
// misfit level on the fit part, the lower RMS simulated-angle error of the model given and of the model
// with the torque fit's effects (here the damping: the lower one), recomputed from the two rollouts;
// without a torque fit, the model given's. The pooled weight the same over both records, and Sse the
// sum of the records' weighted squares.
TEST(MotionFit, EachRecordIsWeightedByItsOwnMisfit) {
  const testing::ScopedTempDir tmp("motion_weights");
  const Pendulum p = RestingPendulum(tmp.path());
  const double I = 0.5, mgl = 5.0, b = 0.5, decay = b / (2 * I), wd = std::sqrt(mgl / I - decay * decay);
  std::vector<MeasuredData> data;
  for (const double a : {0.01, 0.05}) {
    std::string csv = "t,q_knee,tau_knee,cmd_knee\n";
    for (int i = 0; i < 4000; ++i) {
      const double t = i * 1e-3;
      csv += std::to_string(t) + "," + std::to_string(a * std::exp(-decay * t) * std::cos(wd * t)) + ",0,0\n";
    }
    const std::string path = tmp.path() + "/swing" + std::to_string(data.size()) + ".csv";
    WriteText(path, csv);
    data.push_back(ReadMeasuredCsv(path));
  }
  DiagnoseOptions opt;
  opt.threads = 2;
  DiagnosedEffect damping;
  damping.effect.name = "viscous_friction", damping.effect.joint = "knee", damping.effect.value = b;
  damping.effect.unit = "N m s/rad";
  for (const bool with_torque_fit : {false, true}) {
    SCOPED_TRACE(with_torque_fit ? "with the torque fit's damping" : "the model given alone");
    MotionProblem P(p.params, {&data[0], &data[1]}, opt,
                    with_torque_fit ? std::vector<DiagnosedEffect>{damping} : std::vector<DiagnosedEffect>{});
    Eigen::VectorXd x = Eigen::VectorXd::Zero(P.parameters());
    const MotionProblem::Rollout given = P.Simulate(x, MotionProblem::Part::kFit);
    const int c = P.CandidateIndex("viscous_friction", "knee");
    ASSERT_GE(c, 0);
    const int kc = P.candidates()[static_cast<size_t>(c)].cols[0];
    ASSERT_LT(b, P.upper(kc));  // inside its range (DESIGN.md), as the torque fit's values are taken
    x[kc] = b;
    const MotionProblem::Rollout damped = P.Simulate(x, MotionProblem::Part::kFit);
    ASSERT_TRUE(given.ok && damped.ok);
    double pooled[2] = {0, 0}, rows = 0, sse = 0, rms[2], damped_sse[2];
    for (size_t r = 0; r < 2; ++r) {
      const size_t m = P.rows(r).size(), mf = P.fit_rows(r);
      double e[2] = {0, 0};
      for (size_t k = 0; k < mf; ++k) {
        const Eigen::Index i = static_cast<Eigen::Index>(m + k);
        e[0] += std::pow(P.measured(r)[i] - given.q[r][i], 2);
        e[1] += std::pow(P.measured(r)[i] - damped.q[r][i], 2);
      }
      EXPECT_LT(e[1], 0.1 * e[0]);  // the damped twin follows the swing
      damped_sse[r] = e[1];
      const double level = with_torque_fit ? std::min(e[0], e[1]) : e[0];
      rms[r] = std::sqrt(level / static_cast<double>(mf));
      EXPECT_NEAR(P.weight(r, 1), 1 / rms[r], 1e-9 / rms[r]);
      EXPECT_EQ(P.weight(r, 0), 0.0);  // the held hip of a one-joint device
      pooled[0] += e[0], pooled[1] += e[1], rows += static_cast<double>(mf), sse += e[0] / (rms[r] * rms[r]);
    }
    EXPECT_GT(rms[1], 3 * rms[0]);  // the records' misfits differ, so the weights do
    const double level = with_torque_fit ? std::min(pooled[0], pooled[1]) : pooled[0];
    EXPECT_NEAR(P.weight(1), 1 / std::sqrt(level / rows), 1e-9 * P.weight(1));
    double s[2];
    P.Sse(given, MotionProblem::Part::kFit, s);
    EXPECT_EQ(s[0], 0.0);
    EXPECT_NEAR(s[1], sse, 1e-9 * sse);
    // WeightBy (the final values' weights, motion_fit.h step 7): 1 / the damped twin's own RMS error
    // per record, pooled likewise; the held hip stays 0.
    P.WeightBy(damped);
    for (size_t r = 0; r < 2; ++r) {
      const double level = std::sqrt(damped_sse[r] / static_cast<double>(P.fit_rows(r)));
      EXPECT_NEAR(P.weight(r, 1), 1 / level, 1e-9 / level);
      EXPECT_EQ(P.weight(r, 0), 0.0);
    }
    EXPECT_NEAR(P.weight(1), 1 / std::sqrt(pooled[1] / rows), 1e-9 * P.weight(1));
    EXPECT_EQ(P.weight(0), 0.0);
  }
}

// Bad input: --fit other than torque|motion; a record with neither a torque reading nor commands; a
// record whose held-out part is shorter than a window. Exit 2, naming what and what was expected.
TEST(MotionFit, BadInputIsExit2NamingTheFileAndWhatWasExpected) {
  const testing::ScopedTempDir tmp("motion_bad");
  const std::string d = tmp.path();
  Pendulum p = RestingPendulum(d);
  auto r = RunExotwin("diagnose --params " + d + "/pendulum.yaml --measured " + d + "/rest.csv --fit speed --out " + d + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--fit: 'speed', expected torque or motion"), std::string::npos) << r.output;
  std::string csv = "t,q_knee,tau_knee\n";
  for (int i = 0; i < 4000; ++i) csv += std::to_string(i * 1e-3) + "," + std::to_string(0.1 * std::sin(i * 1e-3)) + ",0\n";
  WriteText(d + "/no_input.csv", csv);
  r = RunExotwin("diagnose --params " + d + "/pendulum.yaml --measured " + d + "/no_input.csv --fit motion --out " + d + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no_input.csv: the motion fit needs the actuator torque"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("expected either"), std::string::npos) << r.output;
  csv = "t,q_knee,tau_knee,cmd_knee\n";
  for (int i = 0; i < 1200; ++i) csv += std::to_string(i * 1e-3) + ",0,0,0\n";
  WriteText(d + "/short.csv", csv);
  r = RunExotwin("diagnose --params " + d + "/pendulum.yaml --measured " + d + "/short.csv --fit motion --out " + d + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("short.csv: the motion fit's windows of 0.5 s do not fit the record"), std::string::npos)
      << r.output;
  // Knocks throughout: every 200 ms, 80 ms at rest then 120 ms of a 10 mrad jitter; the quiet
  // stretches (the rest less the fast content's 20 ms span at either end) are 40 ms, below the 0.1 s a
  // window needs (replay.h).
  csv = "t,q_knee,tau_knee,cmd_knee\n";
  for (int i = 0; i < 4000; ++i) {
    const double q = i % 200 < 80 ? 0.0 : 0.01 * std::sin(static_cast<double>((i * 7919) % 104729));
    csv += std::to_string(i * 1e-3) + "," + std::to_string(q) + ",0,0\n";
  }
  WriteText(d + "/knocks.csv", csv);
  r = RunExotwin("diagnose --params " + d + "/pendulum.yaml --measured " + d + "/knocks.csv --fit motion --out " + d + "/o");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("knocks.csv: the motion fit's windows of 0.5 s find no quiet stretch of at least 0.1 s"),
            std::string::npos)
      << r.output;
  // The same through the API.
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  const MeasuredData shrt = ReadMeasuredCsv(d + "/short.csv");
  EXPECT_THROW(Diagnose(p.params, shrt, opt), InputError);
}

// 15 s of the shipped gait (subject `preset`, closed loop) on a plant holding `effects`, with the YAML
// lines `extra` added to the scenario, into dir/measured.csv.
MeasuredData GaitRecord(const std::string& effects, const std::string& dir, double duration = 15,
                        const std::string& preset = "S1", const std::string& extra = "") {
  std::ifstream in(kSrc + "/scenarios/gait_2kmh.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "duration: 60";
  text.replace(text.find(key), key.size(), "duration: " + std::to_string(duration));
  text.replace(text.find("preset: S1"), 10, "preset: " + preset);
  text += extra;
  if (!effects.empty()) text += "plant: {effects: " + effects + "}\n";
  WriteText(dir + "/s.yaml", text);
  const auto r = RunExotwin("run " + dir + "/s.yaml --out " + dir + "/run");
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.output;
  return ReadMeasuredCsv(dir + "/run/measured.csv");
}

Diagnosis MotionFit(const MeasuredData& data) {
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  opt.threads = 2;
  return Diagnose(ReadModelFile(kSrc + "/examples/S1.yaml"), data, opt);
}

void Print(const std::string& what, const Diagnosis& d) {
  std::printf("%s:", what.c_str());
  for (const auto& e : d.effects)
    std::printf(" %s(%s) = %.4g %s [%.4g, %.4g];", e.effect.name.c_str(), e.effect.joint.c_str(), e.effect.value,
                e.effect.unit.c_str(), e.ci_lo, e.ci_hi);
  std::printf(" | torque fit:");
  for (const auto& e : d.torque_named)
    std::printf(" %s(%s) = %.4g;", e.effect.name.c_str(), e.effect.joint.c_str(), e.effect.value);
  std::printf(" | held-out sim knee %.4f -> %.4f deg\n", d.joints[1].rmse_before * 180 / M_PI,
              d.joints[1].rmse_after * 180 / M_PI);
}

// Every effect of `truth` named within `tolerance` (relative) and nothing else.
void ExpectNamed(const Diagnosis& d, const std::vector<Effect>& truth, double tolerance) {
  EXPECT_EQ(d.effects.size(), truth.size());
  for (const Effect& t : truth) {
    const DiagnosedEffect* f = nullptr;
    for (const auto& e : d.effects)
      if (e.effect.name == t.name && e.effect.joint == t.joint) f = &e;
    ASSERT_NE(f, nullptr) << t.name << " (" << t.joint << ") not named";
    EXPECT_NEAR(f->effect.value, t.value, tolerance * t.value) << t.name;
  }
}

Effect E(const std::string& name, const std::string& joint, double value) {
  Effect e;
  e.name = name, e.joint = joint, e.value = value;
  return e;
}

// Every effect the torque fit names and the motion fit does not is listed as torque only.
void ExpectTorqueOnlyListed(const Diagnosis& d) {
  for (const auto& t : d.torque_named) {
    bool named = false, listed = false;
    for (const auto& e : d.effects) named = named || (e.effect.name == t.effect.name && e.effect.joint == t.effect.joint);
    for (const auto& o : d.torque_only) listed = listed || (o.effect.name == t.effect.name && o.effect.joint == t.effect.joint);
    EXPECT_NE(named, listed) << t.effect.name << " (" << t.effect.joint << ")";
  }
}

TEST(MotionFit, HiddenKneeBacklashIsNamed) {
  const testing::ScopedTempDir tmp("motion_backlash");
  const Diagnosis d = MotionFit(GaitRecord("[{name: backlash, joint: knee, value: 0.02}]", tmp.path()));
  Print("knee backlash 0.02 rad", d);
  ExpectNamed(d, {E("backlash", "knee", 0.02)}, 0.2);
  EXPECT_EQ(d.fit, DiagnoseFit::kMotion);
  const std::string json = DiagnosisJson(d);
  EXPECT_NE(json.find("\"fit\": \"motion\""), std::string::npos);
  EXPECT_NE(json.find("\"torque_only\""), std::string::npos);
  ExpectTorqueOnlyListed(d);
  // The extended twin follows the held-out motion closer than the rigid one.
  EXPECT_LT(d.simulation.split[1].rmse_after, 0.5 * d.simulation.split[1].rmse_before);
}

// The record dir/run/measured.csv without its first `seconds` (comments and header kept): its
// windows restart at other phases of the gait (stride 2 s, windows 0.5 s).
MeasuredData CutStart(const std::string& dir, double seconds) {
  std::ifstream in(dir + "/run/measured.csv");
  std::string line, out;
  bool header = false;
  double t0 = std::nan("");
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || !header) {
      header = header || (!line.empty() && line[0] != '#');
      out += line + "\n";
      continue;
    }
    const double t = std::stod(line.substr(0, line.find(',')));
    if (std::isnan(t0)) t0 = t;
    if (t - t0 >= seconds - 1e-9) out += line + "\n";
  }
  WriteText(dir + "/cut.csv", out);
  return ReadMeasuredCsv(dir + "/cut.csv");
}

// The widest hip dead band of issue 41's table, where the band's knocks are hardest: windows every
// 0.5 s that restart or run through one are chaotic for any model, so which gait phases the windows
// restarted at decided whether it was named (0.02787 with a knee strap beside it from the record's
// start, an inertia error and a viscous friction instead with the first 0.25 s cut). In quiet
// windows (replay.h) it is named alone within 20 % either way (measured: 0.02989 / 0.02993 rad).
TEST(MotionFit, HiddenHipBacklashOf30MilliradIsNamedWhereverTheWindowsRestart) {
  const testing::ScopedTempDir tmp("motion_hip_backlash_03");
  const MeasuredData whole = GaitRecord("[{name: backlash, joint: hip, value: 0.03}]", tmp.path(), 60);
  const Diagnosis d = MotionFit(whole);
  Print("hip backlash 0.03 rad", d);
  ExpectNamed(d, {E("backlash", "hip", 0.03)}, 0.2);
  const Diagnosis cut = MotionFit(CutStart(tmp.path(), 0.25));
  Print("hip backlash 0.03 rad, the first 0.25 s cut", cut);
  ExpectNamed(cut, {E("backlash", "hip", 0.03)}, 0.2);
}

// A 5 mrad knee band on the 60 s gait (issue 41's table): the band barely moves the hip, whose first
// weight (1 / the given twin's misfit, 0.56 mrad against the knee's 2.5) is the larger, and the hip's
// weighted error rises with the band: the set's refinement under those weights ends at 3.7 mrad (-26 %),
// the knee's own minimum lies at 4.3-4.4. The final values are refined with the extended twin's own
// levels (hip 0.45, knee 0.77 mrad): 4.1 mrad.
TEST(MotionFit, HiddenKneeBacklashOf5MilliradIsSizedWithTheExtendedTwinsWeights) {
  const testing::ScopedTempDir tmp("motion_backlash_5mrad");
  const Diagnosis d = MotionFit(GaitRecord("[{name: backlash, joint: knee, value: 0.005}]", tmp.path(), 60));
  Print("knee backlash 0.005 rad", d);
  ExpectNamed(d, {E("backlash", "knee", 0.005)}, 0.2);
  bool reweighted = false;
  for (const std::string& line : d.selection)
    reweighted = reweighted || line.find("values refined with the extended twin's misfit") != std::string::npos;
  EXPECT_TRUE(reweighted);
  EXPECT_LT(d.noise[1], 1e-3);  // the final weights: the extended twin's knee level, rad
}

// A wider hip dead band on the same 60 s gait: a later round chose a knee strap beside it whose linear
// value the plant cannot simulate (too stiff for the step); that round refines from the set's current
// values instead (motion_fit.h step 4), where it named nothing before.
TEST(MotionFit, HiddenHipBacklashOf20MilliradIsNamedAlone) {
  const testing::ScopedTempDir tmp("motion_hip_backlash_02");
  const Diagnosis d = MotionFit(GaitRecord("[{name: backlash, joint: hip, value: 0.02}]", tmp.path(), 60));
  Print("hip backlash 0.02 rad", d);
  ExpectNamed(d, {E("backlash", "hip", 0.02)}, 0.2);
}

// A knee strap between the exoskeleton and the human's shank (Table 5's 1100 N m/rad is in the bench
// script; 600 here).
TEST(MotionFit, HiddenKneeStrapWithAHumanIsNamed) {
  const testing::ScopedTempDir tmp("motion_strap");
  const Diagnosis d = MotionFit(GaitRecord("[{name: series_compliance, joint: knee, value: 600}]", tmp.path()));
  Print("knee strap 600 N m/rad", d);
  // The strap alone and within 25 % (issue 41's band): each window's strap starts with the deflection
  // and rate of the measured motion (replay's run-in, diagnosis/replay.h); started at rest at its
  // quasi-static deflection it rings, and a knee inertia_error (~0.005 kg m^2) stands in for that.
  ExpectNamed(d, {E("series_compliance", "knee", 600)}, 0.25);
  ExpectTorqueOnlyListed(d);
  // The selection's refinements say the strap as it is named: its stiffness in N m/rad (the fit's
  // parameter is the compliance 1 / k, ~1.7e-3 rad/(N m) here).
  std::string refined;
  for (const std::string& line : d.selection)
    if (line.find("refined on the plant") != std::string::npos) refined = line;
  const std::string key = "series_compliance(knee) = ";
  const size_t at = refined.find(key);
  ASSERT_NE(at, std::string::npos) << refined;
  EXPECT_NEAR(std::stod(refined.substr(at + key.size())), 600, 0.25 * 600) << refined;
  EXPECT_NE(refined.find(" N m/rad", at), std::string::npos) << refined;
}

// The strap does not depend on where in the gait the windows restart (its record is quiet throughout:
// the every-0.5 s windows, DESIGN.md "The motion fit"): the same record with its first 0.25 s cut
// (every window restarts 0.25 s later in the stride) names it alone within 25 %.
TEST(MotionFit, HiddenKneeStrapIsNamedWhereverTheWindowsRestart) {
  const testing::ScopedTempDir tmp("motion_strap_phase");
  GaitRecord("[{name: series_compliance, joint: knee, value: 600}]", tmp.path());
  const MeasuredData cut = CutStart(tmp.path(), 0.25);
  ASSERT_NEAR(cut.t().front(), 0.251, 1e-9);
  const Diagnosis d = MotionFit(cut);
  Print("knee strap 600 N m/rad, the first 0.25 s cut", d);
  ExpectNamed(d, {E("series_compliance", "knee", 600)}, 0.25);
}

TEST(MotionFit, HiddenKneeSensorDelayIsNamed) {
  const testing::ScopedTempDir tmp("motion_delay");
  const Diagnosis d = MotionFit(GaitRecord("[{name: sensor_delay, joint: knee, value: 0.005}]", tmp.path()));
  Print("knee sensor delay 5 ms", d);
  ExpectNamed(d, {E("sensor_delay", "knee", 0.005)}, 0.2);
}

TEST(MotionFit, KneeBacklashAndCoulombFrictionAreBothNamed) {
  const testing::ScopedTempDir tmp("motion_pair");
  const Diagnosis d = MotionFit(GaitRecord(
      "[{name: backlash, joint: knee, value: 0.02}, {name: coulomb_friction, joint: knee, value: 2.0}]", tmp.path()));
  Print("knee backlash 0.02 rad + Coulomb 2 N m", d);
  ExpectNamed(d, {E("backlash", "knee", 0.02), E("coulomb_friction", "knee", 2.0)}, 0.25);
}

// Table 5's human side (data/plants/human_side.yaml, subject S2 with its passive-moment draw of seed 1)
// on the relaxed gait, the rigid parameters and the device's sensor calibration given: the strap, the
// leg's damping at both joints and the subject's passive moments are to be found, and nothing else.
// Forward selection linearized at the model given stops at a knee joint_stiffness in the strap's place
// and a hip Coulomb friction in the hip damping's; the later rounds (linearized at their refined
// values), the choice among the rounds' sets and the exchanges (motion_fit.h step 5) reach the
// plant's five.
TEST(MotionFit, HumanSideStrapDampingAndPassiveMomentsAreNamed) {
  const testing::ScopedTempDir tmp("motion_exchange");
  const std::string sensor =
      "{name: sensor_offset, joint: hip, value: 0.12}, {name: sensor_gain, joint: hip, value: 0.005}, "
      "{name: sensor_offset, joint: knee, value: -0.12}, {name: sensor_gain, joint: knee, value: -0.005}";
  const MeasuredData record = GaitRecord(
      "[{name: viscous_friction, joint: hip, value: 0.2}, {name: viscous_friction, joint: knee, value: 0.1}, "
      "{name: series_compliance, joint: knee, value: 1100}, {name: passive_moment, joint: hip, value: -0.288}, "
      "{name: passive_moment, joint: knee, value: 0.104}, " + sensor + "]",
      tmp.path(), 22.2, "S2", "human: {behaviour: relaxed}\n");
  LegParams given = SubjectLegParams(PresetSubject("S2"));  // the scenario's subject
  given.passive = PassiveModel::kRiener1999;
  given.effects = {E("sensor_offset", "hip", 0.12), E("sensor_gain", "hip", 0.005), E("sensor_offset", "knee", -0.12),
                   E("sensor_gain", "knee", -0.005)};
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  opt.threads = 2;
  const Diagnosis d = Diagnose(given, record, opt);
  Print("S2's human side", d);
  for (const auto& s : d.selection)
    if (s.find("chosen") != std::string::npos || s.find("exchange") != std::string::npos ||
        s.find("kept") != std::string::npos)
      std::printf("  %s\n", s.c_str());
  std::map<std::string, double> named;
  for (const auto& e : d.effects) named[e.effect.name + "(" + e.effect.joint + ")"] = e.effect.value;
  const std::map<std::string, double> truth = {{"series_compliance(knee)", 1100}, {"passive_moment(hip)", -0.288},
                                               {"passive_moment(knee)", 0.104},   {"viscous_friction(knee)", 0.1},
                                               {"viscous_friction(hip)", 0.2}};
  EXPECT_EQ(named.size(), truth.size());
  for (const auto& t : truth) {
    ASSERT_TRUE(named.count(t.first)) << t.first << " not named";
    EXPECT_NEAR(named[t.first], t.second, 0.25 * std::abs(t.second)) << t.first;
  }
}

// Diagnosis::unexplained of the motion fit (StructureLeft, diagnose_unexplained.h, on the first
// record's held-out simulated angle): a subject's muscles at the knee (a generated record whose torque
// holds muscle activity, which the forward plant cannot carry: no candidate explains the motion the
// reading drives) leave structure there; a clean record of the same generator leaves none.
Diagnosis MotionFitOfGenerated(const std::vector<std::string>& effects, uint64_t seed) {
  GenerateOptions g;
  g.seed = seed;
  g.effects = static_cast<int>(effects.size());
  g.allowed = effects;
  g.joint = "knee";
  g.duration = 20;
  g.rate = 500;
  const LegParams base = ReadModelFile(kSrc + "/examples/S1.yaml");
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  opt.threads = 2;
  const Diagnosis d = Diagnose(base, GenerateMeasured(base, g).data, opt);
  Print(effects.empty() ? "clean record" : effects[0], d);
  for (const auto& u : d.unexplained)
    std::printf("  unexplained at the %s: rms %.4g rad, %.3g Hz, %s\n", u.joint.c_str(), u.rms, u.dominant_hz,
                u.hint.c_str());
  return d;
}

TEST(MotionFit, MuscleActivityIsUnexplainedStructure) {
  const Diagnosis d = MotionFitOfGenerated({"muscle_activity"}, 7);
  bool knee = false;
  for (const auto& u : d.unexplained) knee = knee || u.joint == "knee";
  EXPECT_TRUE(knee);
  bool listed = false;  // and the torque fit's muscle activity is listed as not carried
  for (const auto& o : d.torque_only) listed = listed || (o.effect.name == "muscle_activity" && !o.simulated);
  EXPECT_TRUE(listed);
}

TEST(MotionFit, NothingIsUnexplainedOnACleanRecord) {
  const Diagnosis d = MotionFitOfGenerated({}, 21);
  EXPECT_TRUE(d.effects.empty());
  EXPECT_TRUE(d.unexplained.empty());
}

TEST(MotionFit, NothingIsNamedOnTheRigidPlant) {
  const testing::ScopedTempDir tmp("motion_clean");
  const Diagnosis d = MotionFit(GaitRecord("", tmp.path()));
  Print("rigid plant", d);
  EXPECT_TRUE(d.effects.empty());
}

}  // namespace
}  // namespace exotwin
