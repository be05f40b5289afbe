// One-joint devices in the discrepancy loop (DESIGN.md "One-joint devices"): the one-joint model file
// against HAL-3's plant (sim/hal3_plant.h) and HKS05 eq. 4 in closed form; one-joint records and their
// embedding; hidden effects in HAL-3 twin records of `generate` (singles within 15 %, pairs, nothing on
// clean records); the real simple pendulum's targets (../shared/data, skipped when absent).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "diagnosis/diagnose.h"
#include "diagnosis/generate.h"
#include "diagnosis/predict.h"
#include "tests/diagnosis/hidden_effect_util.h"
#include "core/error.h"
#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "formats/model_file.h"
#include "sim/hal3_plant.h"
#include "sim/plant.h"
#include "tests/temp_dir.h"

namespace exotwin {
namespace {

using testing_hidden::EnvInt;
using testing_hidden::Find;
using testing_hidden::ValueError;

const std::string kSrc = EXOTWIN_SOURCE_DIR;
LegParams Hal3Knee() { return ReadModelFile(kSrc + "/examples/hal3_knee.yaml"); }

TEST(OneJointModel, HalKneeFileHoldsTheHal3PlantsValues) {
  const LegParams p = Hal3Knee();
  ASSERT_TRUE(p.one_joint);
  const Hal3PlantParams h;  // the twin's HAL-3 plant, independent of the file
  EXPECT_NEAR(p.one_joint->device.I, h.hal_I(), 1e-12);
  EXPECT_NEAR(p.one_joint->device.mgl, h.hal_mgl(), 1e-9);
  ASSERT_TRUE(p.one_joint->human);
  EXPECT_NEAR(p.one_joint->device.I + p.one_joint->human->I, h.I(), 1e-12);
  EXPECT_NEAR(p.one_joint->device.mgl + p.one_joint->human->mgl, h.mgl(), 1e-9);
  EXPECT_EQ(p.one_joint->R, h.R);
  EXPECT_EQ(p.one_joint->C, h.C);
  // Written and read back: the same file.
  const LegParams q = ParseModelYaml(ModelToYaml(p), "round trip");
  EXPECT_EQ(ModelToYaml(q), ModelToYaml(p));
  EXPECT_NE(ModelToYaml(p).find("joint: knee"), std::string::npos);
}

// predict (MuJoCo's inverse dynamics of the embedding, plus R and C) against HKS05 eq. 4 in closed
// form: tau_R = I thdd + R thd + C sgn(thd) + mgl sin th.
TEST(OneJointModel, PredictIsHks05Eq4) {
  const LegParams p = Hal3Knee();
  Plant plant(ExowheelMjcfPath(p.human.has_value()));
  plant.SetParams(p);
  Kinematics k;
  for (int i = 0; i < 400; ++i) {
    const double t = 0.005 * i;
    k.t.push_back(t);
    k.q[0].push_back(0), k.qd[0].push_back(0), k.qdd[0].push_back(0);
    k.q[1].push_back(0.4 + 0.7 * std::sin(2.1 * t)), k.qd[1].push_back(1.47 * std::cos(2.1 * t));
    k.qdd[1].push_back(-3.087 * std::sin(2.1 * t) + 2.0 * std::cos(7 * t));
  }
  const Prediction pr = PredictTorque(plant, k);
  const OneJointModel& m = *p.one_joint;
  const double I = m.device.I + m.human->I, mgl = m.device.mgl + m.human->mgl;
  for (size_t i = 0; i < k.t.size(); ++i) {
    const double qd = k.qd[1][i];
    const double want = I * k.qdd[1][i] + m.R * qd + m.C * (qd > 0 ? 1 : qd < 0 ? -1 : 0) + mgl * std::sin(k.q[1][i]);
    ASSERT_NEAR(pr.tau_R[1][i], want, 1e-6 * (1 + std::abs(want))) << "sample " << i;
    ASSERT_NEAR(pr.tau_S[1][i], -want, 1e-6 * (1 + std::abs(want)));
  }
}

TEST(OneJointModel, BadFilesAreRejectedNamingTheKey) {
  auto fails = [](const std::string& yaml, const std::string& what) {
    try {
      ParseModelYaml(yaml, "m.yaml");
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  fails("joint: hip\ndevice: {I: 0.1, mgl: 1}\n", "joint");
  fails("joint: knee\n", "device");
  fails("joint: knee\ndevice: {I: 0.1}\n", "device.mgl");
  fails("joint: knee\ndevice: {I: 0.1, mgl: 1, R: -1}\n", "device.R");
  fails("joint: knee\ndevice: {I: 0.1, mgl: 1}\nL1: 0.4\n", "L1");
  fails("joint: knee\ndevice: {I: 0.1, mgl: 1}\neffects: [{name: backlash, joint: hip, value: 0.01}]\n",
        "effects[0].joint");
}

// A one-joint CSV reads as an embedded record; a record and a model of different joints are bad input.
TEST(OneJointData, RecordsAreEmbeddedAndMustFitTheModel) {
  testing::ScopedTempDir dir("one_joint");
  const std::string one = dir.path() + "/one.csv", two = dir.path() + "/two.csv";
  std::vector<double> t, q, tau, z;
  for (int i = 0; i < 50; ++i) t.push_back(0.01 * i), q.push_back(0.1 * i), tau.push_back(-0.2 * i), z.push_back(0);
  WriteCsv(one, {"t", "q_knee", "tau_knee"}, {&t, &q, &tau});
  WriteCsv(two, {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"}, {&t, &z, &q, &z, &tau});
  const MeasuredData a = ReadMeasuredCsv(one), b = ReadMeasuredCsv(two);
  EXPECT_TRUE(a.one_joint);
  EXPECT_FALSE(b.one_joint);
  EXPECT_EQ(a.q_knee(), q);
  EXPECT_EQ(a.q_hip(), z);
  EXPECT_EQ(TableAsRecorded(a).names, (std::vector<std::string>{"t", "q_knee", "tau_knee"}));
  const LegParams hal = Hal3Knee(), s1 = ReadModelFile(kSrc + "/examples/S1.yaml");
  EXPECT_NO_THROW(CheckRecordFitsModel(hal, "hal3_knee.yaml", a));
  EXPECT_NO_THROW(CheckRecordFitsModel(s1, "S1.yaml", b));
  for (const auto& [params, path, data] :
       {std::tuple{&hal, "hal3_knee.yaml", &b}, std::tuple{&s1, "S1.yaml", &a}}) {
    try {
      CheckRecordFitsModel(*params, path, *data);
      ADD_FAILURE() << path;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_NE(m.find(data->source), std::string::npos) << m;
      EXPECT_NE(m.find("expected"), std::string::npos) << m;
    }
  }
}

GeneratedData Hal3Record(const LegParams& base, uint64_t seed, int effects, const std::vector<std::string>& allowed) {
  GenerateOptions g;
  g.seed = seed;
  g.effects = effects;
  g.allowed = allowed;
  g.duration = 20;
  g.rate = 500;
  return GenerateMeasured(base, g);
}

// The torque analysis alone (the forward replay is checked on the single effects).
DiagnoseOptions TorqueOnly() {
  DiagnoseOptions o;
  o.simulate = false;
  return o;
}

// The motion fit (diagnosis/motion_fit.h) on a one-joint device: HAL-3's R and C are its knee's
// viscous and Coulomb friction effects (model/one_joint.h), and a hidden friction on top of them is
// named on top of them (a candidate although the model carries that effect: the plant sums them) at
// its value within 15 %, alone. Before, neither friction was a candidate and a hidden viscous friction
// of 0.66 N m s/rad was named an inertia error and a 21 ms sensor delay.
TEST(OneJointHiddenEffect, MotionFitNamesAFrictionOnTopOfTheDevicesOwn) {
  const LegParams base = Hal3Knee();
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  for (const std::string name : {"viscous_friction", "coulomb_friction"}) {
    const GeneratedData data = Hal3Record(base, name == "viscous_friction" ? 3 : 5, 1, {name});
    const Effect& truth = data.truth.effects.back();
    const Diagnosis d = Diagnose(base, data.data, opt);
    const DiagnosedEffect* f = Find(d, truth);
    std::printf("%s: truth %.4g, motion fit %.4g\n", name.c_str(), truth.value, f ? f->effect.value : NAN);
    ASSERT_TRUE(f) << name;
    EXPECT_LE(ValueError(truth, f->effect), 0.15) << name;
    EXPECT_EQ(d.effects.size(), 1u) << name;
  }
}

// Every effect of DESIGN.md's table hidden alone in a HAL-3 twin record: named, at its value within
// 15 %, the only one named.
TEST(OneJointHiddenEffect, EverySingleEffectIsNamedAtItsValue) {
  const LegParams base = Hal3Knee();
  std::printf("%-18s %6s %10s %10s %8s\n", "effect", "seed", "truth", "found", "err_%");
  const int seeds = EnvInt("EXOTWIN_ONE_JOINT_SEEDS", 1);
  for (const std::string& name : AllEffectNames()) {
    for (uint64_t seed = 11; seed < 11 + static_cast<uint64_t>(seeds); ++seed) {
      const GeneratedData data = Hal3Record(base, seed + 100 * (&name - &AllEffectNames()[0]), 1, {name});
      ASSERT_TRUE(data.data.one_joint);
      const Effect& truth = data.truth.effects.back();
      EXPECT_EQ(truth.joint, "knee");
      const Diagnosis d = Diagnose(base, data.data);
      const DiagnosedEffect* f = Find(d, truth);
      const double err = f ? ValueError(truth, f->effect) : 1.0;
      std::printf("%-18s %6llu %10.4g %10.4g %7.1f%%\n", name.c_str(), (unsigned long long)seed, truth.value,
                  f ? f->effect.value : NAN, 100 * err);
      EXPECT_TRUE(f) << name << " seed " << seed;
      EXPECT_LE(err, 0.15) << name << " seed " << seed;
      EXPECT_EQ(d.effects.size(), 1u) << name << " seed " << seed;
      EXPECT_GE(d.joints[1].gain_pct, 50) << name << " seed " << seed;
      // The record's ceiling (every candidate fitted on it, in sample) holds at least the effect.
      EXPECT_GE(d.records[0].ceiling[1].gain_pct, 50) << name << " seed " << seed;
      std::printf("%-18s ceiling %.1f %%, null %.1f %%\n", "", d.records[0].ceiling[1].gain_pct,
                  d.records[0].ceiling_null[1].gain_pct);
      // A residual that is a function of the motion (not a constant, not of the angle alone, which
      // the record's near-periodic motion repeats under a shift) stands far above its null ceiling.
      if (name == "coulomb_friction" || name == "viscous_friction" || name == "inertia_error" ||
          name == "torque_ripple" || name == "sensor_delay") {
        EXPECT_GE(d.records[0].ceiling[1].gain_pct - d.records[0].ceiling_null[1].gain_pct, 50) << name;
      }
      EXPECT_EQ(d.records[0].ceiling[0].rmse_before, 0.0);  // the held hip is no data
      // The forward replay of the held-out part (the one-joint plant, its hip held): a hidden friction
      // the extended twin carries is felt in the simulated knee angle; the hip is no data.
      if (name == "coulomb_friction" || name == "viscous_friction") {
        std::printf("%-18s simulated knee %.4f -> %.4f rad (%.1f %%)\n", "", d.simulation.split[1].rmse_before,
                    d.simulation.split[1].rmse_after, d.simulation.split[1].gain_pct);
        EXPECT_TRUE(d.simulation.done) << d.simulation.note;
        EXPECT_GE(d.simulation.split[1].gain_pct, 30) << name << " seed " << seed;
        EXPECT_EQ(d.simulation.split[0].rmse_before, 0.0);
      }
    }
  }
}

TEST(OneJointHiddenEffect, PairsAreNamed) {
  const LegParams base = Hal3Knee();
  int both = 0;
  const int seeds = EnvInt("EXOTWIN_ONE_JOINT_PAIR_SEEDS", 6);
  for (int s = 0; s < seeds; ++s) {
    const GeneratedData data = Hal3Record(base, 500 + s, 2, {});
    const Effect& a = data.truth.effects[data.truth.effects.size() - 2];
    const Effect& b = data.truth.effects.back();
    const Diagnosis d = Diagnose(base, data.data, TorqueOnly());
    const bool ok = Find(d, a) && Find(d, b);
    both += ok;
    std::printf("pair seed %d: %s = %g + %s = %g: found", 500 + s, a.name.c_str(), a.value, b.name.c_str(), b.value);
    for (const auto& e : d.effects) std::printf(" %s = %g", e.effect.name.c_str(), e.effect.value);
    std::printf("\n");
  }
  EXPECT_GE(both * 10, seeds * 8);
}

TEST(OneJointHiddenEffect, NothingIsNamedOnCleanRecords) {
  const LegParams base = Hal3Knee();
  const int seeds = EnvInt("EXOTWIN_ONE_JOINT_CLEAN", 10);
  for (int s = 0; s < seeds; ++s) {
    const Diagnosis d = Diagnose(base, Hal3Record(base, 900 + s, 0, {}).data, TorqueOnly());
    for (const auto& e : d.effects) ADD_FAILURE() << "clean seed " << 900 + s << ": named " << e.effect.name;
  }
}

// Aliases (DiagnosedEffect::aliases). A sensor gain g of a frictionless one-joint device scales its
// torque I qdd + mgl sin q: exactly an inertia correction g I plus a gravity correction g mgl / g0 (the
// columns qdd and g0 sin q), so that pair stands in the gain's place, leaving it nothing. With the
// device's R thd + C sgn(thd) in the twin (HAL-3), the gain's column holds friction too: the pair is
// no longer an alias.
const EffectAlias* AliasOf(const DiagnosedEffect& e, const std::vector<std::string>& names) {
  for (const EffectAlias& a : e.aliases) {
    std::vector<std::string> got;
    for (const Effect& f : a.effects) got.push_back(f.name + (f.axis.empty() ? "" : "." + f.axis));
    if (got == names) return &a;
  }
  return nullptr;
}

GeneratedData GainRecord(const LegParams& base, uint64_t seed) {
  GenerateOptions g;
  g.seed = seed;
  g.effects = 1;
  g.allowed = {"sensor_gain"};
  g.duration = 20;
  g.rate = 500;
  return GenerateMeasured(base, g);
}

TEST(OneJointAliases, AFrictionlessJointsSensorGainIsExactlyAnInertiaAndGravityCorrection) {
  const LegParams base = ReadModelFile(kSrc + "/examples/real_rig/simple_pendulum/model.yaml");
  const GeneratedData data = GainRecord(base, 31);
  const double gain = data.truth.effects.back().value;
  const Diagnosis d = Diagnose(base, data.data, TorqueOnly());
  ASSERT_EQ(d.effects.size(), 1u);
  const DiagnosedEffect& e = d.effects[0];
  ASSERT_EQ(e.effect.name, "sensor_gain");
  for (const EffectAlias& a : e.aliases) std::printf("  sensor_gain %.4g: alias %s\n", gain, AliasText(a).c_str());
  const EffectAlias* a = AliasOf(e, {"inertia_error", "gravity_error.X"});
  ASSERT_TRUE(a);
  EXPECT_LT(a->left_pct, 1e-3);
  EXPECT_GE(a->reach_pct, 99.99);
  EXPECT_TRUE(a->plausible);
  // The closed form: g I and g mgl / g0, within the fit's noise (2 %).
  const OneJointModel& m = *base.one_joint;
  EXPECT_NEAR(a->effects[0].value, gain * m.device.I, 0.02 * std::abs(gain * m.device.I));
  EXPECT_NEAR(a->effects[1].value, gain * m.device.mgl / base.g, 0.02 * std::abs(gain * m.device.mgl / base.g));
  EXPECT_NE(DiagnosisJson(d).find("\"left_pct\""), std::string::npos);
}

TEST(OneJointAliases, WithTheDevicesFrictionInTheTwinTheGainHasNoSuchAlias) {
  const LegParams base = Hal3Knee();
  const GeneratedData data = GainRecord(base, 31);
  const Diagnosis d = Diagnose(base, data.data, TorqueOnly());
  ASSERT_EQ(d.effects.size(), 1u);
  ASSERT_EQ(d.effects[0].effect.name, "sensor_gain");
  for (const EffectAlias& a : d.effects[0].aliases) std::printf("  alias %s\n", AliasText(a).c_str());
  EXPECT_FALSE(AliasOf(d.effects[0], {"inertia_error", "gravity_error.X"}));
}

// The real simple pendulum (shared/data/real_rig/dfki_simple_pendulum, README there) against the
// makers' nominal point mass (examples/real_rig/simple_pendulum/model.yaml: I 0.169 kg m^2, mgl
// 3.31 N m, no friction). The README's careful fit: I 0.177, Coulomb 0.15, viscous 0.002, mgl 3.53.
const std::string kPend = kSrc + "/../shared/data/real_rig/dfki_simple_pendulum/";
const std::string kPendEx = kSrc + "/examples/real_rig/simple_pendulum/";

MeasuredData Pendulum(const std::string& name) {
  return ReadMeasured(kPend + name + ".csv", kPendEx + "dfki_simple_pendulum.map.yaml");
}

void PrintDiagnosis(const char* title, const Diagnosis& d) {
  std::printf("%s\n", title);
  for (const auto& e : d.effects)
    std::printf("  %s%s = %.5g %s [%.5g, %.5g], explains %.1f %%\n", e.effect.name.c_str(),
                e.effect.axis.empty() ? "" : ("." + e.effect.axis).c_str(), e.effect.value, e.effect.unit.c_str(),
                e.ci_lo, e.ci_hi, e.explained_pct);
  for (const auto& r : d.records)
    std::printf("  %s: held-out %.4f -> %.4f N m (%.1f %%), left out %.4f -> %.4f N m (%.1f %%)\n", r.source.c_str(),
                r.split[1].rmse_before, r.split[1].rmse_after, r.split[1].gain_pct, r.left_out[1].rmse_before,
                r.left_out[1].rmse_after, r.left_out[1].gain_pct);
  for (const auto& s : d.implausible) std::printf("  implausible: %s\n", s.c_str());
  for (const auto& s : d.not_identifiable) std::printf("  not identifiable: %s\n", s.c_str());
  if (std::getenv("EXOTWIN_ONE_JOINT_VERBOSE")) {
    std::printf("  cutoff: %s\n", d.cutoff.why.c_str());
    for (const auto& s : d.selection) std::printf("  step: %s\n", s.c_str());
    for (const auto& s : d.scores)
      std::printf("  candidate %s: dBIC %.1f, held-out gain %.1f %%\n", s.label.c_str(), s.delta_bic, s.heldout_gain_pct);
  }
}

TEST(OneJointRealRig, PendulumDynamicRecordsNameCoulombFrictionInItsRange) {
  if (!std::filesystem::exists(kPend)) GTEST_SKIP() << kPend << " absent";
  const char* model_env = std::getenv("EXOTWIN_ONE_JOINT_MODEL");
  const LegParams nominal = ReadModelFile(model_env ? model_env : kPendEx + "model.yaml");
  std::vector<MeasuredData> recs;
  recs.push_back(Pendulum("pd_system_identification"));
  recs.push_back(Pendulum("ddp_swingup"));
  DiagnoseOptions opt;
  if (const char* c = std::getenv("EXOTWIN_ONE_JOINT_CUTOFF")) opt.cutoff_hz = std::atof(c);
  const Diagnosis d = Diagnose(nominal, std::move(recs), opt);
  PrintDiagnosis("pd_system_identification + ddp_swingup:", d);
  const DiagnosedEffect* coulomb = nullptr;
  double I = nominal.one_joint->device.I, mgl = nominal.one_joint->device.mgl;
  for (const auto& e : d.effects) {
    if (e.effect.name == "coulomb_friction") coulomb = &e;
    if (e.effect.name == "inertia_error") I += e.effect.value;
    if (e.effect.name == "gravity_error" && e.effect.axis == "X") mgl += nominal.g * e.effect.value;
  }
  ASSERT_TRUE(coulomb);
  EXPECT_GE(coulomb->effect.value, 0.08);
  EXPECT_LE(coulomb->effect.value, 0.25);
  // A mass correction, when named, goes toward the reference fit (not away from it).
  EXPECT_LE(std::abs(I - 0.177), std::abs(0.168875 - 0.177) + 1e-9) << "I " << I;
  EXPECT_LE(std::abs(mgl - 3.53), std::abs(3.3133 - 3.53) + 1e-9) << "mgl " << mgl;
  // ddp_swingup's whole record, predicted by what pd_system_identification alone supports, gains
  // >= 25 %.
  ASSERT_EQ(d.records.size(), 2u);
  EXPECT_GE(d.records[1].left_out[1].gain_pct, 25) << d.records[1].source;
  // pd_system_identification's whole record cannot gain 25 % from any effects fitted elsewhere: every
  // candidate at once, fitted on it alone with the signs the ranges allow, removes 20.6 % of its
  // error (measured; the reference fit loses 3.6 %). Its torque is the stiff position controller's
  // current, chattering (above 20 Hz: 2.1 N m rms against 0.25 on ddp_swingup; spikes of 17 N m)
  // and sampled at 300 Hz: what leaks into the 4 Hz band is not in the motion.
  for (const RecordScore& r : d.records) {
    std::printf("  %s: ceiling %.4f -> %.4f N m (%.1f %%)\n", r.source.c_str(), r.ceiling[1].rmse_before,
                r.ceiling[1].rmse_after, r.ceiling[1].gain_pct);
    EXPECT_NEAR(r.ceiling[1].rmse_before, r.left_out[1].rmse_before, 0.01 * r.left_out[1].rmse_before);
    EXPECT_GE(r.ceiling[1].gain_pct, r.left_out[1].gain_pct) << r.source;
  }
  EXPECT_LT(d.records[0].ceiling[1].gain_pct, 25) << d.records[0].source;
  // And most of that bound is what the same fit reaches on the record's residual shifted in time (no
  // function of the motion): 16.5 % (measured); ddp_swingup's 78.5 % stands on a null of 36 %.
  for (const RecordScore& r : d.records)
    std::printf("  %s: null ceiling %.1f %%\n", r.source.c_str(), r.ceiling_null[1].gain_pct);
  EXPECT_LT(d.records[0].ceiling[1].gain_pct - d.records[0].ceiling_null[1].gain_pct, 6) << d.records[0].source;
  EXPECT_GT(d.records[1].ceiling[1].gain_pct - d.records[1].ceiling_null[1].gain_pct, 30) << d.records[1].source;
  // The named Coulomb friction has no alias: nothing else stands in its place.
  EXPECT_TRUE(coulomb->aliases.empty());
}

TEST(OneJointRealRig, GravityCompensationNamesNoInertia) {
  if (!std::filesystem::exists(kPend)) GTEST_SKIP() << kPend << " absent";
  const LegParams nominal = ReadModelFile(kPendEx + "model.yaml");
  const Diagnosis d = Diagnose(nominal, Pendulum("gravity_compensation"));
  PrintDiagnosis("gravity_compensation:", d);
  // The motor's torque is the controller's gravity compensation, the hand's is not measured: the
  // inertia is not in the record. It is not named; its fit (-100 % of the twin's) is listed as
  // implausible.
  for (const auto& e : d.effects) EXPECT_NE(e.effect.name, "inertia_error");
  bool listed = false;
  for (const auto& s : d.implausible) listed = listed || s.rfind("inertia_error(knee)", 0) == 0;
  for (const auto& s : d.not_identifiable) listed = listed || s.rfind("inertia_error(knee)", 0) == 0;
  EXPECT_TRUE(listed);
}

// ddp_swingup alone: Coulomb friction, and the nominal dynamics' scale. A sensor gain g is a common
// scale of I and mgl (the motor's torque constant, or the point mass m, scales both alike): the twin's
// I (1 + g) and mgl (1 + g) move toward the reference fit.
TEST(OneJointRealRig, DdpSwingupNamesFrictionAndAScaleTowardTheReferenceFit) {
  if (!std::filesystem::exists(kPend)) GTEST_SKIP() << kPend << " absent";
  const LegParams nominal = ReadModelFile(kPendEx + "model.yaml");
  const Diagnosis d = Diagnose(nominal, Pendulum("ddp_swingup"));
  PrintDiagnosis("ddp_swingup:", d);
  double coulomb = 0, gain = 0, dI = 0, dmgl = 0;
  for (const auto& e : d.effects) {
    if (e.effect.name == "coulomb_friction") coulomb = e.effect.value;
    if (e.effect.name == "sensor_gain") gain = e.effect.value;
    if (e.effect.name == "inertia_error") dI = e.effect.value;
    if (e.effect.name == "gravity_error" && e.effect.axis == "X") dmgl = nominal.g * e.effect.value;
  }
  EXPECT_GE(coulomb, 0.08);
  EXPECT_LE(coulomb, 0.25);
  const double I = (0.168875 + dI) * (1 + gain), mgl = (3.3133 + dmgl) * (1 + gain);
  std::printf("  equivalent I %.4f kg m^2, mgl %.4f N m\n", I, mgl);
  EXPECT_LT(std::abs(I - 0.177), std::abs(0.168875 - 0.177));
  EXPECT_LT(std::abs(mgl - 3.53), std::abs(3.3133 - 3.53));
  EXPECT_GE(d.joints[1].gain_pct, 25);
}

}  // namespace
}  // namespace exotwin
