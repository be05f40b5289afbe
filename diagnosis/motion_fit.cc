#include "diagnosis/motion_fit.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <functional>
#include <mutex>
#include <sstream>
#include <thread>

#include <Eigen/Cholesky>

#include "core/error.h"
#include "core/parallel_for.h"
#include "diagnosis/replay.h"
#include "dsp/statistics.h"
#include "formats/number_text.h"
#include "model/passive_torque.h"
#include "sim/mjcf_cache.h"
#include "sim/plant.h"

namespace exotwin {

namespace {

const char* kJoint[2] = {"hip", "knee"};

constexpr double kNoBacklash = 1e-5;    // rad: a narrower dead band is none (the hinge is not built)
constexpr double kNoCompliance = 1e-7;  // rad/(N m): a stiffer strap is none

// MuJoCo's XML compiler keeps global state: plants are built one at a time.
std::mutex& BuildMutex() {
  static std::mutex m;
  return m;
}


bool AllZero(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; });
}

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

// The values of a torque-named effect as the candidate's parameters (into *theta); false if none.
bool TorqueValues(const MotionProblem& P, const Effect& e, Eigen::VectorXd* theta) {
  const int c = P.CandidateIndex(e.name, e.joint, e.axis);
  if (c < 0) return false;
  const Candidate& cand = P.candidates()[static_cast<size_t>(c)];
  const double v = e.value;
  if (e.name == "series_compliance") {
    (*theta)[cand.cols[0]] = v > 0 ? 1 / v : 0;
  } else if (e.name == "joint_stiffness") {
    (*theta)[cand.cols[0]] = v;
    (*theta)[cand.cols[1]] = v * (e.fields.count("q0") ? e.fields.at("q0") : 0.0);
  } else if (e.name == "torque_ripple") {
    const double ph = e.fields.count("phase") ? e.fields.at("phase") : 0.0;
    (*theta)[cand.cols[0]] = v * std::cos(ph);
    (*theta)[cand.cols[1]] = v * std::sin(ph);
  } else {
    (*theta)[cand.cols[0]] = v;
  }
  return true;
}

// The effect of the model given that takes the place of candidate `name` at `joint` (the same effect;
// a dead band or a strap for either: one internal hinge per joint), nullptr if none.
const Effect* CarriedByModel(const LegParams& params, const std::string& name, const std::string& joint) {
  auto hinge = [](const std::string& n) { return n == "backlash" || n == "series_compliance"; };
  for (const Effect& e : params.effects)
    if (e.joint == joint && (e.name == name || (hinge(name) && hinge(e.name)))) return &e;
  return nullptr;
}

}  // namespace

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
  const int j0 = params.one_joint ? 1 : 0;
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

  // Parameters, their boxes (DESIGN.md's ranges) and secant steps.
  auto Add = [&](const std::string& kind, int j, double lo, double hi, double step, double f = 0) {
    kind_.push_back(kind), joint_.push_back(j), lo_.push_back(lo), hi_.push_back(hi), step_.push_back(step);
    ripple_f_.push_back(f);
    return static_cast<int>(lo_.size()) - 1;
  };
  auto Has = [&](const std::string& name, int j) { return CarriedByModel(params, name, kJoint[j]) != nullptr; };
  for (int j = j0; j < 2; ++j) {
    double qd2 = 0, qdev = 0, cnt = 0;
    std::vector<double> all_q;
    for (const Kinematics& k : kins) {
      for (double v : k.qd[j]) qd2 += v * v, cnt += 1;
      all_q.insert(all_q.end(), k.q[j].begin(), k.q[j].end());
    }
    qdev = std::max(RmsAboutMean(all_q), 1e-3);
    const double qd_rms = std::max(std::sqrt(qd2 / std::max(cnt, 1.0)), 1e-3);
    qd_rms_[j] = qd_rms;
    const double tau = std::max(scale_.tau_max[j], 1e-3);
    const double M = std::max(scale_.M_jj[j], 1e-6);
    const double grav = 0.5 * scale_.distal_moment[j] + 0.05;
    const double range = scale_.q_max[j] - scale_.q_min[j];
    auto Cand = [&](const std::string& name, std::vector<int> cols, const std::string& axis = "") {
      Candidate c;
      c.name = name, c.joint = j, c.axis = axis, c.cols = std::move(cols);
      c.ripple_f = ripple_f_[static_cast<size_t>(c.cols[0])];
      candidates_.push_back(c);
    };
    const int off = Add("offset", j, -0.5 * tau, 0.5 * tau, 0.02 * tau);
    // Friction and inertia are summed by the plant (sim/plant_effects.h): candidates on top of the
    // model's own (a one-joint device's R and C are its knee's frictions, model/one_joint.h).
    Cand("coulomb_friction", {Add("coulomb_friction", j, 0, 0.5 * tau, 0.02 * tau)});
    Cand("viscous_friction", {Add("viscous_friction", j, 0, 100 * tau / qd_rms, 0.02 * tau / qd_rms)});
    Cand("inertia_error", {Add("inertia_error", j, -0.45 * M, M, 0.02 * M)});
    if (!Has("gravity_error", j)) {
      Cand("gravity_error", {Add("gravity_error.X", j, -grav, grav, 0.02 * grav)}, "X");
      Cand("gravity_error", {Add("gravity_error.Y", j, -grav, grav, 0.02 * grav)}, "Y");
    }
    if (!Has("joint_stiffness", j))
      Cand("joint_stiffness", {Add("joint_stiffness", j, 0, 100 * tau / qdev, 0.02 * tau / qdev), off});
    if (params.human && !params.one_joint && !Has("passive_moment", j))
      Cand("passive_moment", {Add("passive_moment", j, -0.95, kMaxPassiveScale - 1, 0.05)});
    if (!Has("backlash", j)) Cand("backlash", {Add("backlash", j, 0, 0.1, 0.005)});
    if (!Has("series_compliance", j) && !(j == 0 && params.human)) {
      const double tc = std::max(scale_.tau_C_max[j], 1e-3);
      Cand("series_compliance", {Add("series_compliance", j, 0, 0.5 * range / tc, 0.005 / tc)});
    }
    for (const DiagnosedEffect& d : torque_named)
      if (d.effect.name == "torque_ripple" && d.effect.joint == kJoint[j] && !Has("torque_ripple", j)) {
        const double f = d.effect.fields.at("cycles_per_rad");
        const int a = Add("torque_ripple.sin", j, -0.5 * tau, 0.5 * tau, 0.02 * tau, f);
        Cand("torque_ripple", {a, Add("torque_ripple.cos", j, -0.5 * tau, 0.5 * tau, 0.02 * tau, f)});
      }
    if (reading_input_) {
      if (!Has("sensor_offset", j)) Cand("sensor_offset", {off});
      if (!Has("sensor_gain", j)) Cand("sensor_gain", {Add("sensor_gain", j, -0.25, 0.25, 0.02)});
      if (!Has("sensor_delay", j)) Cand("sensor_delay", {Add("sensor_delay", j, 0, 0.05, 0.002)});
    }
  }

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
    if (R.by_reading) ActuatorTorqueFromReading(base_fx, s.t, R.reading, s.tau_R);
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

int MotionProblem::CandidateIndex(const std::string& name, const std::string& joint, const std::string& axis) const {
  for (size_t c = 0; c < candidates_.size(); ++c)
    if (candidates_[c].name == name && kJoint[candidates_[c].joint] == joint &&
        (name != "gravity_error" || candidates_[c].axis == axis))
      return static_cast<int>(c);
  return -1;
}

std::string MotionProblem::WhyNoCandidate(const Effect& e) const {
  if (CandidateIndex(e.name, e.joint, e.axis) >= 0) return "";
  if (e.name == "muscle_activity") return "not carried by the forward plant";
  if (e.name.rfind("sensor_", 0) == 0 && !reading_input_) return "the commands drive the plant: no torque reading to correct";
  if (const Effect* g = CarriedByModel(params_, e.name, e.joint))
    return "the model given already carries a " + g->name + " at the " + g->joint + ": no candidate";
  if (e.name == "series_compliance" && e.joint == "hip" && params_.human)
    return "the plant carries a strap with a human at the knee only";
  if (e.name == "passive_moment") return "no passive moment in this model (a two-joint model with a human carries it)";
  if (params_.one_joint && e.joint == "hip") return "a one-joint model has no hip";
  return "no candidate of the motion fit";
}

const std::vector<size_t>& MotionProblem::rows(size_t r) const { return rec_[r]->rows; }
size_t MotionProblem::fit_rows(size_t r) const { return rec_[r]->fit_rows; }
const Eigen::VectorXd& MotionProblem::measured(size_t r) const { return rec_[r]->q; }
size_t MotionProblem::windows(size_t r, Part part) const {
  const Record& R = *rec_[r];
  return part == Part::kFit ? R.windows[0] : part == Part::kHeldOut ? R.windows[1] : R.windows[0] + R.windows[1];
}

