#include <CLI/CLI.hpp>

#include <cstdio>

#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "diagnosis/derivative_cutoff.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/opensim_kinematics.h"
#include "diagnosis/predict.h"
#include "app/commands.h"
#include "core/error.h"
#include "core/heap_policy.h"
#include "sim/plant.h"

namespace exotwin {

std::vector<CommandFactory>& CommandFactories() {
  static std::vector<CommandFactory> factories;
  return factories;
}

namespace {

CommandRunner RegisterPredict(CLI::App& app) {
  struct Opts {
    std::string params, measured, map, out, mjcf, cutoff = "20", side = "r";
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "predict", "Torque-sensor reading the twin predicts for measured kinematics (t,tau_hip,tau_knee)");
  sub->add_option("--params", o->params, "MODEL.yaml (lumped parameters, passive model, effects)")->required();
  sub->add_option("--measured", o->measured,
                  "measured-data CSV (t, q_hip, q_knee, ...), a ROS 2 bag (.mcap or rosbag2 folder, with --map), or an "
                  "OpenSim .mot/.sto motion file (kinematics only)")
      ->required();
  sub->add_option("--side", o->side, "leg of an OpenSim motion file: r (hip_flexion_r, knee_angle_r) or l");
  sub->add_option("--map", o->map, "column map (YAML) turning a foreign --measured CSV or a ROS 2 bag into the schema");
  sub->add_option("--out", o->out, "output CSV of the prediction")->required();
  sub->add_option("--mjcf", o->mjcf, "MJCF model to use instead of the shipped one");
  sub->add_option("--cutoff", o->cutoff,
                  "derivative filter cutoff in Hz, or 'auto' (chosen from the data by held-out "
                  "prediction error, as diagnose does); default 20 (Hwang & Jeon sec. 3.2)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    KeepFreedMemoryForReuse();
    const LegParams params = ReadModelFile(o->params);
    MapReport map_report;
    MeasuredData data = ReadMeasuredKinematics(o->measured, o->map, o->side, 20, &map_report);
    CheckRecordFitsModel(params, o->params, data);
    if (!HasTorque(data)) {
      if (o->cutoff == "auto")
        throw InputError(o->measured + ": --cutoff auto compares predicted with measured torque; this motion file "
                         "holds kinematics only (give the cutoff in Hz)");
      std::fprintf(stderr, "predict: %s holds kinematics only (no torque columns): the prediction is written, "
                   "with no comparison against a measured torque\n", o->measured.c_str());
    }
    if (!o->map.empty()) std::fprintf(stderr, "predict: %s", map_report.Summary().c_str());
    if (params.human) CheckHumanJointRange(data);
    Plant plant(o->mjcf.empty() ? ExowheelMjcfPath(params.human.has_value()) : o->mjcf);
    plant.SetParams(params);
    std::string why;
    const double cutoff = ResolveCutoffOption(o->cutoff, "--cutoff", {&data}, params.L1, params.g, &why);
    if (o->cutoff == "auto") std::fprintf(stderr, "predict: derivative cutoff %s\n", why.c_str());
    const Kinematics kin = DeriveKinematics(std::move(data), cutoff);  // data's memory released
    if (kin.resampled)
      std::fprintf(stderr,
                   "predict: %s is sampled non-uniformly; derivatives computed on a uniform grid at "
                   "the median step and interpolated back\n",
                   o->measured.c_str());
    const Prediction p = PredictTorque(plant, kin);
    std::vector<std::string> names = {"t", "tau_hip", "tau_knee"};
    std::vector<const std::vector<double>*> cols = {&p.t, &p.tau_S[0], &p.tau_S[1]};
    if (params.one_joint) names.erase(names.begin() + 1), cols.erase(cols.begin() + 1);  // its one joint
    WriteCsv(o->out, names, cols,
             {"exotwin predict: torque-sensor reading tau_S = -tau_R (N m)",
              "params: " + o->params + ", measured: " + o->measured +
                  (o->map.empty() ? "" : " (map: " + o->map + ")") + ", derivatives: " +
                  kin.derivative_source});
    return 0;
  };
}

const CommandRegistration kPredict(RegisterPredict);

}  // namespace
}  // namespace exotwin
