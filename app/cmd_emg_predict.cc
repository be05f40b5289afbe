// exotwin emg-predict (DESIGN.md): the joint moments an EMG model (emg-fit) estimates for a
// recording, t,tau_hip,tau_knee on the EMG file's time base; with --moments, R^2 per joint.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>

#include "formats/csv_table.h"
#include "emg/emg_recording.h"
#include "emg/emg_torque_model.h"
#include "app/commands.h"

namespace exotwin {
namespace {

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
