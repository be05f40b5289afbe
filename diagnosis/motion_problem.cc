// MotionProblem (motion_fit.h): the records as the motion fit sees them, the rollouts of the forward
// plant on their windows, the Jacobians and the weighted errors.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <mutex>

#include "core/error.h"
#include "core/parallel_for.h"
#include "diagnosis/motion_fit.h"
#include "diagnosis/motion_fit_internal.h"
#include "diagnosis/replay.h"
#include "formats/number_text.h"
#include "sim/mjcf_cache.h"
#include "sim/plant.h"

namespace exotwin {

namespace {

// MuJoCo's XML compiler keeps global state: plants are built one at a time.
std::mutex& BuildMutex() {
  static std::mutex m;
  return m;
}


bool AllZero(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; });
}

}  // namespace

namespace motion {

double RmsAboutMean(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x;
  m /= static_cast<double>(std::max<size_t>(1, v.size()));
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
}

// The restart state's cutoff of a record (motion_fit.h): DiagnoseOptions::motion_cutoff_hz, at most a
// tenth of the record's sample rate (a fifth of its Nyquist frequency).
double MotionCutoff(const DiagnoseOptions& opt, const MeasuredData& data) {
  return std::min(opt.motion_cutoff_hz, 0.1 / ExamineSampling(data.t(), data.source).dt);
}

// The motion fit's checks of one record (motion_fit.h DiagnoseByMotion): returns the split (first
// held-out sample) and whether the torque reading drives it (else cmd_*).
size_t CheckMotionRecord(const LegParams& params, const MeasuredData& data, const DiagnoseOptions& opt, bool* by_reading) {
  const double H = opt.replay_horizon_s;
  if (!(H > 0)) throw InputError("diagnose --fit motion: window " + NumberText(H) + " s, expected > 0");
  const int j0 = params.one_joint ? 1 : 0;
  const std::vector<double>& t = data.t();
  const size_t n = t.size();
  const double T = t.back() - t.front();
  const double t_split = t.front() + (1 - opt.holdout_fraction) * T;
  const size_t split = static_cast<size_t>(std::lower_bound(t.begin(), t.end(), t_split) - t.begin());
  const double fit_s = split > 0 ? t[split - 1] - t.front() : 0.0, held_s = t.back() - t[std::min(split, n - 1)];
  if (fit_s < H || held_s < H)
    throw InputError(data.source + ": the motion fit's windows of " + NumberText(H) + " s do not fit the record: its fit part is " +
                     NumberText(fit_s, 4) + " s and its held-out part " + NumberText(held_s, 4) + " s (holdout " +
                     NumberText(opt.holdout_fraction) + " of " + NumberText(T, 4) +
                     " s); expected each at least one window (a longer record or a smaller holdout)");
  // The input: the torque reading where the device's joints have one, else cmd_*.
  const std::vector<double>* reading[2] = {&data.tau_hip(), &data.tau_knee()};
  bool has_reading = true, has_cmd = true;
  for (int j = j0; j < 2; ++j) {
    has_reading = has_reading && !AllZero(*reading[j]);
    has_cmd = has_cmd && data.Column(j == 0 ? "cmd_hip" : "cmd_knee") != nullptr;
  }
  if (!has_reading && !has_cmd)
    throw InputError(data.source + ": the motion fit needs the actuator torque that drove the record: its torque reading (" +
                     std::string(params.one_joint ? "tau_knee" : "tau_hip, tau_knee") +
                     ") is zero throughout and it has no commanded torque (" +
                     std::string(params.one_joint ? "cmd_knee" : "cmd_hip, cmd_knee") + "); expected either");
  *by_reading = has_reading;
  return split;
}

}  // namespace motion

using motion::CheckMotionRecord;
using motion::MotionCutoff;
using motion::TorqueValues;

struct MotionProblem::Record {
  std::string source;
  ReplaySeries series;              // t, measured q, restart state (tau_R formed per rollout)
  std::vector<double> reading[2];   // the torque reading tau_S (by_reading)
  std::vector<double> cmd[2];       // the commanded torque (!by_reading)
  bool by_reading = true;
  size_t n = 0, split = 0, samples = 0;
  std::vector<size_t> rows;         // scored sample indices, ascending (fit part first)
  size_t fit_rows = 0;
  size_t windows[2] = {0, 0};       // Replay's windows on the fit and held-out parts
  Eigen::VectorXd q;                // measured angle on the rows: hip block, knee block
};

MotionProblem::~MotionProblem() = default;

