// `exotwin render-replay`: a video of measured data (a measured-data CSV or an OpenSim motion file).
// The twin's leg follows the measured angles;
// overlays show the measured torque against the twin's estimate (from --predicted, else computed
// with `predict`'s model) and EMG envelopes of any emg_* columns. Each --sim (a `replay` output of
// the same record) adds a translucent ghost leg posed at the twin's simulated angles.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>

#include "formats/csv_table.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/opensim_kinematics.h"
#include "diagnosis/predict.h"
#include "app/commands.h"
#include "core/error.h"
#include "dsp/butterworth.h"
#include "render/render_plugin.h"
#include "sim/ghost_legs.h"
#include "sim/plant.h"

namespace exotwin {
namespace {

constexpr double kEmgEnvelopeHz = 6.0;  // low-pass of the rectified EMG (zero-phase, 2nd order)

// Envelope of an amplified EMG signal (V): mean removed, full-wave rectified, low-passed.
std::vector<double> Envelope(const std::vector<double>& x, double fs) {
  double mean = 0;
  for (double v : x) mean += v;
  mean /= x.size();
  std::vector<double> r(x.size());
  for (size_t i = 0; i < x.size(); ++i) r[i] = std::abs(x[i] - mean);
  if (fs <= 2.5 * kEmgEnvelopeHz) return r;
  std::vector<double> e = dsp::FiltFilt(dsp::DesignButterworth(2, dsp::BandType::kLowPass, fs, kEmgEnvelopeHz), r);
  for (double& v : e) v = std::max(0.0, v);
  return e;
}

// The twin's torque estimate on the measured time base, from a `predict` CSV (t, tau_hip, tau_knee).
void ReadPredicted(const std::string& path, const MeasuredData& data, std::vector<double> est[2]) {
  const CsvTable p = ReadCsv(path);
  const char* names[] = {"t", "tau_hip", "tau_knee"};
  for (const char* n : names)
    if (p.Find(n) < 0) throw InputError(path + ": missing column '" + n + "' (expected t,tau_hip,tau_knee)");
  const std::vector<double>& t = p.columns[p.Find("t")];
  if (t.size() < 2) throw InputError(path + ": needs at least 2 rows");
  for (size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1]))
      throw InputError(path + ":" + std::to_string(p.line_of_row[i]) + ": column 't' must be strictly increasing");
  const double tol = 1.5 * MedianStep(data.t());
  if (t.front() > data.t().front() + tol || t.back() < data.t().back() - tol)
    std::fprintf(stderr, "render-replay: %s covers [%g, %g] s but the measurement covers [%g, %g] s; the "
                 "estimate is held constant outside\n", path.c_str(), t.front(), t.back(), data.t().front(),
                 data.t().back());
  est[0] = Interpolate(t, p.columns[p.Find("tau_hip")], data.t());
  est[1] = Interpolate(t, p.columns[p.Find("tau_knee")], data.t());
}

// Ghost colours, in --sim order (red, green, magenta, orange; then again). Not blue: the
// exoskeleton is.
struct GhostColour {
  const char* name;
  std::array<double, 4> rgba;
};
constexpr GhostColour kGhostColours[] = {{"red", {0.95, 0.1, 0.1, 0.45}},
                                         {"green", {0.1, 0.8, 0.2, 0.45}},
                                         {"magenta", {0.85, 0.2, 0.85, 0.45}},
                                         {"orange", {1.0, 0.6, 0.0, 0.45}}};

// A simulated leg from a `replay` CSV, on the measured time base.
struct SimLeg {
  std::string label;
  std::vector<double> q_hip, q_knee;  // rad, per measured sample
  std::vector<bool> covered;          // the replay has the sample (else the ghost takes the measured pose)
};

