// `exotwin replay`: the twin (its effects in the MuJoCo plant) simulated forward on measured records,
// driven by the recorded actuator torque and restarted from the measured state every horizon.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>


#include <cmath>
#include <cstdio>
#include <cstring>

#include "app/commands.h"
#include "core/error.h"
#include "core/output_path.h"
#include "diagnosis/replay.h"
#include "formats/column_map.h"
#include "formats/csv_table.h"
#include "formats/model_file.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

// " hip X rad (Y deg), knee X rad (Y deg)" from joint j0 on (1: the knee of a one-joint device).
std::string ErrorText(const ReplayScore& score, int j0) {
  const char* names[2] = {"hip", "knee"};
  std::string out;
  char buf[96];
  for (int j = j0; j < 2; ++j) {
    std::snprintf(buf, sizeof buf, "%s %s %.4f rad (%.2f deg)", j > j0 ? "," : "", names[j], score.Rmse(j),
                  score.Rmse(j) * 180 / M_PI);
    out += buf;
  }
  return out;
}

CommandRunner RegisterReplay(CLI::App& app) {
  struct Opts {
    std::string params, out, map, mjcf, input = "torque", between = "linear", windows = "every";
    std::vector<std::string> measured;
    double horizon = 0.5, cutoff = kReplayCutoffHz;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "replay", "Forward simulation of measured records by the twin with its effects in the plant");
  sub->add_option("--params", o->params, "MODEL.yaml of the twin (its effects carried by the MuJoCo plant)")->required();
  sub->add_option("--measured", o->measured, "measured-data CSV or ROS 2 bag (with --map); repeat for several records")->required();
  sub->add_option("--out", o->out, "output folder (replay.csv, replay.json)")->required();
  sub->add_option("--map", o->map, "column map (YAML) turning foreign --measured CSVs or ROS 2 bags into the schema");
  sub->add_option("--input", o->input,
                  "torque (tau_R = -tau_S of the record, sensor effects inverted; default) or command (cmd_* columns)");
  sub->add_option("--between-samples", o->between,
                  "the input between samples: linear (interpolated, a rig's continuously sampled torque; default) "
                  "or hold (each sample held until the next: the twin's own records, whose joint modules log the "
                  "torque they apply over the coming step)");
  sub->add_option("--horizon", o->horizon, "seconds between restarts from the measured state (default 0.5)");
  sub->add_option("--windows", o->windows,
                  "every (a window every horizon; default) or quiet (the motion fit's: restarted and scored where "
                  "the measured motion has no fast content the restart velocity misses, e.g. a dead band's knocks)");
  sub->add_option("--cutoff", o->cutoff,
                  "Hz, the zero-phase 2nd-order Butterworth of the angle whose central differences give the restart "
                  "velocity (the restart angle is the measured one); default 10");
  sub->add_option("--mjcf", o->mjcf, "MJCF model to use instead of the shipped one");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    if (o->input != "torque" && o->input != "command")
      throw InputError("replay --input: expected 'torque' or 'command', got '" + o->input + "'");
    if (o->between != "linear" && o->between != "hold")
      throw InputError("replay --between-samples: expected 'linear' or 'hold', got '" + o->between + "'");
    if (o->windows != "every" && o->windows != "quiet")
      throw InputError("replay --windows: expected 'every' or 'quiet', got '" + o->windows + "'");
    if (!(o->horizon > 0) || !std::isfinite(o->horizon))
      throw InputError("replay --horizon: expected a time > 0 s, got " + std::to_string(o->horizon));
    if (!(o->cutoff > 0) || !std::isfinite(o->cutoff))
      throw InputError("replay --cutoff: expected a frequency > 0 Hz, got " + std::to_string(o->cutoff));
    const LegParams params = ReadModelFile(o->params);
    PlantEffects fx;
    const std::unique_ptr<Plant> twin = MakeReplayPlant(params, o->params, o->mjcf, &fx);
    Plant& plant = *twin;
    const ReplayInput input = o->input == "command" ? ReplayInput::kCommand : ReplayInput::kTorque;

    // Everything is read and checked before anything is simulated or written.
    std::vector<ReplaySeries> series;
    for (const std::string& m : o->measured) {
      MapReport report;
      const MeasuredData data = ReadMeasured(m, o->map, 20, &report);
      if (!o->map.empty()) std::fprintf(stderr, "replay: %s", report.Summary().c_str());
      CheckRecordFitsModel(params, o->params, data);
      if (params.human) CheckHumanJointRange(data);
      if (data.t().back() - data.t().front() < o->horizon)
        throw InputError(m + ": --horizon " + std::to_string(o->horizon) + " s is longer than the record (" +
                         std::to_string(data.t().back() - data.t().front()) + " s)");
      series.push_back(ReplaySeriesOf(data, fx, input, o->cutoff));
      series.back().hold = o->between == "hold";
      series.back().quiet_windows = o->windows == "quiet";
    }

    std::vector<double> col_t, col_q[2], col_sim[2], col_w, col_r;
    ReplayScore total;
    nlohmann::json records = nlohmann::json::array();
    const char* names[2] = {"hip", "knee"};
    const int j0 = params.one_joint ? 1 : 0;  // a one-joint device (its hip held at 0) reports its knee only
    for (size_t r = 0; r < series.size(); ++r) {
      const ReplaySeries& s = series[r];
      const ReplayRecord rec = Replay(plant, s, o->horizon);
      total.Add(rec.score);
      nlohmann::json x = {{"source", s.source}, {"windows", rec.score.windows}, {"samples", rec.score.count}};
      for (int j = j0; j < 2; ++j) x["joints"][names[j]] = {{"rmse_rad", rec.score.Rmse(j)}};
      records.push_back(x);
      for (size_t i = 0; i < s.t.size(); ++i) {
        if (rec.Window(i) < 0) continue;
        col_t.push_back(s.t[i]);
        for (int j = 0; j < 2; ++j) {
          col_q[j].push_back(s.q[j][i]);
          col_sim[j].push_back(rec.Sim(j, i));
        }
        col_w.push_back(rec.Window(i));
        col_r.push_back(static_cast<double>(r));
      }
      std::printf("replay: %s: %zu windows of %g s, RMS angle error%s\n", s.source.c_str(), rec.score.windows,
                  o->horizon, ErrorText(rec.score, j0).c_str());
    }
    nlohmann::json j = {{"horizon_s", o->horizon},
                        {"windows", total.windows},
                        {"windows_schedule", o->windows},
                        {"input", o->input},
                        {"input_between_samples", o->between},
                        {"restart_state", "the measured angle and its velocity (central differences of the angle low-passed by a "
                                              "zero-phase 2nd-order Butterworth at " + std::to_string(o->cutoff) + " Hz, handed to the "
                                              "integrator half a step behind); a dead band on the flank "
                                              "the rigid torque of that motion presses, a strap run in over its settling time (DESIGN.md)"},
                        {"joint_limits", "disabled (and the actuators' ctrlrange)"},
                        {"records", records}};
    if (params.one_joint) j["one_joint"] = true;
    for (int k = j0; k < 2; ++k) j["joints"][names[k]] = {{"rmse_rad", total.Rmse(k)}};

    CreateOutputFolder(o->out);
    std::vector<std::string> csv_names = {"t", "q_hip", "q_hip_sim", "q_knee", "q_knee_sim", "window", "record"};
    std::vector<const std::vector<double>*> csv_cols = {&col_t, &col_q[0], &col_sim[0], &col_q[1], &col_sim[1], &col_w, &col_r};
    if (params.one_joint) {  // no hip columns
      csv_names.erase(csv_names.begin() + 1, csv_names.begin() + 3);
      csv_cols.erase(csv_cols.begin() + 1, csv_cols.begin() + 3);
    }
    WriteCsv(o->out + "/replay.csv", csv_names, csv_cols,
             {"exotwin replay: measured and simulated angles (rad); window: restart index in its record; "
              "record: index of --measured",
              "params: " + o->params + ", horizon " + std::to_string(o->horizon) + " s, input " + o->input});
    WriteFileAtomic(o->out + "/replay.json", j.dump(2) + "\n");
    std::printf("replay: %zu windows of %g s, RMS angle error%s\n", total.windows, o->horizon, ErrorText(total, j0).c_str());
    return 0;
  };
}

const CommandRegistration kReplay(RegisterReplay);

}  // namespace
}  // namespace exotwin