MotionProblem::MotionProblem(const LegParams& params, const std::vector<const MeasuredData*>& records,
                             const DiagnoseOptions& opt, const std::vector<DiagnosedEffect>& torque_named)
    : params_(params), opt_(opt) {
  if (records.empty()) throw InputError("diagnose --fit motion: no record given");
  const double H = opt.replay_horizon_s;
  PlantEffects base_fx = ToPlantEffects(params, "the model given");
  std::vector<Kinematics> kins;
  std::vector<ScaleRecord> scale_in;
  kins.reserve(records.size());
  for (const MeasuredData* data : records) {
    auto rec = std::make_unique<Record>();
    Record& R = *rec;
    R.source = data->source;
    R.n = R.samples = data->size();
    bool has_reading = true;
    R.split = CheckMotionRecord(params, *data, opt, &has_reading);
    R.by_reading = has_reading;
    if (!has_reading) reading_input_ = false;
    R.series = ReplaySeriesOf(*data, base_fx, has_reading ? ReplayInput::kTorque : ReplayInput::kCommand,
                              MotionCutoff(opt, *data));
    R.series.quiet_windows = true;  // motion_fit.h: windows that restart and run where the motion is quiet
    for (int j = 0; j < 2; ++j) {
      if (has_reading) R.reading[j] = j == 0 ? data->tau_hip() : data->tau_knee();
      else R.cmd[j] = R.series.tau_R[j];
      std::vector<double>().swap(R.series.tau_R[j]);
    }
    kins.push_back(DeriveKinematics(*data));
    rec_.push_back(std::move(rec));
  }
  for (size_t r = 0; r < rec_.size(); ++r) scale_in.push_back({&kins[r], {&records[r]->tau_hip(), &records[r]->tau_knee()}});
  scale_ = ScaleOf(params, scale_in);
  // The forward plant simulates the strap's dynamics: the quasi-static form's limit does not apply.
  scale_.strap_dynamics[0] = scale_.strap_dynamics[1] = 0;

  AddCandidates(kins, torque_named);

  // The scored rows: the given twin's windows (Replay's schedule) on the fit and held-out parts.
  std::unique_ptr<Plant> plant;
  {
    std::lock_guard<std::mutex> lock(BuildMutex());
    KeepMjcfModel(opt.mjcf.empty() ? ExowheelMjcfPath(params.human.has_value()) : opt.mjcf);  // rollouts copy it
    plant = MakeReplayPlant(params, "the model given", opt.mjcf);
  }
  for (auto& rp : rec_) {
    Record& R = *rp;
    ReplaySeries s = R.series;
    if (R.by_reading) ActuatorTorqueFromReading(base_fx, s.t, R.reading, s.tau_R, &s);
    else s.tau_R[0] = R.cmd[0], s.tau_R[1] = R.cmd[1];
    const ReplayRecord a = Replay(*plant, s, H, 0, R.split);
    const ReplayRecord b = Replay(*plant, s, H, R.split, R.n);
    for (size_t i = 0; i < R.n; ++i)
      if (a.Window(i) >= 0 || b.Window(i) >= 0) R.rows.push_back(i);
    R.fit_rows = static_cast<size_t>(std::lower_bound(R.rows.begin(), R.rows.end(), R.split) - R.rows.begin());
    R.windows[0] = a.score.windows, R.windows[1] = b.score.windows;
    if (R.fit_rows == 0 || R.fit_rows == R.rows.size())
      throw InputError(R.source + ": the motion fit's windows of " + NumberText(H) + " s find no quiet stretch of at least " +
                       NumberText(kReplayQuietShortest) + " s in its " + (R.fit_rows == 0 ? "fit" : "held-out") +
                       " part (the measured angle's fast content, replay.h, exceeds " + NumberText(R.series.quiet_level, 4) +
                       " rad/s throughout); expected a record whose motion is quiet somewhere in each part (a longer record)");
    const size_t m = R.rows.size();
    R.q.resize(static_cast<Eigen::Index>(2 * m));
    for (size_t k = 0; k < m; ++k)
      for (int j = 0; j < 2; ++j) R.q[static_cast<Eigen::Index>(j * m + k)] = R.series.q[j][R.rows[k]];
  }
  // The input's hold between samples (ReplaySeries::hold), chosen from the data: the one under which
  // the given twin follows the fit parts closer.
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(parameters());
  w_[0] = w_[1] = 1;
  rw_.assign(rec_.size(), {1.0, 1.0});
  // The model given and, where the torque fit names effects the plant carries, with those too (a
  // delayed reading, say, would otherwise hide which hold fits).
  Eigen::VectorXd with_torque = zero;
  for (const DiagnosedEffect& d : torque_named) TorqueValues(*this, d.effect, &with_torque);
  for (int k = 0; k < parameters(); ++k) with_torque[k] = std::clamp(with_torque[k], lo_[k], hi_[k]);
  // (The torque fit's twin is simulated where its effects are candidates: else it is the model given.)
  const bool torque_twin = with_torque != zero;
  double by_hold[2] = {INFINITY, INFINITY};
  Rollout rollouts[2][2];  // [hold][the model given, the torque fit's twin]
  for (int h = 0; h < 2; ++h) {
    for (auto& rp : rec_) rp->series.hold = h == 1;
    for (int k = 0; k < (torque_twin ? 2 : 1); ++k) {
      rollouts[h][k] = Simulate(k == 0 ? zero : with_torque, Part::kFit);
      double s2[2];
      if (rollouts[h][k].ok) Sse(rollouts[h][k], Part::kFit, s2), by_hold[h] = std::min(by_hold[h], s2[0] + s2[1]);
    }
  }
  hold_ = by_hold[1] < by_hold[0];
  for (auto& rp : rec_) rp->series.hold = hold_;
  // Output weights: 1 / the misfit level per record and joint on the fit parts, the lower RMS
  // simulated-angle error of the model given and of the model with the torque fit's effects (the
  // rollouts of the hold chosen).
  const Rollout& given = rollouts[hold_][0];
  if (!given.ok) throw SimulationError(0, "the model given diverges in the forward simulation of the records");
  const Rollout& by_torque = rollouts[hold_][1];
  double count = 0, all_rows = 0;
  for (const auto& rp : rec_) count += static_cast<double>(rp->fit_rows), all_rows += static_cast<double>(rp->rows.size());
  std::vector<std::array<double, 2>> level(rec_.size());
  double pooled[2][2] = {{0, 0}, {0, 0}};  // [twin][joint]
  for (size_t r = 0; r < rec_.size(); ++r) {
    double e[2][2] = {{0, 0}, {INFINITY, INFINITY}}, n;  // [twin][joint]
    RecordSse(given, r, Part::kFit, e[0], &n);
    if (by_torque.ok) RecordSse(by_torque, r, Part::kFit, e[1], &n);
    for (int j = 0; j < 2; ++j) {
      level[r][static_cast<size_t>(j)] = std::min(e[0][j], e[1][j]);
      pooled[0][j] += e[0][j], pooled[1][j] += e[1][j];
    }
  }
  const double level_pooled[2] = {std::min(pooled[0][0], pooled[1][0]), std::min(pooled[0][1], pooled[1][1])};
  SetWeights(level, level_pooled);
  fit_share_ = count / std::max(all_rows, 1.0);
  all_rows_ = std::max(all_rows, 1.0);
}