// Reads DIR/replay.csv (t, q_hip_sim, q_knee_sim, record) of one record; of a one-joint record, t,
// q_knee_sim (the hip held at 0, as the replay held it). The rows must lie within the measured
// record's time range (1.5 median steps of slack); the angles are linearly interpolated onto the
// measured times within the replay's first..last row, the samples outside are not covered.
SimLeg ReadSimLeg(const std::string& path, const MeasuredData& data) {
  const CsvTable p = ReadCsv(path);
  for (const char* n : {"t", "q_hip_sim", "q_knee_sim"})
    if (p.Find(n) < 0 && !(data.one_joint && std::string(n) == "q_hip_sim"))
      throw InputError(path + ": missing column '" + n + "' (expected a `replay` output: t, q_hip, q_hip_sim, "
                       "q_knee, q_knee_sim, window, record; of a one-joint record t, q_knee, q_knee_sim, window, "
                       "record)");
  const std::vector<double>& t = p.columns[p.Find("t")];
  if (t.size() < 2) throw InputError(path + ": needs at least 2 rows");
  if (const int rec = p.Find("record"); rec >= 0)
    for (size_t i = 0; i < t.size(); ++i)
      if (p.columns[rec][i] != p.columns[rec][0])
        throw InputError(path + ":" + std::to_string(p.line_of_row[i]) + ": rows of more than one record; "
                         "replay the record alone (one --measured)");
  for (size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1]))
      throw InputError(path + ":" + std::to_string(p.line_of_row[i]) + ": column 't' must be strictly increasing");
  const double tol = 1.5 * MedianStep(data.t());
  if (t.front() < data.t().front() - tol || t.back() > data.t().back() + tol)
    throw InputError(path + ": covers [" + std::to_string(t.front()) + ", " + std::to_string(t.back()) +
                     "] s, outside the measurement's [" + std::to_string(data.t().front()) + ", " +
                     std::to_string(data.t().back()) + "] s: not a replay of this record");
  SimLeg leg;
  leg.q_hip = data.one_joint ? std::vector<double>(data.size(), 0.0)
                             : Interpolate(t, p.columns[p.Find("q_hip_sim")], data.t());
  leg.q_knee = Interpolate(t, p.columns[p.Find("q_knee_sim")], data.t());
  leg.covered.resize(data.size());
  for (size_t i = 0; i < data.size(); ++i)
    leg.covered[i] = data.t()[i] >= t.front() - 1e-9 && data.t()[i] <= t.back() + 1e-9;
  for (size_t i = 0; i < data.size(); ++i)
    if (!std::isfinite(leg.q_hip[i]) || !std::isfinite(leg.q_knee[i]))
      throw InputError(path + ": simulated angles are not finite near t = " + std::to_string(data.t()[i]) + " s");
  return leg;
}

// The label of a --sim file: its folder's name (a `replay --out DIR` writes DIR/replay.csv), else
// the file's name.
std::string SimLabel(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string dir = p.parent_path().filename().string();
  return dir.empty() || dir == "." ? p.filename().string() : dir;
}

