// The EMG model on a real subject (shared/data/real_human/ceinms_lowerlimb_walk36, README there):
// the linear form of HJ15 eq. 26 reproduces the README's held-out figures (first 70 % fitted, last
// 30 % held out: knee R^2 0.60, hip 0.65 over all samples), and the discrepancy loop, its causes
// chosen by blocked cross-validation and kept inside physiology, beats it both cross-validated and on
// the last 30 % (R^2 over the samples within 6 scaled MADs of the median moment, the contact spikes
// left out for every model alike). Skipped when shared/data is not beside the project.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "emg/emg_diagnose.h"
#include "emg/emg_recording.h"

namespace exotwin {
namespace {

const std::string kDir = std::string(EXOTWIN_SOURCE_DIR) + "/../shared/data/real_human/ceinms_lowerlimb_walk36";

TEST(EmgRealHuman, LinearFormReproducesTheReadmeAndTheLoopGains) {
  if (!std::ifstream(kDir + "/emgFilt.sto")) GTEST_SKIP() << "shared/data not beside the project";
  const EmgRecording r = ReadEmgRecording(kDir + "/emgFilt.sto", kDir + "/ik.sto", kDir + "/id.sto", DefaultMuscleMap());
  ASSERT_EQ(r.size(), 6097u);
  EXPECT_EQ(r.missing, std::vector<std::string>{"GMAX"});
  const EmgDiagnosis d = DiagnoseEmg({&r});
  const EmgJointFigures* lin = d.steps.front().model.figures;
  const EmgJointFigures* fin = d.steps.back().model.figures;
  std::printf("%-48s %8s %8s %8s %8s %8s %8s\n", "step", "hip cv", "knee cv", "hip R2", "hip rms", "knee R2", "knee rms");
  for (const auto& s : d.steps)
    std::printf("%-48s %8.3f %8.3f %8.3f %8.2f %8.3f %8.2f\n", s.added.substr(0, 48).c_str(), s.model.figures[0].r2_cv,
                s.model.figures[1].r2_cv, s.model.figures[0].r2_heldout_trim, s.model.figures[0].rms_heldout_trim,
                s.model.figures[1].r2_heldout_trim, s.model.figures[1].rms_heldout_trim);
  for (const auto& s : d.selection) std::printf("  %s\n", s.c_str());
  // README: linear form, all held-out samples.
  EXPECT_NEAR(lin[1].r2_heldout, 0.60, 0.02);
  EXPECT_NEAR(lin[0].r2_heldout, 0.65, 0.02);
  EXPECT_NEAR(lin[1].rms_heldout, 6.0, 0.3);
  EXPECT_NEAR(lin[0].rms_heldout, 13.9, 0.5);
  // Issue 19: 0.60 / 0.73 by the spike rule.
  EXPECT_NEAR(lin[1].r2_heldout_trim, 0.60, 0.02);
  EXPECT_NEAR(lin[0].r2_heldout_trim, 0.73, 0.02);
  // The loop pays at both joints, cross-validated (5 contiguous blocks) and on the last 30 %.
  EXPECT_FALSE(d.folds_are_recordings);
  EXPECT_EQ(d.folds, 5);
  EXPECT_GT(d.steps.size(), 1u);
  for (int j = 0; j < 2; ++j) {
    EXPECT_GT(fin[j].r2_cv, lin[j].r2_cv + 0.04);
    EXPECT_GT(fin[j].r2_heldout_trim, lin[j].r2_heldout_trim + 0.04);
  }
  // Measured: cross-validated hip 0.793, knee 0.765; last 30 % hip 0.791, knee 0.784, every alpha
  // with its muscle's sign (the free fit reached 0.80 at the hip with the rectus femoris pulling the
  // hip into extension, the missing gluteus's moment).
  EXPECT_GE(fin[1].r2_cv, 0.75);
  EXPECT_GE(fin[0].r2_cv, 0.78);
  EXPECT_GE(fin[1].r2_heldout_trim, 0.70);
  EXPECT_GE(fin[0].r2_heldout_trim, 0.78);
  // Every alpha keeps its muscle's sign, or is held at zero and reported.
  for (const EmgTerm& t : d.calibration.terms) {
    if (t.kind != TermKind::kAlpha) continue;
    EXPECT_GE(t.value * t.ExpectedSign(), 0.0) << t.Name();
    if (!t.held) continue;
    bool noted = false;
    for (const std::string& n : d.notes) noted |= n.find(t.Name() + " at the " + (t.joint ? "knee" : "hip")) == 0;
    EXPECT_TRUE(noted) << t.Name();
  }
  // Every named timing inside physiology (emg_diagnose.cc: 10-100 ms delays, 20-100 ms twitch).
  const EmgModelSpec& s = d.calibration.spec;
  for (double v : {s.common_delay, s.twitch}) EXPECT_TRUE(v == 0 || (v >= 0.01 && v <= 0.1)) << v;
  for (const auto& m : s.delay_s) EXPECT_TRUE(m.second >= 0.01 && m.second <= 0.1) << m.second;
  // The band ceiling (emg_diagnose.h BandCeiling). Measured: the hip estimate holds all but 0.1 % of
  // its variance below 3.5 Hz and the hip moment has 15.3 % of its variance above (inverse
  // dynamics' noise: of what lies above 6 Hz, 93 % is not phase-locked to the stride), so no estimate of that band
  // passes 0.866 there; the knee 12 Hz, 6.4 %, 0.948. The model stays below the ceiling.
  for (int j = 0; j < 2; ++j) {
    const EmgBandCeiling& c = d.ceiling[j];
    std::printf("%s: band %.1f Hz, moment share above %.4f, estimate %.5f, ceiling R^2 %.3f\n", j ? "knee" : "hip",
                c.band_hz, c.share_above, c.estimate_share, c.r2);
    EXPECT_LE(fin[j].r2_cv, c.r2);
    EXPECT_LE(d.calibration.figures[j].r2_fit, c.r2);
  }
  EXPECT_NEAR(d.ceiling[0].share_above, 0.153, 0.02);
  EXPECT_LT(d.ceiling[0].r2, 0.9);
}

}  // namespace
}  // namespace exotwin
