// `exotwin replay` (DESIGN.md): the twin simulated forward on measured records. The MuJoCo plant
// carrying the model's effects (Plant::CarryEffects) is driven by the record's actuator torque and
// restarted from the measured state every `horizon` seconds; the simulated angles are scored against
// the measured ones.
//
// Method:
//  - input: tau_R = -tau_S, the reading with the model's sensor effects inverted (ActuatorTorque
//    FromReading), or the commanded torque (cmd_* columns); linearly interpolated at the middle of
//    each physics step (model timestep, 1 ms) and held over the step (ReplaySeries::hold: the last
//    sample at or before that middle).
//  - restart state: the measured angle and its velocity (DeriveAngleRates: central differences of
//    the angle low-passed by the zero-phase 2nd-order Butterworth at the cutoff), at the window's first
//    sample. The angle is not low-passed: the filter's bias where the motion has content near the
//    cutoff (a dead band's knocks, a strap's mode, the gait's harmonics) would be held over the whole
//    window, while the measured angle's own error is the encoder's noise (tests/diagnosis/
//    replay_test.cc, Replay.TheRestartAngleIsTheMeasuredOne). The integrator is handed the velocity
//    half a step earlier, qd - dt/2 qdd (qdd the derived acceleration, 0 where the series has none):
//    MuJoCo's semi-implicit Euler steps q(t + dt) = q(t) + dt qd(t + dt), so the velocity it holds
//    with q(t) is the mean over the step before, (q(t) - q(t - dt)) / dt = qd(t) - dt/2 qdd(t) +
//    O(dt^2) (DESIGN.md "Sampling instant of a joint node"); the derived qd(t), a central difference,
//    runs dt/2 qdd ahead of it, and that offset grows over the window (the real rig's twin swung by
//    sums of sines, restarted from its exact angles: 0.33 / 1.06 mrad RMS hip / knee half a step
//    behind, 1.75 / 7.68 mrad at the derived velocity; tests/diagnosis/replay_test.cc).
//    A dead band (backlash) restarts against the flank the rigid torque of the restart state's motion
//    (angle, velocity, acceleration) presses, what the gear transmits in contact (Plant::Reset's
//    `qdd`). A strap (series compliance) restarts by a run-in: from the restart state run_in
//    before the window (the series' first sample at the earliest), the strap at the deflection that
//    carries the part behind it at the restart state's acceleration there (Plant::Reset's `qdd`), the
//    measured joints follow the restart state's motion step by step (Plant::Restate, linear between
//    samples) under the input torque while the strap moves by its own dynamics; at the window's start
//    the measured joints take the restart state and the window runs free. run_in =
//    Plant::InternalSettlingTime() (a strap's start error decays below 1 %), at most one horizon.
//    The run-in's samples are not scored (they may lie in an earlier window or part).
//  - windows: from the first sample, each window starts at the first sample at or after the previous
//    window's start + horizon and is scored on its samples up to start + horizon (its first sample,
//    the restart, excluded); a last part shorter than the horizon is not run.
//    Quiet windows (ReplaySeries::quiet_windows, the motion fit's): where the motion has fast content
//    that the restart velocity (derived at the cutoff) misses, a dead band's knocks above all, the
//    restart state is wrong and the window's outcome chaotic for any model (a 0.03 rad hip band's
//    truth twin replaying its own 20 s gait record: 0.78 deg RMS every 0.5 s, 0.009 deg in quiet
//    windows; tests/app/replay_cli_test.cc, tests/diagnosis/replay_test.cc). So a window restarts at its first sample
//    only where that is quiet (ReplaySeries::fast <= quiet_level), else at the sample of least fast
//    content within half a horizon after it; it is scored up to start + horizon or up to its first
//    sample that is not quiet (the knock it cannot carry the state through), and not at all where that
//    leaves less than kReplayQuietShortest; the next window's first sample is the first at or after
//    start + horizon. A series quiet throughout has the every-horizon windows.
//  - the simulated angle at a sample time is interpolated linearly between the bracketing steps.
#pragma once
#include <cmath>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "formats/measured_data.h"
#include "sim/plant.h"