void MotionProblem::SetWeights(const std::vector<std::array<double, 2>>& sse, const double pooled[2]) {
  const int j0 = params_.one_joint ? 1 : 0;
  double count = 0;
  rw_.assign(rec_.size(), {0.0, 0.0});
  for (size_t r = 0; r < rec_.size(); ++r) {
    const double mf = std::max<double>(1, static_cast<double>(rec_[r]->fit_rows));
    count += static_cast<double>(rec_[r]->fit_rows);
    for (int j = j0; j < 2; ++j)
      rw_[r][static_cast<size_t>(j)] = 1.0 / std::max(std::sqrt(sse[r][static_cast<size_t>(j)] / mf), 1e-6);
  }
  for (int j = 0; j < 2; ++j) w_[j] = j < j0 ? 0.0 : 1.0 / std::max(std::sqrt(pooled[j] / std::max(count, 1.0)), 1e-6);
}

void MotionProblem::WeightBy(const Rollout& ro) {
  std::vector<std::array<double, 2>> sse(rec_.size());
  double pooled[2] = {0, 0}, n;
  for (size_t r = 0; r < rec_.size(); ++r) {
    RecordSse(ro, r, Part::kFit, sse[r].data(), &n);
    pooled[0] += sse[r][0], pooled[1] += sse[r][1];
  }
  SetWeights(sse, pooled);
}

