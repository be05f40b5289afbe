// exotwin emg-predict (DESIGN.md): the joint moments an EMG model (emg-fit) estimates for a
// recording, t,tau_hip,tau_knee on the EMG file's time base; with --moments, R^2 per joint; the
// extrapolation report: per channel and joint, the share of samples outside the calibration's range
// (a warning above kExtrapolationWarn).
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
    std::vector<double> tau[2];
    for (int j = 0; j < 2; ++j) tau[j] = PredictMoment(model, rec, j);
    WriteCsv(o->out, {"t", "tau_hip", "tau_knee"}, {&rec.t, &tau[0], &tau[1]},
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