namespace exotwin {

enum class ReplayInput { kTorque, kCommand };

// One record on its time base, ready to replay.
struct ReplaySeries {
  std::string source;
  std::vector<double> t;
  double t_start = std::nan("");         // the record's first time (a term's t origin); NaN: t.front()
  std::vector<double> q[2];              // measured angle, rad (scored)
  // restart state: angle (rad; empty: the measured one, q), velocity (rad/s) and acceleration
  // (rad/s^2; empty: 0) derived at the cutoff
  std::vector<double> q0[2], qd0[2], qdd0[2];
  const std::vector<double>& RestartAngle(int j) const { return q0[j].empty() ? q[j] : q0[j]; }
  std::vector<double> tau_R[2];          // actuator torque input, N m
  // The input between samples: false, linear interpolation (a rig's continuously sampled torque);
  // true, each sample held until the next (a zero-order hold: the twin's joint modules log the torque
  // they apply over the coming step, DESIGN.md "Sampling instant of a joint node").
  bool hold = false;
  // Fast content of the measured motion at each sample (rad/s, SetRestartState): the largest, within
  // kReplayQuietSpan s either side, of sum_j |the angle's central difference - the restart velocity|,
  // what the restart velocity misses there (a dead band's knocks; the encoder's noise).
  std::vector<double> fast;
  // A sample is quiet where fast <= quiet_level: kReplayQuietFactor x the series' quietest tenth (the
  // 10 % quantile of fast).
  double quiet_level = 0;
  // The window schedule (replay.h, "windows"): false, a window every horizon; true, quiet windows.
  bool quiet_windows = false;
};

// The default cutoff of the restart state's filter, Hz.
constexpr double kReplayCutoffHz = 10.0;
// Quiet windows (ReplaySeries::quiet_windows): the span of the fast content's maximum (s, either side),
// the quiet level's factor over the series' quietest tenth, the shortest window scored (s).
constexpr double kReplayQuietSpan = 0.02;
constexpr double kReplayQuietFactor = 10.0;
constexpr double kReplayQuietShortest = 0.1;

// tau_R on t from a measured reading tau_S with the sensor effects of fx inverted, in reverse order
// of the model file (tau_S = (reading - offset) / (1 + gain); a delayed reading is read value s later,
// held at the record's end): the torque the actuator applied. A sensor-stage term (tau_S += value *
// expr, expr's tau_R the actuator torque) is inverted with the others by fixed-point iteration on
// tau_R over the whole series (at most kTermInverseIterations, to 1e-10 N m relative); its motion
// signals (q, qd, qdd, ...) are `motion`'s measured angle and restart state (t from t's first sample).
// Throws InputError for a term whose iteration does not converge (|value d expr / d tau_R| >= 1: not
// invertible) or that reads the motion where `motion` is null.
constexpr int kTermInverseIterations = 100;
void ActuatorTorqueFromReading(const PlantEffects& fx, const std::vector<double>& t,
                               const std::vector<double> tau_S[2], std::vector<double> tau_R[2],
                               const ReplaySeries* motion = nullptr);

// The series of a record: t, q (measured), restart state at cutoff_hz, and the input (kTorque: from
// tau_hip/tau_knee through ActuatorTorqueFromReading; kCommand: cmd_hip/cmd_knee, cmd_knee alone for a
// one-joint record, whose held hip is given 0). Throws InputError naming the record for --input command
// without those columns.
ReplaySeries ReplaySeriesOf(const MeasuredData& data, const PlantEffects& fx, ReplayInput input, double cutoff_hz);
// The same from kinematics and a measured reading (diagnose's records).
ReplaySeries ReplaySeriesOf(const std::string& source, const std::vector<double>& t, const std::vector<double> q[2],
                            const std::vector<double> tau_S[2], const PlantEffects& fx, double cutoff_hz);
// The same on a series whose source, t and q the caller filled (e.g. moved in, not copied): the restart
// state and the input.
void CompleteReplaySeries(const std::vector<double> tau_S[2], const PlantEffects& fx, double cutoff_hz, ReplaySeries* s);
// The restart state of a series whose source, t and q are filled (q0 emptied: the restart angle is
// the measured one; qd0, qdd0 at cutoff_hz; fast and quiet_level), the rest kept. Throws InputError
// naming the source for a cutoff not below half the sample rate.
void SetRestartState(double cutoff_hz, ReplaySeries* s);

// One window of a replay: samples (start, stop) scored, restarted at start.
struct ReplayWindowSpan {
  size_t start = 0, stop = 0;
};
// The windows Replay simulates on samples [begin, end) of s (replay.h "windows"; s.quiet_windows).
std::vector<ReplayWindowSpan> ReplayWindows(const ReplaySeries& s, double horizon_s, size_t begin, size_t end);

struct ReplayScore {
  double sse[2] = {0, 0};  // sum of squared angle errors, rad^2
  size_t count = 0;        // scored samples
  size_t windows = 0;
  double Rmse(int j) const;
  void Add(const ReplayScore& o);
};

struct ReplayRecord {
  std::string source;
  ReplayScore score;
  // Samples [first, first + window.size()) of s.t, the part replayed: the simulated angle (NaN where not
  // scored) and the window index (-1 where not scored) of sample first + k at k.
  size_t first = 0;
  std::vector<double> sim[2];
  std::vector<int> window;
  // The same by the sample's index in s.t: NaN / -1 outside the part replayed too.
  double Sim(int j, size_t i) const;
  int Window(size_t i) const;
};

// The plant a replay drives: the MJCF `mjcf` (empty: the shipped EXOwheel model, with or without the
// human by params) realizing params, carrying its effects (ToPlantEffects: InputError naming `source`
// for an effect the plant cannot carry; *fx receives them when given) with joint limits and torque
// clamping off (Plant::FreeJointsAndTorque); a one-joint model's plant holds its hip at 0 (Plant::HoldHip),
// its knee following HKS05 eq. 4 with the device's R, C and the knee's effects.
std::unique_ptr<Plant> MakeReplayPlant(const LegParams& params, const std::string& source, const std::string& mjcf = "",
                                       PlantEffects* fx = nullptr);

// Replays samples [begin, end) of `s` with `plant` (parameters set and effects carried) in windows
// of horizon_s, driven by s.tau_R or, given, by `tau_R` (the same record's input for another twin's
// sensor effects; each the length of s.t). Throws InputError when [begin, end) is shorter than one
// horizon, SimulationError on divergence. Replays of one series with different plants may run on
// different threads.
ReplayRecord Replay(Plant& plant, const ReplaySeries& s, double horizon_s, size_t begin = 0,
                    size_t end = static_cast<size_t>(-1), const std::vector<double>* tau_R = nullptr);

// Replay with the windows shared between two threads: the first half of the windows on `plant`
// (this thread), the second on the plant second() returns, called on the other thread (where the
// caller may build it). Since each window restarts from the series' restart state, the record is
// Replay(plant, ...)'s bit for bit when the second plant is alike (same model, parameters and effects).
ReplayRecord ReplayOnTwoPlants(Plant& plant, const std::function<Plant&()>& second, const ReplaySeries& s,
                               double horizon_s, size_t begin = 0, size_t end = static_cast<size_t>(-1),
                               const std::vector<double>* tau_R = nullptr);

// One twin of ReplayTwoTwins: its plant, a second plant alike built when first asked for (on the thread
// that asks), and its input (nullptr: the series' tau_R).
struct ReplayTwin {
  Plant* plant = nullptr;
  std::function<Plant&()> second;
  const std::vector<double>* tau_R = nullptr;
};

// Two twins replayed on samples [begin, end) of `s` on two threads (threads >= 2; else one after the
// other): each thread runs its own twin's windows from the first on, then takes the other's windows
// not yet taken from the last on, on that twin's second plant; so twins of different costs share
// both cores to the end. Each record is Replay(*twins[k].plant, s, horizon_s, begin, end,
// twins[k].tau_R)'s bit for bit.
std::array<ReplayRecord, 2> ReplayTwoTwins(const ReplayTwin twins[2], const ReplaySeries& s, double horizon_s,
                                           int threads, size_t begin = 0, size_t end = static_cast<size_t>(-1));

}  // namespace exotwin
