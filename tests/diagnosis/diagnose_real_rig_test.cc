// The discrepancy loop on data no simulation made: the seven system-identification records of a
// real two-link rig (shared/data/real_rig/, DFKI double pendulum design A.0; README there). The rigid
// twin is the makers' identified model (examples/real_rig/model.yaml); what it lacks is friction and
// the rotor inertia. The makers' friction identification gives Coulomb + viscous torque at 1 rad/s of
// cf_i pi/2 + b_i = 0.146 / 0.123 N m (hip / second joint): the independent reference.
// Skipped (with a message) when shared/data is not beside the project.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "formats/column_map.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/motion_fit.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "diagnosis/replay.h"

namespace exotwin {
namespace {

const std::string kDir = std::string(EXOTWIN_SOURCE_DIR) + "/../shared/data/real_rig/dfki_double_pendulum_A0";
const char* kRecords[] = {"trajectory_00", "trajectory_01", "trajectory_02", "trajectory_03",
                          "trajectory_04", "trajectory_05", "trajectory_11"};

// The rig's records through the shipped column map.
std::vector<MeasuredData> ReadRig() {
  std::vector<MeasuredData> out;
  for (const char* r : kRecords)
    out.push_back(ReadMeasured(kDir + "/" + r + ".csv",
                               std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/dfki_double_pendulum_A0.map.yaml"));
  return out;
}

LegParams RigModel() { return ReadModelFile(std::string(EXOTWIN_SOURCE_DIR) + "/examples/real_rig/model.yaml"); }

const Effect* Named(const Diagnosis& d, const std::string& name, const std::string& joint) {
  for (const auto& e : d.effects)
    if (e.effect.name == name && e.effect.joint == joint) return &e.effect;
  return nullptr;
}

void Print(const Diagnosis& d) {
  std::printf("cutoff %.3g Hz: %s\n", d.cutoff.hz, d.cutoff.why.c_str());
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  for (const auto& e : d.effects)
    std::printf("  %-18s %-5s %10.4g %-10s [%.4g, %.4g] explains %.1f %%\n", e.effect.name.c_str(),
                e.effect.joint.c_str(), e.effect.value, e.effect.unit.c_str(), e.ci_lo, e.ci_hi, e.explained_pct);
  for (const auto& s : d.implausible) std::printf("  implausible: %s\n", s.c_str());
  std::printf("  held-out 30 %%: hip %.4f -> %.4f, knee %.4f -> %.4f N m\n", d.joints[0].rmse_before,
              d.joints[0].rmse_after, d.joints[1].rmse_before, d.joints[1].rmse_after);
  if (d.leave_one_out)
    std::printf("  left-out records: hip %.4f -> %.4f (%.1f %%), knee %.4f -> %.4f (%.1f %%) N m\n",
                d.left_out[0].rmse_before, d.left_out[0].rmse_after, d.left_out[0].gain_pct,
                d.left_out[1].rmse_before, d.left_out[1].rmse_after, d.left_out[1].gain_pct);
  for (const auto& r : d.records)
    std::printf("  %s: split hip %.4f -> %.4f knee %.4f -> %.4f | left out hip %.4f -> %.4f knee %.4f -> %.4f\n",
                r.source.substr(r.source.rfind('/') + 1).c_str(), r.split[0].rmse_before, r.split[0].rmse_after,
                r.split[1].rmse_before, r.split[1].rmse_after, r.left_out[0].rmse_before,
                r.left_out[0].rmse_after, r.left_out[1].rmse_before, r.left_out[1].rmse_after);
}

bool HaveData() { return std::ifstream(kDir + "/trajectory_00.csv").good(); }

// The diagnosis of the seven records together (default options), computed once for the tests below.
const Diagnosis& AllSeven() {
  static const Diagnosis d = [] {
    const std::vector<MeasuredData> rig = ReadRig();
    std::vector<const MeasuredData*> recs;
    for (const auto& r : rig) recs.push_back(&r);
    return Diagnose(RigModel(), recs);
  }();
  return d;
}

TEST(DiagnoseRealRig, AllSevenRecordsNameFrictionAtBothJointsAndNothingImplausible) {
  if (!HaveData()) GTEST_SKIP() << kDir << " not found (shared/data beside the project)";
  const Diagnosis& d = AllSeven();
  Print(d);
  const double makers[2] = {0.146, 0.123};  // cf pi/2 + b, N m at 1 rad/s
  const char* joints[2] = {"hip", "knee"};
  for (int j = 0; j < 2; ++j) {
    const Effect* c = Named(d, "coulomb_friction", joints[j]);
    ASSERT_NE(c, nullptr) << joints[j];
    const Effect* v = Named(d, "viscous_friction", joints[j]);
    const double at1 = c->value + (v ? v->value : 0.0);
    EXPECT_NEAR(at1, makers[j], 0.4 * makers[j]) << joints[j];
    // Whole left-out records: at least 25 % less torque error than the rigid twin, filtered alike.
    EXPECT_GE(d.left_out[j].gain_pct, 25.0) << joints[j];
  }
  // Nothing the rig cannot have: no springs, straps or dead band on a quasi-direct-drive rig with
  // rigid links (a current-based torque estimate may read a few % off: sensor_gain is allowed).
  for (const auto& e : d.effects) {
    EXPECT_NE(e.effect.name, "series_compliance");
    EXPECT_NE(e.effect.name, "joint_stiffness");
    EXPECT_NE(e.effect.name, "backlash");
  }
  // The knee's rotor inertia gr^2 Ir = 36 * 7.66e-5 = 0.00276 kg m^2 (the makers' model), if named.
  if (const Effect* ie = Named(d, "inertia_error", "knee")) {
    EXPECT_NEAR(ie->value, 0.00276, 0.4 * 0.00276);
  }
  // The cutoff: chosen well below the paper's 20 Hz on this 500 Hz rig with a coarse encoder.
  EXPECT_LT(d.cutoff.hz, 20.0);
}

// The twin that learned the rig also moves like it: every record replayed whole (forward MuJoCo
// simulation, restarted from the measured state every 0.5 s) with the effects diagnose fitted on the
// other six; the simulated-angle RMS error, pooled over the records, falls by at least 60 % at both
// joints against the rigid twin. The independent reference: an integrator written apart from the
// project gave 81 % / 89 % on records 00 and 01 (issue 28). 0.25 s and 1 s are printed.
TEST(DiagnoseRealRig, EveryRecordLeftOutMovesLikeTheRigInSimulation) {
  if (!HaveData()) GTEST_SKIP() << kDir << " not found (shared/data beside the project)";
  const Diagnosis& d = AllSeven();
  // diagnose's own block: the records trimmed of the filters' edges (0.5 s), as all its scores.
  ASSERT_TRUE(d.simulation.done) << d.simulation.note;
  EXPECT_EQ(d.simulation.horizon_s, 0.5);
  for (int j = 0; j < 2; ++j) EXPECT_GE(d.simulation.left_out[j].gain_pct, 60.0) << j;
  // The whole records, untrimmed, at three horizons (replay.h, as `exotwin replay` does).
  const std::vector<MeasuredData> rig = ReadRig();
  const LegParams model = RigModel();
  std::printf("record        horizon  hip rigid / extended (deg)  knee rigid / extended (deg)\n");
  for (double h : {0.25, 0.5, 1.0}) {
    ReplayScore before, after;
    for (size_t r = 0; r < rig.size(); ++r) {
      LegParams loo = model;
      loo.effects = d.records[r].left_out_effects;
      ReplayScore s[2];
      for (int k = 0; k < 2; ++k) {
        const LegParams& p = k == 0 ? model : loo;
        PlantEffects fx;
        const std::unique_ptr<Plant> plant = MakeReplayPlant(p, "test", "", &fx);
        s[k] = Replay(*plant, ReplaySeriesOf(rig[r], fx, ReplayInput::kTorque, kReplayCutoffHz), h).score;
      }
      before.Add(s[0]), after.Add(s[1]);
      std::printf("%s  %4.2f s   %6.2f / %5.2f               %6.2f / %5.2f\n", kRecords[r], h, s[0].Rmse(0) * 180 / M_PI,
                  s[1].Rmse(0) * 180 / M_PI, s[0].Rmse(1) * 180 / M_PI, s[1].Rmse(1) * 180 / M_PI);
    }
    std::printf("pooled         %4.2f s   %6.2f / %5.2f (%.0f %%)       %6.2f / %5.2f (%.0f %%)\n", h,
                before.Rmse(0) * 180 / M_PI, after.Rmse(0) * 180 / M_PI, 100 * (1 - after.Rmse(0) / before.Rmse(0)),
                before.Rmse(1) * 180 / M_PI, after.Rmse(1) * 180 / M_PI, 100 * (1 - after.Rmse(1) / before.Rmse(1)));
    for (int j = 0; j < 2; ++j) {
      EXPECT_LT(after.Rmse(j), before.Rmse(j)) << h << " s, joint " << j;
      if (h == 0.5) {
        EXPECT_GE(100 * (1 - after.Rmse(j) / before.Rmse(j)), 60.0) << "joint " << j;
      }
    }
  }
}

TEST(DiagnoseRealRig, EveryRecordAloneNamesNothingImplausible) {
  if (!HaveData()) GTEST_SKIP() << kDir << " not found (shared/data beside the project)";
  const LegParams model = RigModel();
  for (const MeasuredData& r : ReadRig()) {
    const Diagnosis d = Diagnose(model, r);
    std::printf("%s\n", r.source.c_str());
    Print(d);
    for (const auto& e : d.effects) {
      EXPECT_NE(e.effect.name, "series_compliance") << r.source;
      EXPECT_NE(e.effect.name, "backlash") << r.source;
      if (e.effect.name == "coulomb_friction") {
        EXPECT_LT(e.effect.value, 0.3) << r.source;
      }
    }
  }
}

// The motion fit (diagnose --fit motion) on each record alone. Never worse than the torque fit's twin on
// the same rows (issue 64, motion_fit.h step 6b): every record's extended twin replays its held-out
// part within 1.05x the torque fit's twin at both joints, or says why. Coulomb friction, not viscous in
// its place, at both joints (issue 41), each value's spread across resamples (effects[].spread: the
// block bootstrap's sd and the values with each fifth of the fit rows left out) within +-35 % of the
// value of the seven records pooled (the torque fit's, AllSeven: every record's rows at once), and
// inside the makers' scale. Each record's held-out part is 3 s. Measured: Coulomb at both joints on 5
// of 7 (hip / knee 0.163 / 0.161, 0.163 / 0.132, 0.150 / 0.134, 0.169 / 0.144, 0.145 / 0.163 N m),
// each spread inside +-35 %; record 04 names the torque fit's knee Coulomb and rotor inertia, its hip
// Coulomb removed by the held-out gate (without it the hip replays 5.5 % better); record 05 the torque
// fit's viscous hip friction (its hip Coulomb, the motion fit's own, replays the hip 1.12x the torque
// fit's twin, and added to the viscous at its value refines to zero). Before step 6b: 6 of 7 with
// Coulomb at both joints, 6 of 7 records worse than 1.05x the torque fit's twin (hip 1.11-1.60x,
// record 03's knee 1.41x).
TEST(DiagnoseRealRig, MotionFitOfEachRecordAloneIsNeverWorseThanTheTorqueFitsTwinAndItsCoulombIsStable) {
  if (!HaveData()) GTEST_SKIP() << kDir << " not found (shared/data beside the project)";
  const LegParams model = RigModel();
  const Effect* pooled[2] = {Named(AllSeven(), "coulomb_friction", "hip"), Named(AllSeven(), "coulomb_friction", "knee")};
  ASSERT_TRUE(pooled[0] && pooled[1]);
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  int both = 0, stable = 0;
  for (const MeasuredData& r : ReadRig()) {
    const Diagnosis d = Diagnose(model, {&r}, opt);
    std::printf("%s\n", r.source.c_str());
    Print(d);
    const DiagnosedEffect* c[2] = {nullptr, nullptr};
    for (const DiagnosedEffect& e : d.effects)
      for (int j = 0; j < 2; ++j)
        if (e.effect.name == "coulomb_friction" && e.effect.joint == (j == 0 ? "hip" : "knee")) c[j] = &e;
    both += c[0] && c[1];
    bool in = c[0] && c[1];
    for (int j = 0; j < 2; ++j) {
      if (!c[j]) continue;
      const DiagnosedEffect& e = *c[j];
      EXPECT_LT(e.effect.value, 0.3) << r.source;
      ASSERT_TRUE(std::isfinite(e.spread_sd) && std::isfinite(e.spread_lo)) << r.source << " joint " << j;
      const double p = pooled[j]->value, lo = std::min(e.spread_lo, e.effect.value - e.spread_sd),
                   hi = std::max(e.spread_hi, e.effect.value + e.spread_sd);
      std::printf("  coulomb %s %.4f, sd %.4f, fifths left out [%.4f, %.4f]: %.0f-%.0f %% of the pooled %.4f\n",
                  j == 0 ? "hip" : "knee", e.effect.value, e.spread_sd, e.spread_lo, e.spread_hi, 100 * lo / p,
                  100 * hi / p, p);
      EXPECT_GE(lo, 0.65 * p) << r.source << " joint " << j;
      EXPECT_LE(hi, 1.35 * p) << r.source << " joint " << j;
      in = in && lo >= 0.65 * p && hi <= 1.35 * p;
    }
    stable += in;
    ASSERT_TRUE(d.simulation.done) << r.source << ": " << d.simulation.note;
    ASSERT_TRUE(d.simulation.torque_fit_done) << r.source;
    for (int j = 0; j < 2; ++j) {
      EXPECT_LT(d.simulation.split[j].rmse_after, d.simulation.split[j].rmse_before) << r.source << " joint " << j;
      std::printf("  %s: held-out %.3f (motion) / %.3f (torque fit's twin) deg\n", j == 0 ? "hip" : "knee",
                  d.simulation.split[j].rmse_after * 180 / M_PI, d.simulation.torque_fit_split[j].rmse_after * 180 / M_PI);
      EXPECT_LE(d.simulation.split[j].rmse_after, kTorqueTwinTolerance * d.simulation.torque_fit_split[j].rmse_after)
          << r.source << " joint " << j << ": " << d.simulation.torque_fit_why;
    }
    EXPECT_EQ(d.simulation.torque_fit_why.empty(),
              d.simulation.split[0].rmse_after <= kTorqueTwinTolerance * d.simulation.torque_fit_split[0].rmse_after &&
                  d.simulation.split[1].rmse_after <= kTorqueTwinTolerance * d.simulation.torque_fit_split[1].rmse_after);
  }
  std::printf("Coulomb at both joints on %d of 7 records, its spread within +-35 %% of the pooled value on %d\n", both, stable);
  EXPECT_GE(both, 5);
  EXPECT_EQ(stable, both);
}

// The motion fit of several records keeps an effect that moves the records left out, not only the
// held-out ends (motion_fit.h step 6): fitted on six records, record 00 left out, the
// knee's rotor inertia gains 3.5 % on the six held-out ends (below the 5 % gate) but the whole records
// each predicted by the values fitted on the others move far better with it; dropped, record 00
// replays with 15.9 deg knee error, kept 2.2 deg (rigid 24.5).
TEST(DiagnoseRealRig, MotionFitOfSixRecordsKeepsTheRotorInertiaTheSeventhNeeds) {
  if (!HaveData()) GTEST_SKIP() << kDir << " not found (shared/data beside the project)";
  const std::vector<MeasuredData> rig = ReadRig();
  std::vector<const MeasuredData*> six;
  for (size_t r = 1; r < rig.size(); ++r) six.push_back(&rig[r]);
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  const Diagnosis d = Diagnose(RigModel(), six, opt);
  Print(d);
  const Effect* ie = Named(d, "inertia_error", "knee");
  ASSERT_NE(ie, nullptr) << "the knee's rotor inertia is not named";
  EXPECT_NEAR(ie->value, 0.00276, 0.4 * 0.00276);  // the makers' gr^2 Ir
  for (const char* j : {"hip", "knee"}) EXPECT_NE(Named(d, "coulomb_friction", j), nullptr) << j;
  ReplayScore s[2];
  for (int k = 0; k < 2; ++k) {
    const LegParams p = k == 0 ? RigModel() : d.extended;
    PlantEffects fx;
    const std::unique_ptr<Plant> plant = MakeReplayPlant(p, "test", "", &fx);
    s[k] = Replay(*plant, ReplaySeriesOf(rig[0], fx, ReplayInput::kTorque, kReplayCutoffHz), 0.5).score;
  }
  std::printf("record 00 left out: hip %.2f -> %.2f deg, knee %.2f -> %.2f deg\n", s[0].Rmse(0) * 180 / M_PI,
              s[1].Rmse(0) * 180 / M_PI, s[0].Rmse(1) * 180 / M_PI, s[1].Rmse(1) * 180 / M_PI);
  EXPECT_LT(s[1].Rmse(1), 0.2 * s[0].Rmse(1));
  EXPECT_LT(s[1].Rmse(0), 0.3 * s[0].Rmse(0));
}

// The target for the records left out: all seven records, the motion fit's extended twin (each
// record with the values fitted on the others) replays the records left out at least as well as the
// torque fit's twin (each record with the torque fit's values without it), at both joints. The two
// blocks' rmse_before are the model given's on the rows each block scored: equal while both score the
// same rows (a guard on the block's layout, not a check of its numbers). Measured: hip 2.02 / 2.71 deg,
// knee 6.16 / 6.61 deg (motion / torque). Release suite only (a minute under the sanitizers' 3x).
TEST(DiagnoseRealRig, MotionFitReplaysTheRecordsLeftOutAtLeastAsWellAsTheTorqueFit) {
  if (!HaveData()) GTEST_SKIP() << kDir << " not found (shared/data beside the project)";
  const std::vector<MeasuredData> rig = ReadRig();
  std::vector<const MeasuredData*> all;
  for (const MeasuredData& r : rig) all.push_back(&r);
  DiagnoseOptions opt;
  opt.fit = DiagnoseFit::kMotion;
  const Diagnosis d = Diagnose(RigModel(), all, opt);
  Print(d);
  const SimulationScores& S = d.simulation;
  ASSERT_TRUE(S.done && S.torque_fit_done);
  EXPECT_TRUE(S.torque_fit_not_carried.empty());
  for (int j = 0; j < 2; ++j) {
    std::printf("%s: held-out %.2f (motion) / %.2f (torque) deg; records left out %.2f / %.2f deg\n",
                j == 0 ? "hip" : "knee", S.split[j].rmse_after * 180 / M_PI, S.torque_fit_split[j].rmse_after * 180 / M_PI,
                S.left_out[j].rmse_after * 180 / M_PI, S.torque_fit_left_out[j].rmse_after * 180 / M_PI);
    EXPECT_NEAR(S.torque_fit_split[j].rmse_before, S.split[j].rmse_before, 1e-12);
    EXPECT_NEAR(S.torque_fit_left_out[j].rmse_before, S.left_out[j].rmse_before, 1e-12);
    EXPECT_LE(S.left_out[j].rmse_after, S.torque_fit_left_out[j].rmse_after) << j;
  }
}

}  // namespace
}  // namespace exotwin
