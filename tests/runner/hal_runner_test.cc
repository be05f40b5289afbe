// HAL-3 end to end (scenarios/hal_runner.h): Hayashi's experiment 1 against 2 (Fig. 9), the on-line
// RLS of D and K against the twin's ground truth, and Lee & Sankai's viscous sweep (Fig. 9, LS05 eq. 12).
#include "tests/temp_dir.h"
#include "runner/hal_runner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "formats/csv_table.h"
#include "core/error.h"

namespace exotwin {
namespace {

std::string Shipped(const std::string& rel) { return std::string(EXOTWIN_SOURCE_DIR) + "/scenarios/" + rel; }


RunResult RunShipped(const std::string& file, const std::string& tag) {
  RunOptions o;
  const testing::ScopedTempDir tmp("hal_" + tag);
  o.out_dir = tmp.path();
  return RunHalScenario(ReadScenario(Shipped(file)), o);
}

// Both experiments once for the whole file (12 s of simulated time each).
const RunResult& Exp(int n) {
  static const RunResult e1 = RunShipped("hal3_exp1_no_assist.yaml", "exp1");
  static const RunResult e2 = RunShipped("hal3_exp2_assist.yaml", "exp2");
  return n == 1 ? e1 : e2;
}

void PrintPhaseTable() {
  const auto& a = Exp(1).metrics;
  const auto& b = Exp(2).metrics;
  std::printf("[hal] Fig. 9 quantity                     exp1 (no assist)   exp2 (assist)\n");
  for (const char* k : {"emg_ext_up_V", "emg_ext_down_V", "emg_flex_up_V", "emg_flex_down_V",
                        "emg_ext_up_rect_V", "strain_up_Nm", "strain_down_Nm", "mu_ext_up_Nm", "J_tau_m",
                        "th_max", "th_min", "tracking_rms_rad"})
    std::printf("[hal] %-38s %10.4f        %10.4f\n", k, a.at(k), b.at(k));
}

TEST(HalRunner, ShippedScenariosPassTheirChecks) {
  for (int n : {1, 2}) {
    for (const CheckResult& c : Exp(n).checks)
      EXPECT_TRUE(c.passed) << Exp(n).scenario << ": " << c.name << " = " << c.value << " (" << c.op << " "
                            << c.limit << ")";
  }
}

// Fig. 9-A: the average extensor activity in swing-up drops with the assist; Fig. 9-C: the strain
// signal in swing-up turns from negative (HAL resists) to positive (HAL pushes into extension).
TEST(HalRunner, AssistLowersExtensorEmgInSwingUpAsFig9) {
  PrintPhaseTable();
  const auto& a = Exp(1).metrics;
  const auto& b = Exp(2).metrics;
  // Compared above the relaxed level (~0.1 V, emg_baseline_ext_V): with the noise-corrected HKS05 eq. 2
  // mu^ no longer over-assists at swing levels (the raw-envelope line was ~1.25x too steep there).
  // Seed 1: the envelope drops 0.143 -> 0.123 V (-14 %; -43 % above the baseline).
  const double E0 = b.at("emg_baseline_ext_V");
  EXPECT_GT(E0, 0.05);
  EXPECT_LT(b.at("emg_ext_up_V"), a.at("emg_ext_up_V"));
  EXPECT_LT(b.at("emg_ext_up_V") - E0, 0.9 * (a.at("emg_ext_up_V") - E0));
  EXPECT_LT(b.at("emg_ext_up_rect_V"), a.at("emg_ext_up_rect_V"));
  EXPECT_LT(b.at("mu_ext_up_Nm"), a.at("mu_ext_up_Nm"));
  EXPECT_LT(a.at("strain_up_Nm"), 0.0);
  EXPECT_GT(b.at("strain_up_Nm"), 0.0);
  // The flexor stays near its relaxed level in swing-up in both (Fig. 9-A: ~0.04 V).
  EXPECT_LT(a.at("emg_flex_up_V"), 0.15);
  EXPECT_LT(b.at("emg_flex_up_V"), 0.15);
}

// RLS (HKS05 eq. 8-13) against the identifiable ground truth of HKS05 eq. 4 in the twin: the rho-weighted
// least-squares D, K of the operator's true viscoelastic torque (co-contraction D, K + the
// contraction's angle / velocity factors), means over t > settle (scenarios/hal_runner.cc,
// ProjectedViscoelasticity).
TEST(HalRunner, RlsViscosityWithin20PercentStiffnessIsAKnownGap) {
  const auto& m = Exp(2).metrics;
  std::printf("[hal] RLS: D^ %.3f vs truth %.3f (%.1f %%), K^ %.3f vs truth %.3f (%.1f %%), I^ %.3f\n",
              m.at("rls_D_mean"), m.at("truth_D_mean"), m.at("rls_D_err_pct"), m.at("rls_K_mean"),
              m.at("truth_K_mean"), m.at("rls_K_err_pct"), m.at("rls_I_hat"));
  // The time mean of K(t) (~7 N m/rad in the swing-down co-contraction, ~1 otherwise) is not what any
  // constant-parameter window can identify: the identifiable K is well below it (seed 1: ~1.0 vs ~3.1).
  EXPECT_LT(m.at("truth_K_mean"), 0.6 * m.at("truth_K_timemean"));
  // Seed 1: D within 7 %, K within 21 % (was +235 % before the exact muscle allocation and the
  // errors-in-variables fit of HKS05 eq. 2, see the known gap's header). K is ~6 % of the gravity stiffness
  // the RLS also sees, so 1 % of gain error in mu^ is ~17 % of K: over seeds 1-5 K^ errs by 20-140 %.
  // Regression bounds, not the acceptance (scenarios/hal3_rls_tracking.yaml meets the 20 % with a
  // co-contracting operator; known_gaps/hal3_rls_exp2_stiffness.yaml holds experiment 2's own
  // condition): D inside the issue's bound, K inside twice it.
  EXPECT_LT(m.at("rls_D_err_pct"), 20.0);
  EXPECT_LT(m.at("rls_K_err_pct"), 40.0);
  // On the RLS's own scale, K' = K + Mgl (HKS05 eq. 8): recomputed from the reported means; seed 1 ~1 %.
  const double Kp = m.at("truth_K_mean") + m.at("plant_mgl");
  EXPECT_NEAR(m.at("rls_K_err_pct_of_Kprime"), 100 * std::abs(m.at("rls_K_mean") - m.at("truth_K_mean")) / Kp, 1e-9);
  EXPECT_LT(m.at("rls_K_err_pct_of_Kprime"), 5.0);
}

// The issue's acceptance: D^, K^ within 20 % of the identifiable truth after convergence, for an
// operator who co-contracts (10 % of MVC), with the four extensions of the scenario's header. The
// same run with the paper's four-parameter RLS (I estimated): K' trades with I w^2 in the 0.5 Hz
// swing and K^ misses by far more (seed 1: ~60 %), while I^ leaves the truth; with the known
// inertia I^ is HKS05 eq. 14's exactly.
TEST(HalRunner, RlsTracksACoContractingOperatorWithin20Percent) {
  const Scenario s = ReadScenario(Shipped("hal3_rls_tracking.yaml"));
  RunOptions o;
  const testing::ScopedTempDir tmp("hal_rls");
  o.out_dir = tmp.path();
  const RunResult r = RunHalScenario(s, o);
  for (const CheckResult& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " = " << c.value;
  const auto& m = r.metrics;
  std::printf("[hal] RLS, co-contraction 0.1: D^ %.3f vs truth %.3f (%.1f %%), K^ %.3f vs truth %.3f (%.1f %%)\n",
              m.at("rls_D_mean"), m.at("truth_D_mean"), m.at("rls_D_err_pct"), m.at("rls_K_mean"),
              m.at("truth_K_mean"), m.at("rls_K_err_pct"));
  EXPECT_DOUBLE_EQ(m.at("rls_I_hat"), m.at("plant_I"));  // 1 / (1 / I0): rounding only
  Scenario paper = s;
  paper.hal.rls_known_inertia = false;
  const testing::ScopedTempDir tmp_paper("hal_rls_paper");
  o.out_dir = tmp_paper.path();
  const auto& mp = RunHalScenario(paper, o).metrics;
  std::printf("[hal] same with the four-parameter RLS: K^ %.3f (%.1f %%), I^ %.3f vs %.3f\n", mp.at("rls_K_mean"),
              mp.at("rls_K_err_pct"), mp.at("rls_I_hat"), mp.at("plant_I"));
  EXPECT_GT(mp.at("rls_K_err_pct"), 2 * std::max(20.0, m.at("rls_K_err_pct")));
}

TEST(HalRunner, WritesMeasuredCsvWithHalColumns) {
  RunOptions o;
  const testing::ScopedTempDir tmp("hal_csv");
  o.out_dir = tmp.path();
  Scenario s = ReadScenario(Shipped("hal3_exp1_no_assist.yaml"));
  s.protocol.duration = 1.0;
  s.hal.settle = 0.5;
  const RunResult r = RunHalScenario(s, o);
  const CsvTable t = ReadCsv(o.out_dir + "/measured.csv");
  for (const char* c : {"t", "q_knee", "tau_knee", "cmd_knee", "emg_GMAX", "emg_VM", "emg_RF", "emg_ST", "emg_GAS"})
    EXPECT_GE(t.Find(c), 0) << c;
  EXPECT_EQ(t.rows(), 1000u);
  EXPECT_EQ(r.metrics.at("samples"), 1000.0);  // the console summary's count: the rows logged
  EXPECT_TRUE(std::filesystem::exists(o.out_dir + "/result.json"));
  EXPECT_EQ(r.metrics.at("emg_gaps"), 0.0);
}

TEST(HalRunner, RejectsNonHalDevice) {
  Scenario s = ReadScenario(Shipped("gait_2kmh.yaml"));
  RunOptions o;
  const testing::ScopedTempDir tmp("hal_bad");
  o.out_dir = tmp.path();
  EXPECT_THROW(RunHalScenario(s, o), InputError);
}

// Lee & Sankai Fig. 9 / LS05 eq. 12: J_tau_m over the virtual viscous coefficient. See the comment in
// scenarios/hal3_viscous_sweep.yaml for where the twin's trough falls and why.
TEST(HalRunner, ViscousSweepMusculoskeletalMomentCurve) {
  RunOptions o;
  const testing::ScopedTempDir tmp("hal_sweep");
  o.out_dir = tmp.path();
  const RunResult r = RunHalScenario(ReadScenario(Shipped("hal3_viscous_sweep.yaml")), o);
  const Scenario s = ReadScenario(Shipped("hal3_viscous_sweep.yaml"));
  std::printf("[hal] B_v (N m s/rad)   J_tau_m (N m)   J_me   J_mf\n");
  char key[64];
  for (double v : s.hal.sweep_viscosity) {
    std::snprintf(key, sizeof(key), "%g", v);
    std::printf("[hal] %8.2f            %8.3f      %5.3f  %5.3f\n", v, r.metrics.at(std::string("J_tau_m@") + key),
                r.metrics.at(std::string("J_me@") + key), r.metrics.at(std::string("J_mf@") + key));
  }
  std::printf("[hal] twin minimum at B_v = %.2f (paper: 1.56)\n", r.metrics.at("sweep_argmin_viscosity"));
  EXPECT_EQ(r.metrics.at("runs"), static_cast<double>(s.hal.sweep_viscosity.size()));
  // A trough inside the range: J_tau_m falls down to the minimum and rises after it (the operator's
  // delayed loop wobbles below it; muscle work against the damper grows above it).
  const double best = r.metrics.at("sweep_argmin_viscosity");
  EXPECT_GT(best, s.hal.sweep_viscosity.front());
  EXPECT_LT(best, s.hal.sweep_viscosity.back());
  double prev = 1e9;
  for (double v : s.hal.sweep_viscosity) {
    std::snprintf(key, sizeof(key), "J_tau_m@%g", v);
    const double J = r.metrics.at(key);
    if (v <= best) {
      EXPECT_LE(J, prev + 1e-9) << key << " (falling towards the trough)";
    } else {
      EXPECT_GE(J, prev - 1e-9) << key << " (rising after the trough)";
    }
    prev = J;
  }
  for (const CheckResult& c : r.checks) EXPECT_TRUE(c.passed) << c.name << " = " << c.value;
  // The curves (Fig. 9) as SVG: one polyline per criterion with a point per swept value, and the
  // twin's minimum marked (sweep_plots_test checks the chart's geometry).
  EXPECT_NE(std::find(r.files.begin(), r.files.end(), "sweep.svg"), r.files.end());
  std::ifstream in(o.out_dir + "/sweep.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* label : {"J_tau_m (eq. 12) / max", "J_me, extensor (eq. 16)", "J_mf, flexor (eq. 15)"})
    EXPECT_NE(svg.find(std::string("data-label=\"") + label + "\""), std::string::npos) << label;
  std::snprintf(key, sizeof(key), "twin minimum %g", best);
  EXPECT_NE(svg.find(key), std::string::npos) << key;
}

// The mechanism: the same sweep with an operator whose feedback has no neural delay has no trough
// (its minimum is the lowest B_v: less damping, less muscle work), as the twin printed before the
// delay was modelled.
TEST(HalRunner, ViscousSweepHasNoTroughWithoutOperatorDelay) {
  Scenario s = ReadScenario(Shipped("hal3_viscous_sweep.yaml"));
  s.hal.operator_delay = 0.0;
  s.checks.clear();
  RunOptions o;
  const testing::ScopedTempDir tmp("hal_sweep_nodelay");
  o.out_dir = tmp.path();
  const RunResult r = RunHalScenario(s, o);
  EXPECT_EQ(r.metrics.at("sweep_argmin_viscosity"), s.hal.sweep_viscosity.front());
}

// Over 8 operators (muscle ground truth drawn from seeds 1..8) the trough falls at positive B_v
// with a median within one grid step (0.25-0.31 N m s/rad) of the paper's 1.56 for its 3 operators.
// Measured: 1.56, 2.0, 1.56, 1.0, 2.25, 1.25, 1.0, 1.0 (median 1.4).
TEST(HalRunner, ViscousSweepTroughOverOperators) {
  std::vector<double> argmin;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    Scenario s = ReadScenario(Shipped("hal3_viscous_sweep.yaml"));
    s.human.muscle_seed = seed;
    s.checks.clear();
    RunOptions o;
    const testing::ScopedTempDir tmp("hal_sweep_ops");
    o.out_dir = tmp.path();
    argmin.push_back(RunHalScenario(s, o).metrics.at("sweep_argmin_viscosity"));
    std::printf("[hal] operator %d: trough at B_v = %.2f\n", static_cast<int>(seed), argmin.back());
    EXPECT_GT(argmin.back(), 0.0);
  }
  std::sort(argmin.begin(), argmin.end());
  const double median = 0.5 * (argmin[3] + argmin[4]);
  EXPECT_GE(median, 1.0);
  EXPECT_LE(median, 2.0);
}

}  // namespace
}  // namespace exotwin