CommandRunner RegisterRenderReplay(CLI::App& app) {
  struct Opts {
    std::string params, measured, out, predicted, mjcf, map, side = "r";
    std::vector<std::string> sims, sim_labels;
    RenderOptions render;
  };
  auto o = std::make_shared<Opts>();
  CLI::App* sub = app.add_subcommand(
      "render-replay", "MP4 video of measured data: the leg follows q_hip/q_knee, overlays compare the "
                       "measured torque with the twin's estimate");
  sub->add_option("--params", o->params, "MODEL.yaml (lumped parameters, passive model, effects)")->required();
  sub->add_option("--measured", o->measured,
                  "measured-data CSV (t, q_hip, q_knee, tau_hip, tau_knee, emg_*), or an OpenSim .mot/.sto motion "
                  "file (kinematics only: the torque charts show the twin alone)")
      ->required();
  sub->add_option("--side", o->side, "leg of an OpenSim motion file: r (hip_flexion_r, knee_angle_r) or l");
  sub->add_option("-o,--out", o->out, "output video (MP4, H.264)")->required();
  sub->add_option("--predicted", o->predicted,
                  "twin's prediction CSV (t,tau_hip,tau_knee, as written by `predict`); computed if absent");
  sub->add_option("--map", o->map, "column map of a foreign --measured CSV or a ROS 2 bag (as `predict`'s)");
  sub->add_option("--sim", o->sims,
                  "a `replay` output (DIR/replay.csv) of this record: adds a translucent ghost leg at its "
                  "simulated angles (red, then green, magenta, orange); repeatable");
  sub->add_option("--sim-label", o->sim_labels, "label of each --sim, in order (default: its folder's name)");
  sub->add_option("--mjcf", o->mjcf, "MJCF model to use instead of the shipped one");
  sub->add_option("--width", o->render.width, "frame width, px (even)")->check(CLI::Range(16, 8192));
  sub->add_option("--height", o->render.height, "frame height, px (even)")->check(CLI::Range(16, 8192));
  sub->add_option("--fps", o->render.fps, "frames per second of data time")->check(CLI::Range(1.0, 240.0));
  sub->add_flag("--shadows", o->render.shadows, "render shadows (about 2x slower with OSMesa)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    const LegParams params = ReadModelFile(o->params);
    const MeasuredData data = ReadMeasuredKinematics(o->measured, o->map, o->side);
    CheckRecordFitsModel(params, o->params, data);
    const std::string mjcf = o->mjcf.empty() ? ExowheelMjcfPath(params.human.has_value()) : o->mjcf;
    Plant plant(mjcf);
    plant.SetParams(params);
    if (o->sim_labels.size() > o->sims.size())
      throw InputError("render-replay: " + std::to_string(o->sim_labels.size()) + " --sim-label for " +
                       std::to_string(o->sims.size()) + " --sim");
    std::vector<SimLeg> sims;
    std::vector<GhostLegStyle> styles;
    for (size_t k = 0; k < o->sims.size(); ++k) {
      sims.push_back(ReadSimLeg(o->sims[k], data));
      sims.back().label = k < o->sim_labels.size() ? o->sim_labels[k] : SimLabel(o->sims[k]);
      styles.push_back({"_ghost" + std::to_string(k + 1), kGhostColours[k % std::size(kGhostColours)].rgba});
    }
    // Without --sim the video renders the plant's own model, posed through the hinges hip/knee.
    std::unique_ptr<GhostLegModel> ghosts;
    if (!sims.empty()) ghosts = std::make_unique<GhostLegModel>(mjcf, styles, params.L1);

    std::vector<double> est[2];
    if (!o->predicted.empty()) {
      ReadPredicted(o->predicted, data, est);
    } else {
      const Prediction p = PredictTorque(plant, DeriveKinematics(data));
      est[0] = p.tau_S[0];
      est[1] = p.tau_S[1];
    }

    const double dt = MedianStep(data.t());
    std::vector<std::vector<double>> emg;
    for (const char* m : {"GMAX", "VM", "RF", "ST", "GAS"})
      if (const std::vector<double>* col = data.Column(std::string("emg_") + m)) {
        o->render.emg_names.push_back(m);
        emg.push_back(Envelope(*col, 1.0 / dt));
      }

    const auto wall0 = std::chrono::steady_clock::now();
    if (!sims.empty()) o->render.legend.push_back({"measured", {0.25, 0.45, 0.85}});  // the exoskeleton's blue
    for (size_t k = 0; k < sims.size(); ++k)
      o->render.legend.push_back({sims[k].label + " (simulated)",
                                  {styles[k].rgba[0], styles[k].rgba[1], styles[k].rgba[2]}});
    for (size_t k = 0; k < sims.size(); ++k)
      std::fprintf(stderr, "render-replay: ghost leg %zu (%s): %s from %s\n", k + 1,
                   kGhostColours[k % std::size(kGhostColours)].name, sims[k].label.c_str(),
                   o->sims[k].c_str());
    const std::unique_ptr<VideoSink> video =
        OpenVideo(ghosts ? ghosts->model() : plant.model(), o->out, o->render);
    for (size_t i = 0; i < data.size(); ++i) {
      OverlaySample s;
      s.t = data.t()[i];
      s.q_hip = data.q_hip()[i];
      s.q_knee = data.q_knee()[i];
      s.tau_meas[0] = HasTorque(data) ? data.tau_hip()[i] : NAN;  // NaN: not drawn
      s.tau_meas[1] = HasTorque(data) ? data.tau_knee()[i] : NAN;
      s.tau_est[0] = est[0][i];
      s.tau_est[1] = est[1][i];
      for (const auto& e : emg) s.emg.push_back(e[i]);
      if (!ghosts) {
        video->AddSample(s);
        continue;
      }
      ghosts->SetLeg(-1, s.q_hip, s.q_knee);
      for (size_t k = 0; k < sims.size(); ++k)
        if (sims[k].covered[i]) ghosts->SetLeg(int(k), sims[k].q_hip[i], sims[k].q_knee[i]);
        else ghosts->SetLeg(int(k), s.q_hip, s.q_knee);
      video->AddSample(ghosts->data(), s);
    }
    video->Finish(data.t().back() + dt);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const double duration = data.t().back() + dt - data.t().front();
    std::fprintf(stderr, "render-replay: wrote %s: %ld frames (%.2f s at %g fps, %dx%d, %s) in %.2f s wall, "
                 "%.2fx real time\n", o->out.c_str(), video->frames(), duration, o->render.fps,
                 o->render.width, o->render.height, video->codec().c_str(), wall, duration / wall);
    return 0;
  };
}

const CommandRegistration kRenderReplay(RegisterRenderReplay);

}  // namespace
}  // namespace exotwin