std::vector<Effect> MotionProblem::EffectsOf(const Eigen::VectorXd& theta) const {
  std::vector<Effect> link, sensor;
  auto Make = [](const std::string& name, int j, double v, const std::string& unit) {
    Effect e;
    e.name = name, e.joint = kJoint[j], e.value = v, e.unit = unit;
    return e;
  };
  for (int k = 0; k < parameters(); ++k) {
    const double v = theta[k];
    const int j = joint_[k];
    const std::string& kind = kind_[k];
    if (v == 0) continue;
    if (kind == "coulomb_friction" && v > 0) link.push_back(Make(kind, j, v, "N m"));
    if (kind == "viscous_friction" && v > 0) link.push_back(Make(kind, j, v, "N m s/rad"));
    if (kind == "inertia_error") link.push_back(Make(kind, j, v, "kg m^2"));
    if (kind == "passive_moment") link.push_back(Make(kind, j, v, "relative"));
    if (kind.rfind("gravity_error", 0) == 0) {
      Effect e = Make("gravity_error", j, v, "kg m");
      e.axis = kind.substr(14);
      link.push_back(e);
    }
    if (kind == "joint_stiffness" && v > 0) {  // its constant part k q0 is the offset parameter
      Effect e = Make(kind, j, v, "N m/rad");
      e.fields["q0"] = 0;
      link.push_back(e);
    }
    if (kind == "backlash" && v > kNoBacklash) link.push_back(Make(kind, j, v, "rad"));
    if (kind == "series_compliance" && v > kNoCompliance) link.push_back(Make(kind, j, 1 / v, "N m/rad"));
    if (kind == "torque_ripple.sin") {
      const double b = theta[k + 1];
      Effect e = Make("torque_ripple", j, std::hypot(v, b), "N m");
      e.fields["cycles_per_rad"] = ripple_f_[k];
      e.fields["phase"] = std::atan2(b, v);
      link.push_back(e);
    }
    // The input's constant torque: a sensor offset where the reading drives (tau_R = -(reading - offset)).
    if (kind == "offset" && reading_input_) sensor.push_back(Make("sensor_offset", j, v, "N m"));
    if (kind == "sensor_gain") sensor.push_back(Make(kind, j, v, "relative"));
    if (kind == "sensor_delay" && v > 0) sensor.push_back(Make(kind, j, v, "s"));
  }
  for (int k = 0; k < parameters(); ++k)  // a ripple whose sine part is 0
    if (kind_[k] == "torque_ripple.cos" && theta[k] != 0 && theta[k - 1] == 0) {
      Effect e = Make("torque_ripple", joint_[k], std::abs(theta[k]), "N m");
      e.fields["cycles_per_rad"] = ripple_f_[k];
      e.fields["phase"] = std::atan2(theta[k], 0.0);
      link.push_back(e);
    }
  link.insert(link.end(), sensor.begin(), sensor.end());
  return link;
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
      ActuatorTorqueFromReading(fx, s.t, R.reading, s.tau_R);
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
  std::vector<Eigen::VectorXd> thetas;
  std::vector<double> h(cols.size());
  for (size_t c = 0; c < cols.size(); ++c) {
    const int k = cols[c];
    h[c] = theta[k] + step_[k] <= hi_[k] ? step_[k] : -step_[k];
    Eigen::VectorXd x = theta;
    x[k] += h[c];
    thetas.push_back(x);
  }
  std::vector<Rollout> ro = SimulateAll(thetas, part);
  for (size_t c = 0; c < cols.size(); ++c) {
    if (!ro[c].ok) {  // the other way
      const int k = cols[c];
      h[c] = -h[c];
      Eigen::VectorXd x = theta;
      x[k] = std::clamp(x[k] + h[c], lo_[k], hi_[k]);
      h[c] = x[k] - theta[k];
      if (h[c] != 0) ro[c] = Simulate(x, part);
      if (!ro[c].ok || h[c] == 0) continue;
    }
    Eigen::Index off = 0;
    for (size_t r = 0; r < rec_.size(); ++r) {
      const Eigen::VectorXd d = (ro[c].q[r] - at.q[r]) / h[c];
      for (Eigen::Index i = 0; i < d.size(); ++i) J(off + i, static_cast<Eigen::Index>(c)) = std::isfinite(d[i]) ? d[i] : 0.0;
      off += d.size();
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

// ---------------------------------------------------------------------------------------------------
// The fit (motion_fit.h "Method").

namespace {

using Part = MotionProblem::Part;

double Cost(const MotionProblem& P, const MotionProblem::Rollout& ro, Part part) {
  if (!ro.ok) return INFINITY;
  double s[2];
  P.Sse(ro, part, s);
  return s[0] + s[1];
}

// Stacked row indices (records stacked, 2 m each) of a part, rows of weight 0 left out.
std::vector<Eigen::Index> PartRows(const MotionProblem& P, Part part) {
  std::vector<Eigen::Index> out;
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    const size_t m = P.rows(r).size();
    for (int j = 0; j < 2; ++j) {
      if (P.weight(j) == 0) continue;
      const size_t k0 = part == Part::kHeldOut ? P.fit_rows(r) : 0, k1 = part == Part::kFit ? P.fit_rows(r) : m;
      for (size_t k = k0; k < k1; ++k) out.push_back(off + static_cast<Eigen::Index>(j * m + k));
    }
    off += static_cast<Eigen::Index>(2 * m);
  }
  return out;
}

// Weighted residual (measured - simulated) on `idx` of a rollout.
Eigen::VectorXd WeightedResidual(const MotionProblem& P, const MotionProblem::Rollout& ro,
                                 const std::vector<Eigen::Index>& idx) {
  Eigen::VectorXd all;
  std::vector<double> w;
  Eigen::Index total = 0;
  for (size_t r = 0; r < P.records(); ++r) total += P.measured(r).size();
  all.resize(total);
  Eigen::VectorXd wv(total);
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    const Eigen::Index m2 = P.measured(r).size();
    all.segment(off, m2) = P.measured(r) - ro.q[r];
    wv.segment(off, m2 / 2).setConstant(P.weight(r, 0));
    wv.segment(off + m2 / 2, m2 / 2).setConstant(P.weight(r, 1));
    off += m2;
  }
  Eigen::VectorXd e(static_cast<Eigen::Index>(idx.size()));
  for (size_t k = 0; k < idx.size(); ++k) e[static_cast<Eigen::Index>(k)] = wv[idx[k]] * all[idx[k]];
  return e;
}

Eigen::VectorXd RowWeights(const MotionProblem& P) {
  Eigen::Index total = 0;
  for (size_t r = 0; r < P.records(); ++r) total += P.measured(r).size();
  Eigen::VectorXd wv(total);
  Eigen::Index off = 0;
  for (size_t r = 0; r < P.records(); ++r) {
    const Eigen::Index m2 = P.measured(r).size();
    wv.segment(off, m2 / 2).setConstant(P.weight(r, 0));
    wv.segment(off + m2 / 2, m2 / 2).setConstant(P.weight(r, 1));
    off += m2;
  }
  return wv;
}

// Autocorrelation length (rows) of the weighted fit-part residual: the longest over records and
// joints, at most a window's rows.
double ResidualAutocorrelation(const MotionProblem& P, const MotionProblem::Rollout& ro, double window_rows) {
  double tau = 1;
  for (size_t r = 0; r < P.records(); ++r) {
    const size_t m = P.rows(r).size(), mf = P.fit_rows(r);
    for (int j = 0; j < 2; ++j) {
      if (P.weight(j) == 0 || mf < 8) continue;
      std::vector<double> e(mf);
      for (size_t k = 0; k < mf; ++k) {
        const Eigen::Index i = static_cast<Eigen::Index>(j * m + k);
        e[k] = P.measured(r)[i] - ro.q[r][i];
      }
      tau = std::max(tau, AutocorrelationLength(e.data(), e.size()));
    }
  }
  return std::min(tau, std::max(1.0, window_rows));
}

// The weighted Jacobian of the fit rows (PartRows(P, kFit), rows weighted as RowWeights) of
// parameters `cols` at theta, whose rollout (fit part at least) is `at`.
Eigen::MatrixXd WeightedFitJacobian(const MotionProblem& P, const Eigen::VectorXd& theta, const MotionProblem::Rollout& at,
                                    const std::vector<int>& cols) {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  const Eigen::VectorXd wv = RowWeights(P);
  const Eigen::MatrixXd Jall = P.Jacobian(theta, at, cols, Part::kFit);
  Eigen::MatrixXd J(static_cast<Eigen::Index>(idx.size()), Jall.cols());
  for (size_t k = 0; k < idx.size(); ++k) J.row(static_cast<Eigen::Index>(k)) = wv[idx[k]] * Jall.row(idx[k]);
  return J;
}

// Each record left out in turn: the values of `cols` one Gauss-Newton step from theta on the other
// records' fit parts (J, e: the weighted Jacobian and residual of the fit rows at theta), inside the
// box; the rest of theta as it is. Where without a record the values are not identifiable, that
// record's index in *unidentifiable (else -1) and an empty result.
std::vector<Eigen::VectorXd> LeftOutThetas(const MotionProblem& P, const Eigen::VectorXd& theta,
                                           const std::vector<int>& cols, const Eigen::MatrixXd& J,
                                           const Eigen::VectorXd& e, int* unidentifiable) {
  *unidentifiable = -1;
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  std::vector<size_t> owner(idx.size());
  Eigen::Index off = 0;
  size_t rec = 0;
  for (size_t k = 0; k < idx.size(); ++k) {
    while (idx[k] >= off + P.measured(rec).size()) off += P.measured(rec).size(), ++rec;
    owner[k] = rec;
  }
  std::vector<Eigen::VectorXd> out;
  const Eigen::Index p = static_cast<Eigen::Index>(cols.size());
  for (size_t r = 0; r < P.records(); ++r) {
    Eigen::VectorXd x = theta;
    if (p > 0) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(p, p);
      Eigen::VectorXd g = Eigen::VectorXd::Zero(p);
      for (size_t k = 0; k < owner.size(); ++k) {
        if (owner[k] == r) continue;
        const Eigen::Index i = static_cast<Eigen::Index>(k);
        A.noalias() += J.row(i).transpose() * J.row(i);
        g.noalias() += J.row(i).transpose() * e[i];
      }
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
      const Eigen::VectorXd d = ldlt.solve(g);
      if (ldlt.info() != Eigen::Success || !d.allFinite() || !(A.diagonal().minCoeff() > 0)) {
        *unidentifiable = static_cast<int>(r);
        return {};
      }
      for (Eigen::Index c = 0; c < p; ++c) {
        const int k = cols[static_cast<size_t>(c)];
        x[k] = std::clamp(theta[k] + d[c], P.lower(k), P.upper(k));
      }
    }
    out.push_back(x);
  }
  return out;
}

struct Refined {
  Eigen::VectorXd theta;
  double cost = INFINITY;
  Eigen::MatrixXd J;  // weighted, fit rows x cols, at theta
  Eigen::VectorXd e;  // weighted residual there
};

// Projected Levenberg-Marquardt on parameters `cols` (motion_fit.h step 4), from the best of `starts`.
// With `jacobian` false, Refined::J and ::e are left empty where the last step moved theta (no rollouts
// for a Jacobian nobody reads).
Refined Refine(const MotionProblem& P, const std::vector<int>& cols, const std::vector<Eigen::VectorXd>& starts,
               int iterations = kMotionLmIterations, bool jacobian = true) {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  const Eigen::VectorXd wv = RowWeights(P);
  auto Clamp = [&](Eigen::VectorXd x) {
    for (int k : cols) x[k] = std::clamp(x[k], P.lower(k), P.upper(k));
    return x;
  };
  std::vector<Eigen::VectorXd> xs;
  for (const auto& s : starts) xs.push_back(Clamp(s));
  std::vector<MotionProblem::Rollout> ro = P.SimulateAll(xs, Part::kFit);
  size_t best = 0;
  for (size_t k = 1; k < xs.size(); ++k)
    if (Cost(P, ro[k], Part::kFit) < Cost(P, ro[best], Part::kFit)) best = k;
  Refined R;
  R.theta = xs[best];
  MotionProblem::Rollout at = ro[best];
  R.cost = Cost(P, at, Part::kFit);
  if (!std::isfinite(R.cost)) return R;
  auto WeightedJ = [&](const MotionProblem::Rollout& a, const Eigen::VectorXd& theta) {
    return WeightedFitJacobian(P, theta, a, cols);
  };
  double lambda = 1e-3;
  bool fresh = false;
  // The Levenberg-Marquardt iterations from R.theta (its rollout `at`).
  auto Lm = [&]() {
    for (int it = 0; it < iterations; ++it) {
      R.J = WeightedJ(at, R.theta);
      R.e = WeightedResidual(P, at, idx);
      fresh = true;
      const Eigen::MatrixXd A = R.J.transpose() * R.J;
      const Eigen::VectorXd g = R.J.transpose() * R.e;
      const Eigen::VectorXd D = A.diagonal().cwiseMax(1e-12 * std::max(A.diagonal().maxCoeff(), 1e-300));
      bool improved = false;
      const double before = R.cost;
      for (int trial = 0; trial < 6 && !improved; ++trial) {
        Eigen::MatrixXd Al = A;
        Al.diagonal() += lambda * D;
        const Eigen::VectorXd d = Al.ldlt().solve(g);
        Eigen::VectorXd x = R.theta;
        for (size_t c = 0; c < cols.size(); ++c) x[cols[c]] += d[static_cast<Eigen::Index>(c)];
        x = Clamp(x);
        if ((x - R.theta).norm() == 0) break;
        // The decrease the linear model predicts for the clamped step, |e|^2 - |e - J dx|^2: below the
        // stopping rule's 1e-5 of the cost, no rollout can meet the rule (converged).
        Eigen::VectorXd dx(static_cast<Eigen::Index>(cols.size()));
        for (size_t c = 0; c < cols.size(); ++c) dx[static_cast<Eigen::Index>(c)] = x[cols[c]] - R.theta[cols[c]];
        if (2 * dx.dot(g) - dx.dot(A * dx) < 1e-5 * R.cost) break;
        MotionProblem::Rollout rx = P.Simulate(x, Part::kFit);
        const double cx = Cost(P, rx, Part::kFit);
        if (cx < R.cost) {
          R.theta = x, R.cost = cx, at = std::move(rx);
          lambda = std::max(lambda / 3, 1e-9);
          improved = true, fresh = false;
        } else {
          lambda *= 5;
        }
      }
      if (!improved || before - R.cost < 1e-5 * before) break;
    }
  };
  Lm();
  // A dead band's cost is rough below the scale of its effect (a closure moves by a whole physics
  // step as the band changes by a fraction of a step's travel: notches of a few % within 1e-4 rad),
  // where the local step above sees a minimum that is none. Probes at a quarter and a half of the
  // band's size (at least its secant step) on either side, the other values held; where one is
  // lower the refinement restarts there (kMotionBandProbes rounds at most).
  for (int round = 0; round < kMotionBandProbes; ++round) {
    std::vector<Eigen::VectorXd> probes;
    for (int k : cols) {
      if (P.kind(k) != "backlash") continue;
      const double size = std::max(R.theta[k], P.step(k));
      for (double f : {-0.5, -0.25, 0.25, 0.5}) {
        Eigen::VectorXd x = R.theta;
        x[k] = std::clamp(x[k] + f * size, P.lower(k), P.upper(k));
        if (x[k] != R.theta[k]) probes.push_back(x);
      }
    }
    if (probes.empty()) break;
    std::vector<MotionProblem::Rollout> pr = P.SimulateAll(probes, Part::kFit);
    size_t b = 0;
    double cb = Cost(P, pr[0], Part::kFit);
    for (size_t k = 1; k < probes.size(); ++k) {
      const double ck = Cost(P, pr[k], Part::kFit);
      if (ck < cb) cb = ck, b = k;
    }
    if (!(cb < R.cost)) break;
    R.theta = probes[b], R.cost = cb, at = std::move(pr[b]);
    fresh = false, lambda = 1e-3;
    Lm();
  }
  if (!fresh && jacobian) {
    R.J = WeightedJ(at, R.theta);
    R.e = WeightedResidual(P, at, idx);
  }
  return R;
}

// One parameter k refined alone (motion_fit.h step 3's screening fit) by the secant method on the
// fit part's weighted least squares: the derivative of the simulated angles is the secant through the
// last two rollouts (the first: from `base`, theta's own rollout, to `start`), the step Gauss-Newton's
// on it, clamped to the box; one rollout per iteration, at most `iterations`, fewer when the predicted
// decrease falls below the refinement's stopping rule. Returns the best value seen (theta[k] itself
// when nothing lowers the cost).
double RefineOne(const MotionProblem& P, int k, const Eigen::VectorXd& theta, const MotionProblem::Rollout& base,
                 double start, int iterations) {
  const std::vector<Eigen::Index> idx = PartRows(P, Part::kFit);
  // e = w (q - qsim) on the fit rows, so the weighted derivative of qsim is -de/dx: the secant
  // (e_prev - e_cur) / (x_cur - x_prev).
  double x_prev = theta[k], x_cur = std::clamp(start, P.lower(k), P.upper(k));
  if (!base.ok || x_cur == x_prev) return x_prev;
  Eigen::VectorXd e_prev = WeightedResidual(P, base, idx);
  double best_x = x_prev, best_cost = e_prev.squaredNorm();
  Eigen::VectorXd x = theta;
  x[k] = x_cur;
  const MotionProblem::Rollout ro = P.Simulate(x, Part::kFit);
  if (!ro.ok) return best_x;
  Eigen::VectorXd e_cur = WeightedResidual(P, ro, idx);
  double cost_cur = e_cur.squaredNorm();
  if (cost_cur < best_cost) best_x = x_cur, best_cost = cost_cur;
  for (int it = 1; it < iterations; ++it) {
    const Eigen::VectorXd Jw = (e_prev - e_cur) / (x_cur - x_prev);
    const double a = Jw.squaredNorm();
    if (!(a > 0)) break;
    // Gauss-Newton on the secant, e(x) ~ e_cur - Jw (x - x_cur), clamped to the box.
    const double x_new = std::clamp(x_cur + Jw.dot(e_cur) / a, P.lower(k), P.upper(k));
    const double dx = x_new - x_cur;
    if (dx == 0 || 2 * dx * Jw.dot(e_cur) - a * dx * dx < 1e-5 * cost_cur) break;  // converged (the stopping rule)
    x[k] = x_new;
    const MotionProblem::Rollout rn = P.Simulate(x, Part::kFit);
    if (!rn.ok) break;
    Eigen::VectorXd e_new = WeightedResidual(P, rn, idx);
    const double cost_new = e_new.squaredNorm();
    if (cost_new < best_cost) best_x = x_new, best_cost = cost_new;
    x_prev = x_cur, e_prev = std::move(e_cur);
    x_cur = x_new, e_cur = std::move(e_new), cost_cur = cost_new;
  }
  return best_x;
}

std::string Labels(const MotionProblem& P, const std::vector<int>& set) {
  std::string o;
  for (int c : set) o += (o.empty() ? "" : " + ") + P.candidates()[static_cast<size_t>(c)].Label();
  return o.empty() ? "the model given" : o;
}

// A candidate's fitted value as the effect it names, in that effect's unit (EffectsOf: a strap's
// stiffness 1 / compliance, a ripple's amplitude and phase); where its parameters name no effect (0, a
// dead band or strap below the plant's floor, the constant input torque of a record driven by its
// commands) the parameters themselves.
std::string ValueText(const MotionProblem& P, const Candidate& cand, const Eigen::VectorXd& theta) {
  Eigen::VectorXd only = Eigen::VectorXd::Zero(theta.size());
  for (int k : cand.cols) only[k] = theta[k];
  std::string o;
  for (const Effect& e : P.EffectsOf(only)) {
    o += (o.empty() ? "" : ", ") + NumberText(e.value, 4) + " " + e.unit;
    if (e.fields.count("phase")) o += " (phase " + NumberText(e.fields.at("phase"), 3) + " rad)";
  }
  if (o.empty())
    for (int k : cand.cols) o += (o.empty() ? "" : " ") + NumberText(theta[k], 4);
  return o;
}

JointScore Score(double sse_before, double sse_after, double count) {
  count = std::max(count, 1.0);
  return {std::sqrt(sse_before / count), std::sqrt(sse_after / count),
          sse_before > 0 ? 100 * (1 - std::sqrt(sse_after / sse_before)) : 0};
}

}  // namespace

