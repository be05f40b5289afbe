// `exotwin render-replay`: a video of measured data (a measured-data CSV or an OpenSim motion file).
// The twin's leg follows the measured angles;
// overlays show the measured torque against the twin's estimate (from --predicted, else computed
// with `predict`'s model) and EMG envelopes of any emg_* columns.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "formats/csv_table.h"
#include "formats/measured_data.h"
#include "formats/model_file.h"
#include "formats/opensim_kinematics.h"
#include "diagnosis/predict.h"
#include "app/commands.h"
#include "core/error.h"
#include "dsp/butterworth.h"
#include "render/render_plugin.h"
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

CommandRunner RegisterRenderReplay(CLI::App& app) {
  struct Opts {
    std::string params, measured, out, predicted, mjcf, side = "r";
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
  sub->add_option("--mjcf", o->mjcf, "MJCF model to use instead of the shipped one");
  sub->add_option("--width", o->render.width, "frame width, px (even)")->check(CLI::Range(16, 8192));
  sub->add_option("--height", o->render.height, "frame height, px (even)")->check(CLI::Range(16, 8192));
  sub->add_option("--fps", o->render.fps, "frames per second of data time")->check(CLI::Range(1.0, 240.0));
  sub->add_flag("--shadows", o->render.shadows, "render shadows (about 2x slower with OSMesa)");
  return [sub, o]() -> int {
    if (!*sub) return -1;
    const LegParams params = ReadModelFile(o->params);
    const MeasuredData data = ReadMeasuredKinematics(o->measured, "", o->side);
    CheckRecordFitsModel(params, o->params, data);
    Plant plant(o->mjcf.empty() ? ExowheelMjcfPath(params.human.has_value()) : o->mjcf);
    plant.SetParams(params);

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
    const std::unique_ptr<VideoSink> video = OpenVideo(plant.model(), o->out, o->render);
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
      video->AddSample(s);
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
