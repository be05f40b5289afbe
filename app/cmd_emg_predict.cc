// exotwin emg-predict (DESIGN.md): the joint moments an EMG model (emg-fit) estimates for a
// recording, t,tau_hip,tau_knee on the EMG file's time base; with --moments, R^2 per joint; the
// extrapolation report: per channel and joint, the share of samples outside the calibration's range
// (a warning above kExtrapolationWarn); per joint whether the recording is another gait than the
// calibrated one (the papers' form predicts it, emg_torque_model.h kOtherGaitShare).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "formats/csv_table.h"
#include "emg/emg_recording.h"
#include "emg/emg_torque_model.h"
#include "app/commands.h"

namespace exotwin {
namespace {

constexpr double kExtrapolationWarn = 0.05;  // share of samples outside the calibration's range

void ReportExtrapolation(const EmgTorqueModel& model, const EmgRecording& rec) {
  if (model.range.empty()) {
    std::fprintf(stderr, "emg-predict: the model file has no calibration_range: no extrapolation report\n");
    return;
  }
  const EmgExtrapolation x = ExtrapolationOf(model.range, rec);
  std::printf("extrapolation: share of samples outside the calibration's range (warning above %.0f %%)\n",
              100 * kExtrapolationWarn);
  auto line = [](const std::string& what, double share, double lo, double hi, const char* unit) {
    std::printf("  %-28s %6.1f %%   calibrated %.4g .. %.4g%s%s\n", what.c_str(), 100 * share, lo, hi, *unit ? " " : "",
                unit);
    if (share > kExtrapolationWarn)
      std::fprintf(stderr, "emg-predict: warning: %.1f %% of the samples of %s lie outside the calibration's range "
                   "(%.4g .. %.4g%s%s): the model extrapolates there\n", 100 * share, what.c_str(), lo, hi, *unit ? " " : "",
                   unit);
  };
  for (size_t c = 0; c < x.channels.size(); ++c) {
    const auto it = std::find(model.range.channels.begin(), model.range.channels.end(), x.channels[c]);
    const size_t k = static_cast<size_t>(it - model.range.channels.begin());
    if (it == model.range.channels.end()) {
      std::printf("  %-28s not in the calibration\n", ("envelope " + x.channels[c]).c_str());
      continue;
    }
    line("envelope " + x.channels[c], x.envelope_share[c], model.range.e_lo[k], model.range.e_hi[k], "");
  }
  const char* jn[2] = {"hip", "knee"};
  for (int j = 0; j < 2; ++j) {
    line(std::string(jn[j]) + " angle", x.angle_share[j], model.range.q_lo[j], model.range.q_hi[j], "rad");
    line(std::string(jn[j]) + " velocity", x.velocity_share[j], model.range.qd_lo[j], model.range.qd_hi[j], "rad/s");
  }
}

// The musculoskeletal form's muscle states against their calibrated ranges, and where the linear form
// stands in for it (emg_torque_model.h PredictMoments).
void ReportMuscleStates(const EmgTorqueModel& model, const EmgRecording& rec, const EmgPrediction& pr) {
  const char* jn[2] = {"hip", "knee"};
  if (!model.msk.present) {
    std::printf("forms: linear at both joints (the model file has no musculoskeletal form)\n");
    return;
  }
  std::printf("forms: hip %s, knee %s\n", model.msk_form[0] ? "musculoskeletal" : "linear",
              model.msk_form[1] ? "musculoskeletal" : "linear");
  const double n = static_cast<double>(std::max<size_t>(1, rec.size()));
  std::printf("muscle states: share of samples outside the calibrated fibre length or velocity\n");
  std::set<Muscle> synthesized;  // a synthesized muscle's terms share one path and state: one line
  for (size_t c = 0; c < model.msk.muscles.size() && c < pr.msk.fibre.size(); ++c) {
    const EmgMskMuscle& m = model.msk.muscles[c];
    if (m.synthesized && !synthesized.insert(m.muscle).second) continue;
    double out = 0;
    for (size_t i = 0; i < rec.size(); ++i) {
      const double l = pr.msk.fibre[c][i], v = pr.msk.velocity[c][i];
      out += (l < m.fibre_lo || l > m.fibre_hi || v < m.velocity_lo || v > m.velocity_hi) ? 1 : 0;
    }
    std::printf("  %-28s %6.1f %%   calibrated fibre %.3g .. %.3g l_opt, velocity %.3g .. %.3g v_max\n",
                ("muscle " + m.MuscleLabel()).c_str(), 100 * out / n, m.fibre_lo, m.fibre_hi, m.velocity_lo, m.velocity_hi);
  }
  for (int j = 0; j < 2; ++j) {
    if (!model.msk_form[j] || pr.papers[j]) continue;  // another gait: ReportOtherGait
    std::printf("%s: the linear form stands in on %.1f %% of the samples (a muscle spanning the joint outside its "
                "calibrated state)\n", jn[j], 100 * pr.fallback_share[j]);
    if (pr.fallback_share[j] > kExtrapolationWarn)
      std::fprintf(stderr, "emg-predict: warning: at the %s, %.1f %% of the samples leave the muscles' calibrated states: "
                   "predicted by the linear form there\n", jn[j], 100 * pr.fallback_share[j]);
  }
}

// Per joint: the share of samples outside the calibration's range, and whether the papers' form
// predicts the joint as another gait's (emg_torque_model.h kOtherGaitShare).
void ReportOtherGait(const EmgTorqueModel& model, const EmgPrediction& pr) {
  if (model.range.empty()) return;
  const char* jn[2] = {"hip", "knee"};
  for (int j = 0; j < 2; ++j) {
    std::printf("%s: %.1f %% of the samples outside the calibration's range (either joint's angle or velocity, or a "
                "muscle spanning the %s)", jn[j], 100 * pr.outside_share[j], jn[j]);
    if (pr.papers[j]) {
      std::printf(": another gait than the calibrated one (above %.0f %%): predicted by the papers' form (HJ15 eq. 26) "
                  "on the whole recording\n", 100 * kOtherGaitShare);
      std::fprintf(stderr, "emg-predict: warning: at the %s, %.1f %% of the samples lie outside the calibration's range: "
                   "another gait; the papers' form (HJ15 eq. 26) predicts it, not the calibrated %s form\n", jn[j],
                   100 * pr.outside_share[j], model.msk.present && model.msk_form[j] ? "musculoskeletal" : "linear");
    } else if (pr.outside_share[j] > kOtherGaitShare) {
      std::printf(": another gait, but the model file has no papers_form (written before it): the calibrated form "
                  "predicts\n");
    } else {
      std::printf(": the calibrated form predicts\n");
    }
  }
}

CommandRunner RegisterEmgPredict(CLI::App& app) {
  struct Opts {
    std::string model, emg, kin, mom, map, out;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand("emg-predict", "Hip and knee moments an EMG model (emg-fit) estimates for a recording");
  sub->add_option("--model", o->model, "EMGMODEL.yaml written by emg-fit")->required();
  sub->add_option("--emg", o->emg, "EMG envelopes (.sto)")->required();
  sub->add_option("--kinematics", o->kin, "inverse-kinematics angles (.sto/.mot)")->required();
  sub->add_option("--moments", o->mom, "inverse-dynamics moments (.sto): prints R^2 per joint");
  sub->add_option("--map", o->map, "muscle map YAML (as for emg-fit); default: OpenSim names");
  sub->add_option("--out", o->out, "output CSV t,tau_hip,tau_knee (N m)")->required();
  return [sub, o]() -> int {
    if (!*sub) return -1;
    const EmgTorqueModel model = ReadEmgModel(o->model);
    const MuscleMap map = o->map.empty() ? DefaultMuscleMap() : ReadMuscleMap(o->map);
    const EmgRecording rec = ReadEmgRecording(o->emg, o->kin, o->mom, map);
    for (const auto& n : rec.notes) std::fprintf(stderr, "emg-predict: %s: %s\n", rec.source.c_str(), n.c_str());
    ReportExtrapolation(model, rec);
    const EmgPrediction pr = PredictMoments(model, rec);
    const std::vector<double>* tau = pr.tau;
    ReportMuscleStates(model, rec, pr);
    ReportOtherGait(model, pr);
    WriteCsv(o->out, {"t", "tau_hip", "tau_knee"}, {&rec.t, &pr.tau[0], &pr.tau[1]},
             {"exotwin emg-predict: estimated muscular joint moment (N m, hip flexion +, knee extension +)",
              "model: " + o->model + ", emg: " + o->emg + ", kinematics: " + o->kin});
    if (rec.has_moments()) {
      const char* jn[2] = {"hip", "knee"};
      for (int j = 0; j < 2; ++j) {
        std::vector<size_t> all(rec.size());
        for (size_t i = 0; i < all.size(); ++i) all[i] = i;
        double r2, rms, r2t, rmst;
        ScoreSamples(rec.tau[j], tau[j], all, &r2, &rms);
        const std::vector<size_t> in = WithinSpikeLimit(rec.tau[j], 0, rec.size());
        ScoreSamples(rec.tau[j], tau[j], in, &r2t, &rmst);
        std::printf("%s: R^2 %.3f, rms %.2f N m (all samples); within %g scaled MADs of the median moment: R^2 "
                    "%.3f, rms %.2f N m (%zu of %zu samples)\n",
                    jn[j], r2, rms, kSpikeMads, r2t, rmst, in.size(), rec.size());
      }
    }
    return 0;
  };
}

const CommandRegistration kEmgPredict(RegisterEmgPredict);

}  // namespace
}  // namespace exotwin