void MotionProblem::RecordSse(const Rollout& ro, size_t r, Part part, double sse[2], double* count) const {
  const Record& R = *rec_[r];
  const size_t m = R.rows.size();
  const size_t k0 = part == Part::kHeldOut ? R.fit_rows : 0, k1 = part == Part::kFit ? R.fit_rows : m;
  sse[0] = sse[1] = 0;
  for (int j = 0; j < 2; ++j)
    for (size_t k = k0; k < k1; ++k) {
      const Eigen::Index i = static_cast<Eigen::Index>(j * m + k);
      sse[j] += std::pow(R.q[i] - ro.q[r][i], 2);
    }
  *count = static_cast<double>(k1 - k0);
}

double MotionProblem::ReplaysSimulated() const {
  return static_cast<double>(rollouts_[static_cast<int>(Part::kFit)]) * fit_share_ +
         static_cast<double>(rollouts_[static_cast<int>(Part::kHeldOut)]) * (1 - fit_share_) +
         static_cast<double>(rollouts_[static_cast<int>(Part::kBoth)]) +
         static_cast<double>(record_rows_) / all_rows_;
}

const std::vector<size_t>& MotionProblem::rows(size_t r) const { return rec_[r]->rows; }
size_t MotionProblem::fit_rows(size_t r) const { return rec_[r]->fit_rows; }
const Eigen::VectorXd& MotionProblem::measured(size_t r) const { return rec_[r]->q; }
size_t MotionProblem::windows(size_t r, Part part) const {
  const Record& R = *rec_[r];
  return part == Part::kFit ? R.windows[0] : part == Part::kHeldOut ? R.windows[1] : R.windows[0] + R.windows[1];
}

MotionProblem::Rollout MotionProblem::Simulate(const Eigen::VectorXd& theta, Part part) const {
  ++rollouts_[static_cast<int>(part)];
  return Run(theta, part, -1);
}

MotionProblem::Rollout MotionProblem::SimulateRecord(const Eigen::VectorXd& theta, size_t record) const {
  record_rows_ += static_cast<long>(rec_[record]->rows.size());
  return Run(theta, Part::kBoth, static_cast<int>(record));
}

std::vector<MotionProblem::Rollout> MotionProblem::SimulateEachRecord(const std::vector<Eigen::VectorXd>& thetas) const {
  std::vector<Rollout> out(thetas.size());
  ParallelFor(thetas.size(), DiagnoseThreads(opt_), [&](size_t r) { out[r] = SimulateRecord(thetas[r], r); });
  return out;
}

MotionProblem::Rollout MotionProblem::Run(const Eigen::VectorXd& theta, Part part, int only) const {
  LegParams p = params_;
  const std::vector<Effect> extra = EffectsOf(theta);
  p.effects.insert(p.effects.end(), extra.begin(), extra.end());
  std::unique_ptr<Plant> plant;
  PlantEffects fx;
  {
    std::lock_guard<std::mutex> lock(BuildMutex());
    try {
      plant = MakeReplayPlant(p, "motion fit", opt_.mjcf, &fx);
    } catch (const InputError&) {
      return {};
    }
  }
  Rollout out;
  out.ok = true;
  const double H = opt_.replay_horizon_s;
  // A rollout outside a ParallelFor item (the line searches, the scores) shares its windows with a
  // second plant alike, built on the other thread when first needed: the same angles bit for bit.
  std::unique_ptr<Plant> second;
  const std::function<Plant&()> Second = [&]() -> Plant& {
    if (!second) {
      std::lock_guard<std::mutex> lock(BuildMutex());
      second = MakeReplayPlant(p, "motion fit", opt_.mjcf);
    }
    return *second;
  };
  const bool split = !InsideParallelFor() && DiagnoseThreads(opt_) >= 2;
  auto replay = [&](const ReplaySeries& s, size_t begin, size_t end) {
    return split ? ReplayOnTwoPlants(*plant, Second, s, H, begin, end) : Replay(*plant, s, H, begin, end);
  };
  for (size_t r = 0; r < rec_.size(); ++r) {
    const Record& R = *rec_[r];
    if (only >= 0 && static_cast<size_t>(only) != r) {
      out.q.push_back(Eigen::VectorXd::Constant(static_cast<Eigen::Index>(2 * R.rows.size()), std::nan("")));
      continue;
    }
    ReplaySeries s = R.series;
    if (R.by_reading) {
      ActuatorTorqueFromReading(fx, s.t, R.reading, s.tau_R, &s);
    } else {
      s.tau_R[0] = R.cmd[0], s.tau_R[1] = R.cmd[1];
      for (int k = 0; k < parameters(); ++k)
        if (kind_[k] == "offset" && theta[k] != 0)
          for (double& v : s.tau_R[joint_[k]]) v += theta[k];
    }
    const size_t m = R.rows.size();
    Eigen::VectorXd q = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(2 * m), std::nan(""));
    try {
      auto Take = [&](const ReplayRecord& rr, size_t k0, size_t k1) {
        for (size_t k = k0; k < k1; ++k)
          for (int j = 0; j < 2; ++j) q[static_cast<Eigen::Index>(j * m + k)] = rr.Sim(j, R.rows[k]);
      };
      if (part != Part::kHeldOut) Take(replay(s, 0, R.split), 0, R.fit_rows);
      if (part != Part::kFit) Take(replay(s, R.split, R.n), R.fit_rows, m);
    } catch (const SimulationError&) {
      return {};
    }
    for (Eigen::Index i = 0; i < q.size(); ++i)  // a row inside the part the replay missed: not ok
      if (!std::isfinite(q[i]) && ((i % static_cast<Eigen::Index>(m)) < static_cast<Eigen::Index>(R.fit_rows)
                                       ? part != Part::kHeldOut
                                       : part != Part::kFit))
        return {};
    out.q.push_back(std::move(q));
  }
  return out;
}

