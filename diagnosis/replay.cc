#include "diagnosis/replay.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <mutex>
#include <utility>

#include "core/error.h"
#include "core/parallel_for.h"
#include "dsp/statistics.h"
#include "sim/plant_effects.h"

namespace exotwin {

namespace {

// The reading before joint j's sensor effects: tau_S with them undone in reverse order; a term's
// value * expr taken off at the actuator torque `tau` (null: no term).
std::vector<double> ReadingBeforeSensor(const PlantEffects& fx, int j, const std::vector<double>& t,
                                        const std::vector<double>& tau_S, const std::vector<double>* tau,
                                        const ReplaySeries* motion) {
  std::vector<double> s = tau_S;
  for (auto it = fx.sensor[j].rbegin(); it != fx.sensor[j].rend(); ++it) {
    if (it->expr.empty()) {
      FindFamily(it->name)->off_reading(it->value, t, &s);
      continue;
    }
    if (!tau) continue;
    const TermExpr& expr = CachedTermExpr(it->expr);
    const bool moves = expr.Reads("q") || expr.Reads("qd") || expr.Reads("qdd") || expr.Reads("q_hip") ||
                       expr.Reads("q_knee") || expr.Reads("qd_hip") || expr.Reads("qd_knee");
    if (moves && !motion)
      throw InputError("sensor term \"" + it->expr + "\": reads the motion, which this reading's inversion is not given");
    std::vector<TermSignals> rows(s.size());
    for (size_t i = 0; i < s.size(); ++i) {
      TermSignals& x = rows[i];
      x.tau_R = (*tau)[i], x.t = t[i] - t[0];
      if (!moves) continue;
      auto at = [&](const std::vector<double>& v) { return v.empty() ? 0.0 : v[i]; };
      x.q_hip = motion->q[0][i], x.q_knee = motion->q[1][i];
      x.qd_hip = at(motion->qd0[0]), x.qd_knee = at(motion->qd0[1]);
      x.q = j == 0 ? x.q_hip : x.q_knee, x.qd = j == 0 ? x.qd_hip : x.qd_knee, x.qdd = at(motion->qdd0[j]);
    }
    std::vector<double> v(s.size());
    expr.EvalRows(rows, v.data());
    for (size_t i = 0; i < s.size(); ++i) s[i] -= it->value * v[i];
  }
  return s;
}

}  // namespace

void ActuatorTorqueFromReading(const PlantEffects& fx, const std::vector<double>& t,
                               const std::vector<double> tau_S[2], std::vector<double> tau_R[2],
                               const ReplaySeries* motion) {
  for (int j = 0; j < 2; ++j) {
    std::vector<double> s = ReadingBeforeSensor(fx, j, t, tau_S[j], nullptr, motion);
    tau_R[j].resize(s.size());
    for (size_t i = 0; i < s.size(); ++i) tau_R[j][i] = -s[i];
    bool terms = false;
    for (const SensorEffect& e : fx.sensor[j]) terms |= !e.expr.empty();
    if (!terms) continue;
    // tau_R = -(reading with the effects undone at tau_R): a fixed point, a contraction where
    // |value d expr / d tau_R| < 1.
    for (int k = 0;; ++k) {
      s = ReadingBeforeSensor(fx, j, t, tau_S[j], &tau_R[j], motion);
      double change = 0, scale = 1;
      for (size_t i = 0; i < s.size(); ++i) {
        change = std::max(change, std::abs(-s[i] - tau_R[j][i]));
        scale = std::max(scale, std::abs(s[i]));
        tau_R[j][i] = -s[i];
      }
      if (change <= 1e-10 * scale) break;
      if (k + 1 == kTermInverseIterations || !std::isfinite(change))
        throw InputError("the " + std::string(j == 0 ? "hip" : "knee") + "'s sensor terms: the actuator torque from the "
                         "reading did not converge in " + std::to_string(kTermInverseIterations) +
                         " fixed-point steps (last change " + std::to_string(change) +
                         " N m): not invertible where |value d expr / d tau_R| >= 1");
    }
  }
}

void SetRestartState(double cutoff_hz, ReplaySeries* out) {
  const Sampling sampling = ExamineSampling(out->t, out->source);
  for (int j = 0; j < 2; ++j) {
    out->q0[j] = std::vector<double>();  // the measured angle itself (replay.h)
    AngleRates rates = DeriveAngleRates(sampling, out->t, out->q[j], cutoff_hz, out->source);
    out->qd0[j] = std::move(rates.qd);
    out->qdd0[j] = std::move(rates.qdd);
  }
  // The fast content (replay.h): |central difference - restart velocity| summed over the joints, then
  // its largest within kReplayQuietSpan either side (a monotone queue of candidates for the maximum).
  const std::vector<double>& t = out->t;
  const size_t n = t.size();
  std::vector<double> miss(n, 0.0);
  for (size_t i = 0; i < n && n >= 2; ++i) {
    const size_t a = i > 0 ? i - 1 : 0, b = i + 1 < n ? i + 1 : n - 1;
    for (int j = 0; j < 2; ++j)
      miss[i] += std::abs((out->q[j][b] - out->q[j][a]) / (t[b] - t[a]) - out->qd0[j][i]);
  }
  out->fast.assign(n, 0.0);
  std::deque<size_t> top;  // indices of decreasing miss, within the span of the sample at hand
  size_t next = 0;
  for (size_t i = 0; i < n; ++i) {
    for (; next < n && t[next] <= t[i] + kReplayQuietSpan + 1e-12; ++next) {
      while (!top.empty() && miss[top.back()] <= miss[next]) top.pop_back();
      top.push_back(next);
    }
    while (t[top.front()] < t[i] - kReplayQuietSpan - 1e-12) top.pop_front();
    out->fast[i] = miss[top.front()];
  }
  std::vector<double> fast = out->fast;
  out->quiet_level = n > 0 ? kReplayQuietFactor * PercentileInPlace(fast, 0.1) : 0.0;
}

ReplaySeries ReplaySeriesOf(const std::string& source, const std::vector<double>& t, const std::vector<double> q[2],
                            const std::vector<double> tau_S[2], const PlantEffects& fx, double cutoff_hz) {
  ReplaySeries s;
  s.source = source;
  s.t = t;
  s.q[0] = q[0];
  s.q[1] = q[1];
  CompleteReplaySeries(tau_S, fx, cutoff_hz, &s);
  return s;
}

void CompleteReplaySeries(const std::vector<double> tau_S[2], const PlantEffects& fx, double cutoff_hz, ReplaySeries* s) {
  SetRestartState(cutoff_hz, s);
  ActuatorTorqueFromReading(fx, s->t, tau_S, s->tau_R, s);
}

ReplaySeries ReplaySeriesOf(const MeasuredData& data, const PlantEffects& fx, ReplayInput input, double cutoff_hz) {
  if (input == ReplayInput::kTorque) {
    const std::vector<double> q[2] = {data.q_hip(), data.q_knee()};
    const std::vector<double> tau_S[2] = {data.tau_hip(), data.tau_knee()};
    return ReplaySeriesOf(data.source, data.t(), q, tau_S, fx, cutoff_hz);
  }
  ReplaySeries s;
  s.source = data.source;
  s.t = data.t();
  s.q[0] = data.q_hip();
  s.q[1] = data.q_knee();
  const char* names[2] = {"cmd_hip", "cmd_knee"};
  for (int j = 0; j < 2; ++j) {
    if (j == 0 && data.one_joint) {  // no hip: the embedding's held hip gets no command
      s.tau_R[0].assign(s.t.size(), 0.0);
      continue;
    }
    const std::vector<double>* c = data.Column(names[j]);
    if (!c)
      throw InputError(data.source + ": --input command needs the column '" + names[j] +
                       "' (the commanded actuator torque, N m); the record has none");
    s.tau_R[j] = *c;
  }
  SetRestartState(cutoff_hz, &s);
  return s;
}

double ReplayScore::Rmse(int j) const { return count ? std::sqrt(sse[j] / static_cast<double>(count)) : 0.0; }

void ReplayScore::Add(const ReplayScore& o) {
  sse[0] += o.sse[0];
  sse[1] += o.sse[1];
  count += o.count;
  windows += o.windows;
}

std::unique_ptr<Plant> MakeReplayPlant(const LegParams& params, const std::string& source, const std::string& mjcf,
                                       PlantEffects* fx) {
  const PlantEffects effects = ToPlantEffects(params, source);
  auto plant = std::make_unique<Plant>(mjcf.empty() ? ExowheelMjcfPath(params.human.has_value()) : mjcf);
  plant->SetParams(params);
  plant->CarryEffects(effects);
  plant->FreeJointsAndTorque();
  if (params.one_joint) plant->HoldHip();  // the embedding's hip (model/one_joint.h)
  if (fx) *fx = effects;
  return plant;
}

double ReplayRecord::Sim(int j, size_t i) const {
  return i >= first && i - first < sim[j].size() ? sim[j][i - first] : std::nan("");
}

int ReplayRecord::Window(size_t i) const { return i >= first && i - first < window.size() ? window[i - first] : -1; }

std::vector<ReplayWindowSpan> ReplayWindows(const ReplaySeries& s, double horizon_s, size_t begin, size_t end) {
  const std::vector<double>& t = s.t;
  end = std::min(end, t.size());
  const bool quiet = s.quiet_windows && s.fast.size() == t.size();
  auto Quiet = [&](size_t i) { return !quiet || s.fast[i] <= s.quiet_level; };
  // The window's restart: its first sample where that is quiet, else the least fast within half a horizon.
  auto Restart = [&](size_t first) {
    if (Quiet(first)) return first;
    size_t best = first;
    for (size_t i = first; i < end && t[i] <= t[first] + 0.5 * horizon_s + 1e-12; ++i)
      if (s.fast[i] < s.fast[best]) best = i;
    return best;
  };
  std::vector<ReplayWindowSpan> windows;
  size_t start = begin < end ? Restart(begin) : end;
  while (start < end && t[end - 1] - t[start] >= horizon_s) {
    size_t stop = start + 1;
    while (stop < end && t[stop] <= t[start] + horizon_s + 1e-12 && Quiet(stop)) ++stop;
    if (!quiet || t[stop - 1] - t[start] >= kReplayQuietShortest) windows.push_back({start, stop});
    start = static_cast<size_t>(std::lower_bound(t.begin() + static_cast<long>(start), t.begin() + static_cast<long>(end),
                                                 t[start] + horizon_s - 1e-12) - t.begin());
    if (start < end) start = Restart(start);
  }
  return windows;
}

namespace {

// Simulates window w (restarted at sample `start`, scored on its samples below `end` up to start +
// horizon_s) with `plant`, writing the simulated angles and the window index of its samples into out
// (sim and window by the sample's index less out->first). The window's result depends on nothing before
// it: the plant restarts from the series' restart state (run-in included).
void ReplayWindow(Plant& plant, const ReplaySeries& s, const std::vector<double>* u, double horizon_s, size_t start,
                  size_t end, int w, ReplayRecord* out) {
  const std::vector<double>& t = s.t;
  const size_t begin = out->first;
  const double dt = plant.timestep();
  // A strap's run-in (replay.h): its settling time, at most one horizon.
  const double run_in_s = std::min(horizon_s, plant.InternalSettlingTime());
  size_t in = start;  // input interpolation: t[in] <= time < t[in + 1]
  auto Input = [&](double time) -> Eigen::Vector2d {
    while (in + 1 < t.size() && t[in + 1] <= time) ++in;
    if (s.hold || in + 1 >= t.size() || time <= t[in]) return {u[0][in], u[1][in]};
    const double a = (time - t[in]) / (t[in + 1] - t[in]);
    return {u[0][in] + a * (u[0][in + 1] - u[0][in]), u[1][in] + a * (u[1][in + 1] - u[1][in])};
  };
  // The restart state's acceleration at sample i (0 where the series has none) and the velocity the
  // integrator holds with the angle there: half a step earlier (replay.h).
  auto Acceleration = [&](size_t i) -> Eigen::Vector2d {
    return {s.qdd0[0].empty() ? 0.0 : s.qdd0[0][i], s.qdd0[1].empty() ? 0.0 : s.qdd0[1][i]};
  };
  auto StepVelocity = [&](size_t i) -> Eigen::Vector2d {
    return Eigen::Vector2d(s.qd0[0][i], s.qd0[1][i]) - 0.5 * dt * Acceleration(i);
  };
  const std::vector<double>* angle0[2] = {&s.RestartAngle(0), &s.RestartAngle(1)};
  const double t0 = t[start], t_end = t0 + horizon_s;
  // The run-in's first sample: run_in_s before t0, the series' first at the earliest.
  const size_t r = run_in_s > 0 ? static_cast<size_t>(std::lower_bound(t.begin(), t.begin() + static_cast<long>(start),
                                                                        t0 - run_in_s - 1e-12) - t.begin())
                                : start;
  // The restart state's acceleration: a dead band's flank is the one the rigid torque of that motion
  // presses (what the gear transmits in contact), a strap's deflection the one carrying it.
  const Eigen::Vector2d qdd0 = Acceleration(r);
  plant.SetTermTimeOrigin(std::isnan(s.t_start) ? t.front() : s.t_start);  // a term's t: from the record's start
  plant.Reset({(*angle0[0])[r], (*angle0[1])[r]}, StepVelocity(r), t[r], &qdd0);
  if (r < start) {
    // The measured joints follow the restart state's motion (linear between samples), each step
    // driven by the input; the internal hinges move by their own dynamics.
    in = r;
    size_t k = r;
    while (plant.time() < t0 - 0.5 * dt) {
      const double time = plant.time();
      while (k + 1 < start && t[k + 1] <= time) ++k;
      const double a = std::clamp((time - t[k]) / (t[k + 1] - t[k]), 0.0, 1.0);
      plant.Restate({(*angle0[0])[k] + a * ((*angle0[0])[k + 1] - (*angle0[0])[k]),
                     (*angle0[1])[k] + a * ((*angle0[1])[k + 1] - (*angle0[1])[k])},
                    StepVelocity(k) + a * (StepVelocity(k + 1) - StepVelocity(k)), time);
      plant.Step(Input(time + 0.5 * dt));
    }
    plant.Restate({(*angle0[0])[start], (*angle0[1])[start]}, StepVelocity(start), t0);
  }
  in = start;
  Eigen::Vector2d q_prev = plant.q();
  double time_prev = t0;
  for (size_t i = start + 1; i < end && t[i] <= t_end + 1e-12; ++i) {
    while (plant.time() < t[i] - 1e-12) {
      q_prev = plant.q();
      time_prev = plant.time();
      plant.Step(Input(plant.time() + 0.5 * dt));
    }
    const double span = plant.time() - time_prev;
    const double a = span > 0 ? (t[i] - time_prev) / span : 1.0;
    const Eigen::Vector2d qs = q_prev + a * (plant.q() - q_prev);
    for (int j = 0; j < 2; ++j) out->sim[j][i - begin] = qs[j];
    out->window[i - begin] = w;
  }
}

// The record of a replay of samples [begin, end) of s before its windows run: the checks, the NaN
// series, the windows.
ReplayRecord StartRecord(const ReplaySeries& s, double horizon_s, size_t begin, size_t* end,
                         std::vector<ReplayWindowSpan>* spans) {
  const std::vector<double>& t = s.t;
  *end = std::min(*end, t.size());
  if (!(horizon_s > 0)) throw InputError(s.source + ": replay horizon " + std::to_string(horizon_s) + " s, expected > 0");
  if (begin >= *end || t[*end - 1] - t[begin] < horizon_s)
    throw InputError(s.source + ": replay horizon " + std::to_string(horizon_s) + " s is longer than the part replayed (" +
                     std::to_string(begin < *end ? t[*end - 1] - t[begin] : 0.0) + " s)");
  ReplayRecord out;
  out.source = s.source;
  out.first = begin;
  for (auto& v : out.sim) v.assign(*end - begin, std::nan(""));
  out.window.assign(*end - begin, -1);
  *spans = ReplayWindows(s, horizon_s, begin, *end);
  return out;
}

// The score of a record whose windows have run, in sample order: the same sums whichever plant
// simulated which window.
void ScoreRecord(const ReplaySeries& s, size_t windows, ReplayRecord* out) {
  for (size_t k = 0; k < out->window.size(); ++k) {
    if (out->window[k] < 0) continue;
    for (int j = 0; j < 2; ++j) {
      const double e = out->sim[j][k] - s.q[j][out->first + k];
      out->score.sse[j] += e * e;
    }
    ++out->score.count;
  }
  out->score.windows = windows;
}

ReplayRecord ReplayOn(Plant& plant, const std::function<Plant&()>* second, const ReplaySeries& s, double horizon_s,
                      size_t begin, size_t end, const std::vector<double>* tau_R) {
  const std::vector<double>* u = tau_R ? tau_R : s.tau_R;
  std::vector<ReplayWindowSpan> spans;
  ReplayRecord out = StartRecord(s, horizon_s, begin, &end, &spans);
  const size_t W = spans.size();
  auto Windows = [&](Plant& p, size_t w0, size_t w1) {
    for (size_t w = w0; w < w1; ++w) ReplayWindow(p, s, u, horizon_s, spans[w].start, spans[w].stop, static_cast<int>(w), &out);
  };
  if (second && W >= 2) {
    ParallelFor(2, 2, [&](size_t half) {
      if (half == 0) Windows(plant, 0, W / 2);
      else Windows((*second)(), W / 2, W);
    });
  } else {
    Windows(plant, 0, W);
  }
  ScoreRecord(s, W, &out);
  return out;
}

}  // namespace

ReplayRecord Replay(Plant& plant, const ReplaySeries& s, double horizon_s, size_t begin, size_t end,
                    const std::vector<double>* tau_R) {
  return ReplayOn(plant, nullptr, s, horizon_s, begin, end, tau_R);
}

ReplayRecord ReplayOnTwoPlants(Plant& plant, const std::function<Plant&()>& second, const ReplaySeries& s,
                               double horizon_s, size_t begin, size_t end, const std::vector<double>* tau_R) {
  return ReplayOn(plant, &second, s, horizon_s, begin, end, tau_R);
}

std::array<ReplayRecord, 2> ReplayTwoTwins(const ReplayTwin twins[2], const ReplaySeries& s, double horizon_s,
                                           int threads, size_t begin, size_t end) {
  std::array<ReplayRecord, 2> out;
  std::vector<ReplayWindowSpan> spans;
  out[0] = StartRecord(s, horizon_s, begin, &end, &spans);
  out[1] = out[0];  // the same part and windows, nothing simulated yet
  const size_t W = spans.size();
  const std::vector<double>* u[2];
  for (int k = 0; k < 2; ++k) u[k] = twins[k].tau_R ? twins[k].tau_R : s.tau_R;
  auto Run = [&](int k, Plant& p, size_t w) {
    ReplayWindow(p, s, u[k], horizon_s, spans[w].start, spans[w].stop, static_cast<int>(w), &out[k]);
  };
  if (threads < 2) {
    for (int k = 0; k < 2; ++k)
      for (size_t w = 0; w < W; ++w) Run(k, *twins[k].plant, w);
  } else {
    // Twin k's windows not yet taken: [next[k], last[k]).
    size_t next[2] = {0, 0}, last[2] = {W, W};
    std::mutex m;
    auto Take = [&](int k, bool front, size_t* w) {
      std::lock_guard<std::mutex> lock(m);
      if (next[k] >= last[k]) return false;
      *w = front ? next[k]++ : --last[k];
      return true;
    };
    ParallelFor(2, 2, [&](size_t kk) {
      const int k = static_cast<int>(kk), o = 1 - k;
      size_t w;
      while (Take(k, true, &w)) Run(k, *twins[k].plant, w);
      Plant* helper = nullptr;  // the other twin's second plant, once there is a window to take
      while (Take(o, false, &w)) {
        if (!helper) helper = &twins[o].second();
        Run(o, *helper, w);
      }
    });
  }
  for (int k = 0; k < 2; ++k) ScoreRecord(s, W, &out[k]);
  return out;
}

}  // namespace exotwin