Diagnosis DiagnoseByMotion(const LegParams& params, const std::vector<const MeasuredData*>& records,
                           const DiagnoseOptions& opt) {
  bool by_reading = true;
  for (const MeasuredData* data : records) CheckMotionRecord(params, *data, opt, &by_reading);
  // 1. The torque fit: starting values and what it would name.
  DiagnoseOptions topt = opt;
  topt.fit = DiagnoseFit::kTorque;
  topt.simulate = false;
  Diagnosis T = Diagnose(params, records, topt);

  MotionProblem P(params, records, opt, T.effects);
  const int n_par = P.parameters();
  const std::vector<Candidate>& cands = P.candidates();
  const bool loo = records.size() >= 2;
  ColumnBank cand_bank;  // the candidates alone (ColumnsOf)
  cand_bank.candidates = cands;
  std::vector<int> all(static_cast<size_t>(n_par));
  for (int k = 0; k < n_par; ++k) all[static_cast<size_t>(k)] = k;

  Diagnosis D;
  D.fit = DiagnoseFit::kMotion;
  D.holdout_fraction = opt.holdout_fraction;
  D.leave_one_out = loo;
  D.torque_named = T.effects;
  D.cutoff = T.cutoff;

  // Where the simulation goes, in replays of the records (reported in the selection log).
  enum Stage { kSetUp, kJacobians, kScreening, kRefinement, kGate, kScores, kStages };
  double cost[kStages] = {0, 0, 0, 0, 0, 0}, mark = 0;
  auto Charge = [&](Stage st) {
    const double now = P.ReplaysSimulated();
    cost[st] += now - mark;
    mark = now;
  };

  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_par);
  const MotionProblem::Rollout given = P.Simulate(zero, Part::kBoth);
  Charge(kSetUp);
  if (!given.ok) throw SimulationError(0, "the model given diverges in the forward simulation of the records");
  double window_rows = 0;
  {
    double rows = 0, windows = 0;
    for (size_t r = 0; r < P.records(); ++r) {
      rows += static_cast<double>(P.rows(r).size());
      windows += static_cast<double>(P.windows(r, Part::kBoth));
    }
    window_rows = rows / std::max(windows, 1.0);
  }

  // 2-5. Linearize, select, refine.
  Eigen::VectorXd theta = zero;
  MotionProblem::Rollout at = given;
  std::vector<int> chosen, previous;
  Grams g_last;
  double tau_eff = 1;
  std::vector<std::vector<int>> seen;
  struct Round {
    std::vector<int> set;
    Eigen::VectorXd theta;
    double cost;  // fit-part cost of the refined set
  };
  std::vector<Round> rounds;
  const Eigen::VectorXd wv = RowWeights(P);
  // The linear model at theta of Jacobian J (motion_fit.h step 2): one bank per record, their Grams.
  auto Linearize = [&](const Eigen::MatrixXd& J, std::vector<ColumnBank>* banks_out, Grams* g_out) {
    std::vector<ColumnBank> banks(P.records());
    Eigen::Index off = 0;
    for (size_t r = 0; r < P.records(); ++r) {
      ColumnBank& b = banks[r];
      const size_t m = P.rows(r).size();
      const Eigen::Index m2 = static_cast<Eigen::Index>(2 * m);
      b.sample = P.rows(r);
      b.train.resize(m);
      for (size_t k = 0; k < m; ++k) b.train[k] = k < P.fit_rows(r);
      b.X = wv.segment(off, m2).asDiagonal() * J.middleRows(off, m2);
      b.r = wv.segment(off, m2).asDiagonal() * (P.measured(r) - at.q[r] + J.middleRows(off, m2) * theta);
      b.candidates = cands;
      b.used = n_par;
      b.n = records[r]->size();
      off += m2;
    }
    Grams g = MakeGrams(banks);
    g.n_eff = g.n_tr / tau_eff;
    g.scale_name = "measured angle";
    for (size_t r = 0; r < P.records(); ++r) {
      const size_t m = P.rows(r).size(), mf = P.fit_rows(r);
      for (int j = 0; j < 2; ++j) {
        std::vector<double> q;
        for (size_t k = mf; k < m; ++k) q.push_back(P.measured(r)[static_cast<Eigen::Index>(j * m + k)]);
        const double s = RmsAboutMean(q) * P.weight(r, j);
        g.tt_te[j] += s * s * static_cast<double>(q.size());
      }
    }
    *banks_out = std::move(banks);
    *g_out = std::move(g);
  };
  // Column k of J replaced by the secant (q(x) - q(theta)) / (x_k - theta_k).
  auto Secant = [&](Eigen::MatrixXd* J, int k, const MotionProblem::Rollout& rx, double dx) {
    Eigen::Index off = 0;
    for (size_t r = 0; r < P.records(); ++r) {
      J->col(k).segment(off, rx.q[r].size()) = (rx.q[r] - at.q[r]) / dx;
      off += rx.q[r].size();
    }
  };
  // Exact BIC of a fit-part cost (Cost, Part::kFit) with k parameters (the selection's effective
  // sample size).
  auto ExactBic = [&](double cost, size_t k) {
    const double n_eff = g_last.n_eff > 0 ? g_last.n_eff : 1.0, n_tr = std::max(g_last.n_tr, 1.0);
    return n_eff * std::log(cost / n_tr) + static_cast<double>(k) * std::log(n_eff);
  };
  auto ParameterCount = [&](const std::vector<int>& set) {
    size_t k = 0;
    for (int c : set) k += cands[static_cast<size_t>(c)].cols.size();
    return k;
  };
  // The exchanges of motion_fit.h step 5: a chosen effect replaced by a candidate where the linear
  // model of this round (bank, g) ranks the swap lowest in BIC and the exact plant confirms it (the
  // swapped set refined from the set's values, the effect taken out, and from the linear fit's: its
  // fit-part BIC lower); kMotionExchanges at most.
  // Forward selection with backward elimination misses a swap when an effect entered early stands in
  // for one that only pays once others are in (a knee joint_stiffness for a strap, issue 41).
  auto Exchange = [&](const ColumnBank& bank, const Grams& g, int round) {
    for (int ex = 0; ex < kMotionExchanges; ++ex) {
      const Fit cur = FitCols(g, ColumnsOf(bank, chosen), false);
      if (!cur.ok) break;
      double best_bic = cur.bic;
      std::vector<int> best_set;
      Fit best_fit;
      for (size_t i = 0; i < chosen.size(); ++i)
        for (size_t c = 0; c < cands.size(); ++c) {
          if (std::find(chosen.begin(), chosen.end(), static_cast<int>(c)) != chosen.end()) continue;
          std::vector<int> set = chosen;
          set[i] = static_cast<int>(c);
          const Fit f = FitCols(g, ColumnsOf(bank, set), false);
          if (f.ok && f.bic < best_bic) best_bic = f.bic, best_set = set, best_fit = f;
        }
      if (best_set.empty()) break;
      Eigen::VectorXd kept = theta, lin = theta;
      for (int c : chosen)
        if (std::find(best_set.begin(), best_set.end(), c) == best_set.end())
          for (int k : cands[static_cast<size_t>(c)].cols) kept[k] = lin[k] = 0;
      for (size_t k = 0; k < best_fit.cols.size(); ++k)
        lin[best_fit.cols[k]] =
            std::clamp(best_fit.coef[static_cast<Eigen::Index>(k)], P.lower(best_fit.cols[k]), P.upper(best_fit.cols[k]));
      const Refined rf = Refine(P, ColumnsOf(cand_bank, best_set), {lin, kept}, kMotionLmIterations, false);
      if (!std::isfinite(rf.cost)) break;
      const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
      const double bic_x = ExactBic(rf.cost, ParameterCount(best_set));
      const bool better = bic_x < bic_now;
      D.selection.push_back("round " + std::to_string(round + 1) + ": exchange " + Labels(P, chosen) + " -> " +
                            Labels(P, best_set) + ": exact BIC " + NumberText(bic_now, 4) + " -> " +
                            NumberText(bic_x, 4) + (better ? ", taken" : ", not taken"));
      if (!better) break;
      MotionProblem::Rollout rx = P.Simulate(rf.theta, Part::kBoth);  // both parts, for what follows
      if (!rx.ok) break;
      chosen = best_set, theta = rf.theta, at = std::move(rx);
    }
    // The friction's form on the exact plant: each named viscous friction exchanged for a Coulomb
    // friction at its joint and the other way round (the linear model's ranking cannot tell the two
    // apart where the joint's speed is nearly constant in magnitude; the torque fit's confusion),
    // from the value dissipating the same power at the joint's RMS speed (c = b qd_rms) and from the
    // torque fit's, taken where the exact fit-part BIC is lower.
    for (size_t i = 0; i < chosen.size(); ++i) {
      const Candidate& from = cands[static_cast<size_t>(chosen[i])];
      if (from.name != "viscous_friction" && from.name != "coulomb_friction") continue;
      const bool to_coulomb = from.name == "viscous_friction";
      const int to = P.CandidateIndex(to_coulomb ? "coulomb_friction" : "viscous_friction", kJoint[from.joint]);
      if (to < 0 || std::find(chosen.begin(), chosen.end(), to) != chosen.end()) continue;
      std::vector<int> set = chosen;
      set[i] = to;
      const int kf = from.cols[0], kt = cands[static_cast<size_t>(to)].cols[0];
      const double v = theta[kf], speed = P.qd_rms(from.joint);
      std::vector<Eigen::VectorXd> starts(1, theta);
      starts[0][kf] = 0;
      starts[0][kt] = std::clamp(to_coulomb ? v * speed : v / speed, P.lower(kt), P.upper(kt));
      for (const DiagnosedEffect& d : T.effects)
        if (d.effect.name == cands[static_cast<size_t>(to)].name && d.effect.joint == kJoint[from.joint]) {
          starts.push_back(starts[0]);
          starts.back()[kt] = std::clamp(d.effect.value, P.lower(kt), P.upper(kt));
        }
      const Refined rf = Refine(P, ColumnsOf(cand_bank, set), starts, kMotionLmIterations, false);
      if (!std::isfinite(rf.cost)) continue;
      const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
      const double bic_x = ExactBic(rf.cost, ParameterCount(set));
      const bool better = bic_x < bic_now;
      D.selection.push_back("round " + std::to_string(round + 1) + ": friction form " + Labels(P, chosen) + " -> " +
                            Labels(P, set) + ": exact BIC " + NumberText(bic_now, 4) + " -> " + NumberText(bic_x, 4) +
                            (better ? ", taken" : ", not taken"));
      if (!better) continue;
      MotionProblem::Rollout rx = P.Simulate(rf.theta, Part::kBoth);
      if (!rx.ok) continue;
      chosen = set, theta = rf.theta, at = std::move(rx);
    }
  };
  // The torque fit's effects put to the plant (motion_fit.h step 5): each effect the torque fit names
  // that is a candidate and not chosen, added to the set at the torque fit's value (fitted on the
  // same fit parts), is tried further where it lowers the held-out simulated error at its joint by
  // kMinHeldoutGain; then refined with the set from there, taken where the exact fit-part BIC is
  // lower. One that conflicts with a chosen effect (Conflicts: the other gravity axis, a shared
  // offset) is not tried. The torque residual has weighed it already (the BIC margin, held-out gains,
  // |t|); the plant has to agree, not to find it again: where the fit part barely moves a joint, its
  // friction shows in the torque but only weakly in 0.5 s windows of simulated motion. A torque fit's
  // stand-in for an effect the torque cannot see (a ripple for a dead band) moves the held-out motion
  // away and is not refined.
  auto ConfirmTorqueNamed = [&]() {
    auto eligible = [&](int c) {
      return c >= 0 && std::none_of(chosen.begin(), chosen.end(), [&](int s) {
               return Conflicts(cands[static_cast<size_t>(s)], cands[static_cast<size_t>(c)]);
             });
    };
    // Each effect's trial at the current values; all remaining ones simulated together (in parallel)
    // whenever the set changes.
    std::vector<int> cand_of(T.effects.size(), -1);
    std::vector<Eigen::VectorXd> trial(T.effects.size());
    std::vector<MotionProblem::Rollout> trial_ro(T.effects.size());
    std::vector<char> simulated(T.effects.size(), 0);
    for (size_t e = 0; e < T.effects.size(); ++e) {
      const Effect& fx = T.effects[e].effect;
      cand_of[e] = P.CandidateIndex(fx.name, fx.joint, fx.name == "gravity_error" ? fx.axis : "");
    }
    for (size_t e = 0; e < T.effects.size(); ++e) {
      const int c = cand_of[e];
      if (!eligible(c)) continue;
      if (!simulated[e]) {
        std::vector<size_t> batch;
        std::vector<Eigen::VectorXd> xs;
        for (size_t f = e; f < T.effects.size(); ++f) {
          if (!eligible(cand_of[f])) continue;
          Eigen::VectorXd x = theta;
          if (!TorqueValues(P, T.effects[f].effect, &x)) continue;
          for (int k : cands[static_cast<size_t>(cand_of[f])].cols) x[k] = std::clamp(x[k], P.lower(k), P.upper(k));
          trial[f] = x;
          batch.push_back(f);
          xs.push_back(x);
        }
        const std::vector<MotionProblem::Rollout> ro = P.SimulateAll(xs, Part::kHeldOut);
        for (size_t b = 0; b < batch.size(); ++b) trial_ro[batch[b]] = ro[b], simulated[batch[b]] = 1;
        if (!simulated[e]) continue;  // TorqueValues: no candidate value stands for it
      }
      const Candidate& cand = cands[static_cast<size_t>(c)];
      const Eigen::VectorXd& x = trial[e];
      std::string text = "the torque fit's " + cand.Label() + " = " + ValueText(P, cand, x) + " added to " +
                         Labels(P, chosen) + ": ";
      if (!trial_ro[e].ok) {
        D.selection.push_back(text + "the plant cannot simulate it, not taken");
        continue;
      }
      double te_now[2], te_x[2];
      P.Sse(at, Part::kHeldOut, te_now);
      P.Sse(trial_ro[e], Part::kHeldOut, te_x);
      const double gain = te_now[cand.joint] > 0 ? 1 - te_x[cand.joint] / te_now[cand.joint] : 0.0;
      text += "held-out simulated error at the " + std::string(kJoint[cand.joint]) + " " + NumberText(-100 * gain, 3) + " %";
      if (!(gain >= kMinHeldoutGain)) {
        D.selection.push_back(text + " (needed -" + NumberText(100 * kMinHeldoutGain) + " %), not taken");
        continue;
      }
      std::vector<int> set = chosen;
      set.push_back(c);
      const Refined rf = Refine(P, ColumnsOf(cand_bank, set), {x}, kMotionLmIterations, false);
      if (!std::isfinite(rf.cost)) continue;
      const double bic_now = ExactBic(Cost(P, at, Part::kFit), ParameterCount(chosen));
      const double bic_x = ExactBic(rf.cost, ParameterCount(set));
      const bool better = bic_x < bic_now;
      D.selection.push_back(text + "; refined, exact BIC " + NumberText(bic_now, 4) + " -> " + NumberText(bic_x, 4) +
                            (better ? ", taken" : ", not taken"));
      if (!better) continue;
      MotionProblem::Rollout rx = P.Simulate(rf.theta, Part::kBoth);
      if (!rx.ok) continue;
      chosen = set, theta = rf.theta, at = std::move(rx);
      std::fill(simulated.begin(), simulated.end(), 0);  // the trials of the rest, at the new values
    }
  };
  for (int round = 0; round < kMotionOuterSteps; ++round) {
    Eigen::MatrixXd J = P.Jacobian(theta, at, all, Part::kBoth);
    tau_eff = ResidualAutocorrelation(P, at, window_rows);
    // The one-parameter effects of the current set: secants from the set without them.
    std::vector<int> in_set;
    std::vector<Eigen::VectorXd> without;
    for (int c : chosen)
      if (cands[static_cast<size_t>(c)].cols.size() == 1 && theta[cands[static_cast<size_t>(c)].cols[0]] != 0) {
        in_set.push_back(cands[static_cast<size_t>(c)].cols[0]);
        without.push_back(theta);
        without.back()[in_set.back()] = 0;
      }
    const std::vector<MotionProblem::Rollout> ro_without = P.SimulateAll(without, Part::kBoth);
    for (size_t k = 0; k < in_set.size(); ++k)
      if (ro_without[k].ok) Secant(&J, in_set[k], ro_without[k], -(theta[in_set[k]]));
    Charge(kJacobians);
    std::vector<ColumnBank> banks;
    Grams g;
    Linearize(J, &banks, &g);
    // Screening (motion_fit.h step 3): every one-parameter candidate whose linear fit on top of the
    // current set is significant and lowers the BIC is refined alone on the plant (LM, the set held);
    // its column becomes the secant to that value, so the selection sees its exact single fit.
    {
      const Fit f_set = FitCols(g, ColumnsOf(banks[0], chosen), false);
      std::vector<int> screen;
      std::vector<Eigen::VectorXd> start;
      for (size_t c = 0; c < cands.size(); ++c) {
        const Candidate& cand = cands[c];
        if (cand.cols.size() != 1 || std::find(chosen.begin(), chosen.end(), static_cast<int>(c)) != chosen.end()) continue;
        std::vector<int> set = chosen;
        set.push_back(static_cast<int>(c));
        const Fit f = FitCols(g, ColumnsOf(banks[0], set), false);
        const int k = cand.cols[0];
        if (!f.ok || !(f.bic < f_set.bic) || !(std::abs(CoefOf(f, k)) > kMinT * SeOf(f, k))) continue;
        Eigen::VectorXd x = theta;
        x[k] = std::clamp(CoefOf(f, k), P.lower(k), P.upper(k));
        if (x[k] == theta[k]) continue;
        screen.push_back(k);
        start.push_back(x);
      }
      std::vector<double> refined(screen.size());
      std::vector<MotionProblem::Rollout> at_refined(screen.size());
      ParallelFor(screen.size(), DiagnoseThreads(opt), [&](size_t i) {
        const int k = screen[i];
        refined[i] = RefineOne(P, k, theta, at, start[i][k], kMotionScreenIterations);
        if (refined[i] == theta[k]) return;
        Eigen::VectorXd x = theta;
        x[k] = refined[i];
        at_refined[i] = P.Simulate(x, Part::kBoth);
      });
      for (size_t i = 0; i < screen.size(); ++i)
        if (at_refined[i].ok) Secant(&J, screen[i], at_refined[i], refined[i] - theta[screen[i]]);
      if (!screen.empty()) Linearize(J, &banks, &g);
      Charge(kScreening);
    }
    Fit lin;
    SelectionTrace trace;
    chosen = SelectEffects(banks[0], g, P.scale(), opt.max_effects, loo, &lin, &trace);
    for (const auto& s : trace.steps)
      D.selection.push_back("round " + std::to_string(round + 1) + " (linearized at " + Labels(P, previous) + "): " + s);
    g_last = std::move(g);
    if (chosen.empty()) {
      theta = zero, at = given;
      break;
    }
    const std::vector<int> cols = ColumnsOf(banks[0], chosen);
    Eigen::VectorXd start_lin = zero, start_torque = zero;
    for (size_t k = 0; k < lin.cols.size(); ++k) start_lin[lin.cols[k]] = lin.coef[static_cast<Eigen::Index>(k)];
    start_torque = start_lin;
    bool has_torque = false;
    for (int c : chosen)
      for (const DiagnosedEffect& e : T.effects) {
        const Candidate& cand = cands[static_cast<size_t>(c)];
        if (e.effect.name == cand.name && e.effect.joint == kJoint[cand.joint] &&
            (cand.name != "gravity_error" || e.effect.axis == cand.axis))
          has_torque = TorqueValues(P, e.effect, &start_torque) || has_torque;
      }
    std::vector<Eigen::VectorXd> starts = {start_lin};
    if (has_torque) starts.push_back(start_torque);
    Refined rf = Refine(P, cols, starts, kMotionLmIterations, false);
    if (!std::isfinite(rf.cost)) {
      // Neither start simulates (e.g. a strap's linear value too stiff for the step): from the current
      // values (the set's new effects at 0), which do.
      Eigen::VectorXd from_theta = zero;
      for (int k : cols) from_theta[k] = theta[k];
      rf = Refine(P, cols, {from_theta}, kMotionLmIterations, false);
    }
    if (!std::isfinite(rf.cost)) {
      D.selection.push_back("round " + std::to_string(round + 1) + ": " + Labels(P, chosen) +
                            " cannot be simulated at its fitted values; " +
                            (previous.empty() ? "nothing named" : "the last round's set kept"));
      chosen = previous;
      if (chosen.empty()) theta = zero, at = given;
      break;
    }
    theta = rf.theta;
    at = P.Simulate(theta, Part::kBoth);
    Charge(kRefinement);
    rounds.push_back({chosen, theta, rf.cost});
    std::ostringstream os;
    os << "round " << round + 1 << ": refined on the plant:";
    for (int c : chosen) {
      const Candidate& cand = cands[static_cast<size_t>(c)];
      os << " " << cand.Label() << " = " << ValueText(P, cand, theta);
    }
    D.selection.push_back(os.str());
    std::vector<int> key = chosen;
    std::sort(key.begin(), key.end());
    const bool repeated = std::find(seen.begin(), seen.end(), key) != seen.end();
    std::vector<int> last_key = previous;
    std::sort(last_key.begin(), last_key.end());
    const bool converged = repeated && rounds.size() >= 2 && last_key == key;
    if (!repeated) seen.push_back(key);
    previous = chosen;
    if (!repeated && round + 1 < kMotionOuterSteps) continue;
    // Converged (the round chose the last round's set again): this set. A cycle (a set of an earlier
    // round, not the last's) or out of rounds: the rounds' set of the lowest exact fit-part BIC (a
    // round linearized elsewhere may end on a worse set than an earlier one). Then the exchanges on
    // this round's linear model.
    size_t best = rounds.size() - 1;
    for (size_t k = 0; !converged && k < rounds.size(); ++k)
      if (ExactBic(rounds[k].cost, ParameterCount(rounds[k].set)) <
          ExactBic(rounds[best].cost, ParameterCount(rounds[best].set)))
        best = k;
    if (best + 1 != rounds.size()) {
      MotionProblem::Rollout rb = P.Simulate(rounds[best].theta, Part::kBoth);
      if (rb.ok) {
        D.selection.push_back("round " + std::to_string(best + 1) + "'s set " + Labels(P, rounds[best].set) +
                              " kept: exact BIC " +
                              NumberText(ExactBic(rounds[best].cost, ParameterCount(rounds[best].set)), 4) +
                              ", the last round's " + Labels(P, chosen) + " " +
                              NumberText(ExactBic(rounds.back().cost, ParameterCount(chosen)), 4));
        chosen = rounds[best].set, theta = rounds[best].theta, at = std::move(rb);
      }
    }
    Exchange(banks[0], g_last, round);
    break;
  }
  ConfirmTorqueNamed();

  Charge(kRefinement);
  // 6. The exact held-out gate.
  std::vector<double> explained(chosen.size(), 0.0);
  double sse_given_te[2];
  P.Sse(given, Part::kHeldOut, sse_given_te);
  Refined last;
  bool have_last = false;
  while (!chosen.empty()) {
    // A refined value outside its range (DESIGN.md's table: the selection checked the linear fit's)
    // goes first; else the effect whose removal raises the error at its joint least (of the held-out
    // ends, or with several records the better of that and the whole records left out), if below
    // kMinHeldoutGain.
    int drop = -1;
    std::string why;
    for (size_t k = 0; k < chosen.size() && drop < 0; ++k) {
      const Candidate& c = cands[static_cast<size_t>(chosen[k])];
      Eigen::VectorXd coef(static_cast<Eigen::Index>(c.cols.size()));
      for (size_t i = 0; i < c.cols.size(); ++i) coef[static_cast<Eigen::Index>(i)] = theta[c.cols[i]];
      if (!Plausible(ToEffect(c, coef, c.cols), P.scale(), &why)) {
        drop = static_cast<int>(k);
        why = "range: " + c.Label() + " removed at its refined value: " + why;
      }
    }
    if (drop < 0) {
      std::vector<Eigen::VectorXd> thetas = {theta};
      for (int c : chosen) {
        Eigen::VectorXd x = theta;
        for (int k : cands[static_cast<size_t>(c)].cols) x[k] = 0;
        thetas.push_back(x);
      }
      // With several records, both parts: the fit part's residual gives the values each record left
      // out takes (LeftOutThetas), whose whole-record error is the second test.
      const std::vector<MotionProblem::Rollout> ro = P.SimulateAll(thetas, loo ? Part::kBoth : Part::kHeldOut);
      double full[2];
      P.Sse(ro[0], Part::kHeldOut, full);
      std::vector<std::array<double, 2>> left_out(thetas.size(), {NAN, NAN});
      if (loo && ro[0].ok) {
        const std::vector<int> cols = ColumnsOf(cand_bank, chosen);
        const Eigen::MatrixXd J = WeightedFitJacobian(P, theta, ro[0], cols);
        const std::vector<Eigen::Index> fit_rows = PartRows(P, Part::kFit);
        for (size_t set = 0; set < thetas.size(); ++set) {
          if (!ro[set].ok) continue;
          std::vector<int> cs;
          std::vector<Eigen::Index> keep;
          for (size_t c = 0; c < cols.size(); ++c) {
            const auto& out = set == 0 ? std::vector<int>{} : cands[static_cast<size_t>(chosen[set - 1])].cols;
            if (std::find(out.begin(), out.end(), cols[c]) != out.end()) continue;
            cs.push_back(cols[c]);
            keep.push_back(static_cast<Eigen::Index>(c));
          }
          Eigen::MatrixXd Js(J.rows(), static_cast<Eigen::Index>(keep.size()));
          for (size_t c = 0; c < keep.size(); ++c) Js.col(static_cast<Eigen::Index>(c)) = J.col(keep[c]);
          int bad = -1;
          const std::vector<Eigen::VectorXd> lt =
              cs.empty() ? std::vector<Eigen::VectorXd>(P.records(), thetas[set])
                         : LeftOutThetas(P, thetas[set], cs, Js, WeightedResidual(P, ro[set], fit_rows), &bad);
          if (bad >= 0) continue;
          const std::vector<MotionProblem::Rollout> lro = P.SimulateEachRecord(lt);
          std::array<double, 2> sum = {0, 0};
          for (size_t r = 0; r < lro.size() && std::isfinite(sum[0]); ++r) {
            double a[2] = {NAN, NAN}, n;
            if (lro[r].ok) P.RecordSse(lro[r], r, Part::kBoth, a, &n);
            sum[0] += a[0], sum[1] += a[1];
          }
          left_out[set] = sum;
        }
      }
      double worst_gain = INFINITY, worst_held = 0, worst_left = NAN;
      explained.assign(chosen.size(), 0.0);
      for (size_t k = 0; k < chosen.size(); ++k) {
        const int j = cands[static_cast<size_t>(chosen[k])].joint;
        double without[2] = {INFINITY, INFINITY};
        if (ro[k + 1].ok) P.Sse(ro[k + 1], Part::kHeldOut, without);
        const double held = without[j] > 0 ? 1 - full[j] / without[j] : 0.0;
        // Records left out (several records): kept where either test gains kMinHeldoutGain (a record's
        // held-out end may lack the motion an effect shows in, which the other records carry).
        const double left = left_out[0][j] / left_out[k + 1][j];
        const double gain = std::isfinite(left) && left_out[k + 1][j] > 0 ? std::max(held, 1 - left) : held;
        explained[k] = 100 * ((without[0] + without[1]) - (full[0] + full[1])) /
                       std::max(sse_given_te[0] + sse_given_te[1], 1e-300);
        if (gain < worst_gain)
          worst_gain = gain, worst_held = held, worst_left = std::isfinite(left) ? 1 - left : NAN, drop = static_cast<int>(k);
      }
      if (worst_gain >= kMinHeldoutGain) break;
      const Candidate& wc = cands[static_cast<size_t>(chosen[static_cast<size_t>(drop)])];
      why = "exact held-out gate: " + wc.Label() + " removed: without it the held-out simulated error at the " +
            kJoint[wc.joint] + " is only " + NumberText(100 * worst_held, 3) + " % higher" +
            (std::isfinite(worst_left) ? ", the records' left out " + NumberText(100 * worst_left, 3) + " %" : "") +
            " (needed " + NumberText(100 * kMinHeldoutGain) + " %)";
    }
    D.selection.push_back(why);
    for (int k : cands[static_cast<size_t>(chosen[static_cast<size_t>(drop)])].cols) theta[k] = 0;
    chosen.erase(chosen.begin() + drop);
    have_last = false;
    if (chosen.empty()) {
      theta = zero;
      break;
    }
    const Refined rf = Refine(P, ColumnsOf(cand_bank, chosen), {theta});
    if (std::isfinite(rf.cost)) theta = rf.theta, last = rf, have_last = true;
  }
  at = P.Simulate(theta, Part::kBoth);
  if (!at.ok) throw SimulationError(0, "the motion fit's extended twin diverges on the records");
  Charge(kGate);

  // 7. Values and intervals from the final Jacobian: the set's values refined once more with the
  // weights of the extended twin's own misfit (motion_fit.h "Output weights").
  const std::vector<int> cols = ColumnsOf(cand_bank, chosen);
  if (!chosen.empty()) {
    const double before[2] = {P.weight(0), P.weight(1)};
    P.WeightBy(at);
    have_last = false;
    std::string text = "values refined with the extended twin's misfit as the output weights:";
    for (int j = params.one_joint ? 1 : 0; j < 2; ++j)
      text += std::string(" ") + kJoint[j] + " " + NumberText(1 / P.weight(j), 4) + " rad (was " + NumberText(1 / before[j], 4) + ")";
    D.selection.push_back(text);
  }
  D.tau_eff = ResidualAutocorrelation(P, at, window_rows);
  if (!chosen.empty()) {
    if (!have_last) last = Refine(P, cols, {theta});  // with the new weights (from theta, its band probes)
    theta = last.theta;
    at = P.Simulate(theta, Part::kBoth);
    Fit f;
    f.ok = true;
    f.cols = cols;
    f.coef.resize(static_cast<Eigen::Index>(cols.size()));
    for (size_t k = 0; k < cols.size(); ++k) f.coef[static_cast<Eigen::Index>(k)] = theta[cols[k]];
    const double n = static_cast<double>(last.e.size()), p = static_cast<double>(cols.size());
    const double s2 = last.e.squaredNorm() / std::max(n - p, 1.0) * D.tau_eff;
    const Eigen::MatrixXd A = last.J.transpose() * last.J;
    const Eigen::MatrixXd cov = s2 * A.ldlt().solve(Eigen::MatrixXd::Identity(A.rows(), A.cols()));
    f.se = cov.diagonal().cwiseMax(0).cwiseSqrt();
    for (size_t k = 0; k < chosen.size(); ++k) {
      DiagnosedEffect de = ToEffect(cands[static_cast<size_t>(chosen[k])], f);
      de.explained_pct = explained[k];
      D.effects.push_back(de);
    }
  }
  std::stable_sort(D.effects.begin(), D.effects.end(), [](const DiagnosedEffect& a, const DiagnosedEffect& b) {
    const bool sa = a.effect.name.rfind("sensor_", 0) == 0, sb = b.effect.name.rfind("sensor_", 0) == 0;
    return sa != sb ? !sa : a.explained_pct > b.explained_pct;
  });
  D.extended = params;
  for (const auto& de : D.effects) D.extended.effects.push_back(de.effect);
  // The sensor effects in the order the rollouts applied them (offset, gain, delay).
  std::stable_sort(D.extended.effects.begin() + static_cast<long>(params.effects.size()), D.extended.effects.end(),
                   [](const Effect& a, const Effect& b) {
                     auto rank = [](const Effect& e) {
                       return e.name == "sensor_offset" ? 1 : e.name == "sensor_gain" ? 2 : e.name == "sensor_delay" ? 3 : 0;
                     };
                     return rank(a) < rank(b);
                   });

  // Scores: the given vs the extended twin, held-out parts and whole records left out (rad).
  SimulationScores& S = D.simulation;
  S.horizon_s = opt.replay_horizon_s;
  S.cutoff_hz = 0;
  for (const MeasuredData* data : records) S.cutoff_hz = std::max(S.cutoff_hz, MotionCutoff(opt, *data));
  double sb[2] = {0, 0}, sa[2] = {0, 0}, cnt = 0, lb[2] = {0, 0}, la[2] = {0, 0}, lcnt = 0;
  // Each record left out in turn: the values one Gauss-Newton step from the final ones on the other
  // records' fit parts (the final refinement's Jacobian and residual; the round's linear model g_last
  // is linearized where that round started, which the rounds' choice and the exchanges may have left
  // far behind), each simulated on its record.
  std::vector<Eigen::VectorXd> loo_thetas;
  if (loo) {
    int bad = -1;
    if (cols.empty()) loo_thetas.assign(P.records(), theta);
    else loo_thetas = LeftOutThetas(P, theta, cols, last.J, last.e, &bad);
    if (bad >= 0)
      throw InputError(records[static_cast<size_t>(bad)]->source +
                       ": without this record the chosen effects are not identifiable");
  }
  const std::vector<MotionProblem::Rollout> loo_ro = P.SimulateEachRecord(loo_thetas);
  for (size_t r = 0; r < P.records(); ++r) {
    RecordScore rs;
    rs.source = records[r]->source;
    rs.samples = records[r]->size();
    double b[2], a[2], c;
    P.RecordSse(given, r, Part::kHeldOut, b, &c);
    P.RecordSse(at, r, Part::kHeldOut, a, &c);
    const auto& t = records[r]->t();
    const size_t split = P.rows(r)[P.fit_rows(r)];
    rs.sim_split_windows = P.windows(r, Part::kHeldOut);
    for (int j = 0; j < 2; ++j) {
      rs.split[j] = rs.sim_split[j] = Score(b[j], a[j], c);
      sb[j] += b[j], sa[j] += a[j];
    }
    cnt += c;
    if (loo) {
      double lb_r[2], la_r[2], lc;
      P.RecordSse(given, r, Part::kBoth, lb_r, &lc);
      if (!loo_ro[r].ok) throw SimulationError(0, rs.source + ": the effects fitted on the other records diverge on it");
      P.RecordSse(loo_ro[r], r, Part::kBoth, la_r, &lc);
      for (int j = 0; j < 2; ++j) {
        rs.left_out[j] = rs.sim_left_out[j] = Score(lb_r[j], la_r[j], lc);
        lb[j] += lb_r[j], la[j] += la_r[j];
      }
      lcnt += lc;
      rs.sim_left_out_windows = P.windows(r, Part::kBoth);
      rs.left_out_effects = params.effects;
      const std::vector<Effect> fx = P.EffectsOf(loo_thetas[r]);
      rs.left_out_effects.insert(rs.left_out_effects.end(), fx.begin(), fx.end());
    }
    if (r == 0) {  // the plotted series: the held-out part, NaN off the scored rows
      const size_t n = t.size(), m = P.rows(0).size();
      S.t.assign(t.begin() + static_cast<long>(split), t.end());
      for (int j = 0; j < 2; ++j) {
        S.measured[j].assign(n - split, std::nan(""));
        S.rigid[j] = S.extended[j] = S.measured[j];
        for (size_t k = P.fit_rows(0); k < m; ++k) {
          const size_t i = P.rows(0)[k] - split;
          const Eigen::Index row = static_cast<Eigen::Index>(j * m + k);
          S.measured[j][i] = P.measured(0)[row];
          S.rigid[j][i] = given.q[0][row];
          S.extended[j][i] = at.q[0][row];
        }
      }
    }
    D.records.push_back(rs);
  }
  for (int j = 0; j < 2; ++j) {
    D.joints[j] = S.split[j] = Score(sb[j], sa[j], cnt);
    if (loo) D.left_out[j] = S.left_out[j] = Score(lb[j], la[j], lcnt);
    D.noise[j] = P.weight(j) > 0 ? 1 / P.weight(j) : 0.0;
  }
  S.done = true;
  {
    std::ostringstream os;
    os << "the model given and the motion fit's extended twin (their effects in the MuJoCo plant, joint limits off) "
          "driven by the measured torque, in quiet windows of " << NumberText(opt.replay_horizon_s)
       << " s (replay --windows quiet) restarted from the measured state (the measured angle and its velocity, derived at "
       << NumberText(S.cutoff_hz)
       << " Hz or a tenth of a record's sample rate, zero-phase 2nd-order Butterworth; a strap run in over its settling "
          "time), on the held-out parts"
       << (loo ? " and on every whole record with the effects fitted on the others" : "");
    S.note = os.str();
  }

  // Torque only: what the torque fit names and the motion fit does not.
  std::vector<Eigen::VectorXd> tthetas;
  std::vector<size_t> tidx;
  for (size_t k = 0; k < T.effects.size(); ++k) {
    const Effect& e = T.effects[k].effect;
    bool named = false;
    for (const auto& de : D.effects)
      named = named || (de.effect.name == e.name && de.effect.joint == e.joint && de.effect.axis == e.axis);
    if (named) continue;
    TorqueOnlyEffect to;
    to.effect = e;
    Eigen::VectorXd x = theta;
    to.simulated = TorqueValues(P, e, &x);
    if (!to.simulated) to.why = P.WhyNoCandidate(e);
    if (to.simulated) {
      for (int c = 0; c < n_par; ++c) x[c] = std::clamp(x[c], P.lower(c), P.upper(c));
      tthetas.push_back(x);
      tidx.push_back(D.torque_only.size());
    }
    D.torque_only.push_back(to);
  }
  const std::vector<MotionProblem::Rollout> tro = P.SimulateAll(tthetas, Part::kHeldOut);
  double base_te[2];
  P.Sse(at, Part::kHeldOut, base_te);
  for (size_t k = 0; k < tro.size(); ++k) {
    TorqueOnlyEffect& to = D.torque_only[tidx[k]];
    if (!tro[k].ok) {
      to.simulated = false;
      to.why = "its rollout failed (the plant refused the values or diverged)";
      continue;
    }
    double s[2];
    P.Sse(tro[k], Part::kHeldOut, s);
    for (int j = 0; j < 2; ++j) to.heldout_change_pct[j] = base_te[j] > 0 ? 100 * (s[j] / base_te[j] - 1) : 0.0;
  }

  // The torque fit's twin on the same rows (SimulationScores::torque_fit_*): its effects, and per
  // record left out its values fitted without that record, as the plant carries them.
  if (S.done) {
    auto ThetaOf = [&](const std::vector<Effect>& fx, std::vector<std::string>* not_carried) {
      Eigen::VectorXd x = zero;
      for (const Effect& e : fx) {
        if (TorqueValues(P, e, &x)) continue;
        const std::string label = e.name + " (" + e.joint + ")";
        if (not_carried && std::find(not_carried->begin(), not_carried->end(), label) == not_carried->end())
          not_carried->push_back(label);
      }
      for (int c = 0; c < n_par; ++c) x[c] = std::clamp(x[c], P.lower(c), P.upper(c));
      return x;
    };
    std::vector<Effect> named;
    for (const DiagnosedEffect& d : T.effects) named.push_back(d.effect);
    const Eigen::VectorXd t_theta = ThetaOf(named, &S.torque_fit_not_carried);
    const MotionProblem::Rollout t_ro = P.Simulate(t_theta, Part::kHeldOut);
    std::vector<Eigen::VectorXd> t_loo;
    if (loo)
      for (size_t r = 0; r < P.records(); ++r) {
        const std::vector<Effect>& fx = T.records[r].left_out_effects;
        t_loo.push_back(ThetaOf(std::vector<Effect>(fx.begin() + static_cast<long>(std::min(params.effects.size(), fx.size())), fx.end()),
                                &S.torque_fit_not_carried));
      }
    const std::vector<MotionProblem::Rollout> t_loo_ro = P.SimulateEachRecord(t_loo);
    bool ok = t_ro.ok;
    for (const auto& ro : t_loo_ro) ok = ok && ro.ok;
    if (ok) {
      double tb[2] = {0, 0}, ta[2] = {0, 0}, tc = 0, ltb[2] = {0, 0}, lta[2] = {0, 0}, ltc = 0;
      for (size_t r = 0; r < P.records(); ++r) {
        double b[2], a[2], c;
        P.RecordSse(given, r, Part::kHeldOut, b, &c);
        P.RecordSse(t_ro, r, Part::kHeldOut, a, &c);
        for (int j = 0; j < 2; ++j) tb[j] += b[j], ta[j] += a[j];
        tc += c;
        if (!loo) continue;
        P.RecordSse(given, r, Part::kBoth, b, &c);
        P.RecordSse(t_loo_ro[r], r, Part::kBoth, a, &c);
        for (int j = 0; j < 2; ++j) ltb[j] += b[j], lta[j] += a[j];
        ltc += c;
      }
      for (int j = 0; j < 2; ++j) {
        S.torque_fit_split[j] = Score(tb[j], ta[j], tc);
        if (loo) S.torque_fit_left_out[j] = Score(ltb[j], lta[j], ltc);
      }
      S.torque_fit_done = true;
    }
  }

  Charge(kScores);
  {
    std::ostringstream os;
    os << "simulation, in replays of the records: set-up " << NumberText(cost[kSetUp], 3) << ", Jacobians "
       << NumberText(cost[kJacobians], 3) << ", screening " << NumberText(cost[kScreening], 3) << ", refinement "
       << NumberText(cost[kRefinement], 3) << ", held-out gate " << NumberText(cost[kGate], 3)
       << ", intervals and scores " << NumberText(cost[kScores], 3) << " (" << NumberText(P.ReplaysSimulated(), 4)
       << " in all)";
    D.selection.push_back(os.str());
  }
  D.kin = std::move(T.kin);
  D.split = T.split;
  std::ostringstream m;
  m << "motion fit: the candidate effects' values fitted by simulating the forward plant on the records (multiple "
       "shooting: quiet windows of " << NumberText(opt.replay_horizon_s) << " s, restarted from the measured state, the measured "
       "angle and its velocity derived at " << NumberText(D.simulation.cutoff_hz) << " Hz, where the motion has no fast content "
       "that velocity misses, a dead band's knocks, and scored while it stays so; replay --windows quiet), driven by the "
       "recorded actuator torque ("
    << (P.hold() ? "each sample held over the step" : "interpolated linearly between samples")
    << ", the closer of the two for the model given); outputs the "
       "angles weighted by 1 / the given twin's RMS simulated error per joint (" << NumberText(D.noise[0], 3) << " / "
    << NumberText(D.noise[1], 3) << " rad); fit on the first " << NumberText(100 * (1 - opt.holdout_fraction), 3)
    << " % of every record, held out the rest" << (loo ? ", every whole record also left out in turn" : "")
    << "; selection on the forward-difference Jacobian by the torque fit's gates (BIC margin " << NumberText(kBicMargin)
    << ", |t| > " << NumberText(kMinT) << ", held-out gain >= " << NumberText(100 * kMinHeldoutGain)
    << " %, ranges), values refined by projected Levenberg-Marquardt in the box of the ranges, each named effect "
       "checked on the exact held-out simulation; residual autocorrelation " << NumberText(D.tau_eff, 3) << " rows";
  D.method = m.str();
  return D;
}

}  // namespace exotwin