std::vector<MotionProblem::Rollout> MotionProblem::SimulateAll(const std::vector<Eigen::VectorXd>& thetas,
                                                               Part part) const {
  std::vector<Rollout> out(thetas.size());
  ParallelFor(thetas.size(), DiagnoseThreads(opt_), [&](size_t k) { out[k] = Simulate(thetas[k], part); });
  return out;
}

Eigen::MatrixXd MotionProblem::Jacobian(const Eigen::VectorXd& theta, const Rollout& at, const std::vector<int>& cols,
                                        Part part) const {
  Eigen::Index rows = 0;
  for (const auto& rp : rec_) rows += static_cast<Eigen::Index>(2 * rp->rows.size());
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(cols.size()));
  std::vector<double> h(cols.size());
  // The rollouts a batch of DiagnoseThreads columns at a time, each one's column of J written and the
  // rollout dropped (every rollout is as large as a column of J: all at once would double J's memory).
  const size_t batch = static_cast<size_t>(std::max(1, DiagnoseThreads(opt_)));
  for (size_t c0 = 0; c0 < cols.size(); c0 += batch) {
    const size_t c1 = std::min(cols.size(), c0 + batch);
    std::vector<Eigen::VectorXd> thetas;
    for (size_t c = c0; c < c1; ++c) {
      const int k = cols[c];
      h[c] = theta[k] + step_[k] <= hi_[k] ? step_[k] : -step_[k];
      Eigen::VectorXd x = theta;
      x[k] += h[c];
      thetas.push_back(x);
    }
    std::vector<Rollout> ro = SimulateAll(thetas, part);
    for (size_t c = c0; c < c1; ++c) {
      Rollout& rc = ro[c - c0];
      if (!rc.ok) {  // the other way
        const int k = cols[c];
        h[c] = -h[c];
        Eigen::VectorXd x = theta;
        x[k] = std::clamp(x[k] + h[c], lo_[k], hi_[k]);
        h[c] = x[k] - theta[k];
        if (h[c] != 0) rc = Simulate(x, part);
        if (!rc.ok || h[c] == 0) continue;
      }
      Eigen::Index off = 0;
      for (size_t r = 0; r < rec_.size(); ++r) {
        const Eigen::VectorXd d = (rc.q[r] - at.q[r]) / h[c];
        for (Eigen::Index i = 0; i < d.size(); ++i) J(off + i, static_cast<Eigen::Index>(c)) = std::isfinite(d[i]) ? d[i] : 0.0;
        off += d.size();
      }
    }
  }
  return J;
}

void MotionProblem::Sse(const Rollout& ro, Part part, double sse[2]) const {
  sse[0] = sse[1] = 0;
  for (size_t r = 0; r < rec_.size(); ++r) {
    const Record& R = *rec_[r];
    const size_t m = R.rows.size();
    const size_t k0 = part == Part::kHeldOut ? R.fit_rows : 0, k1 = part == Part::kFit ? R.fit_rows : m;
    for (int j = 0; j < 2; ++j)
      for (size_t k = k0; k < k1; ++k) {
        const Eigen::Index i = static_cast<Eigen::Index>(j * m + k);
        sse[j] += std::pow(rw_[r][static_cast<size_t>(j)] * (R.q[i] - ro.q[r][i]), 2);
      }
  }
}

}  // namespace exotwin
