#include "formats/measured_data.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "formats/number_text.h"
#include "core/error.h"
#include "core/parallel_for.h"
#include "dsp/butterworth.h"
#include "dsp/derivatives.h"

namespace exotwin {

const std::vector<double>* MeasuredData::Column(const std::string& name) const {
  const int i = table.Find(name);
  return i < 0 ? nullptr : &table.columns[i];
}

namespace {
const char* const kRequired[5] = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee"};
}  // namespace

const std::vector<double>& MeasuredData::Required(int k) const {
  static const std::vector<double> kNone;
  return at_[k] < 0 ? kNone : table.columns[at_[k]];
}

void MeasuredData::BindRequired() {
  for (int k = 0; k < 5; ++k) {
    at_[k] = table.Find(kRequired[k]);
    if (at_[k] < 0)
      throw InputError(source + ": missing required column '" + kRequired[k] +
                       "' (expected t, q_hip, q_knee, tau_hip, tau_knee)");
  }
}

MeasuredData MakeMeasuredData(CsvTable table, const std::string& source) {
  MeasuredData d;
  d.source = source;
  d.table = std::move(table);
  d.BindRequired();
  return d;
}

bool IsMeasuredColumn(const std::string& n) {
  static const char* kKnown[] = {"t", "q_hip", "q_knee", "tau_hip", "tau_knee", "qd_hip", "qd_knee",
                                 "qdd_hip", "qdd_knee", "cmd_hip", "cmd_knee"};
  for (const char* k : kKnown)
    if (n == k) return true;
  return n.rfind("emg_", 0) == 0;
}

namespace {

// "<file>:<line>: column '<name>': " (the sample's index when the table was built without lines).
std::string Where(const std::string& source, const CsvTable& t, size_t row, const std::string& column) {
  const std::string at = row < t.line_of_row.size() ? std::to_string(t.line_of_row[row])
                                                     : "sample " + std::to_string(row + 1);
  return source + ":" + at + ": column '" + column + "': ";
}

}  // namespace

bool IsOneJointTable(const CsvTable& table) {
  for (const char* hip : {"q_hip", "tau_hip", "qd_hip", "qdd_hip", "cmd_hip"}) {
    if (table.Find(hip) >= 0) return false;
    for (const CsvTable::Dropped& d : table.dropped)
      if (d.name == hip) return false;
  }
  return table.Find("q_knee") >= 0 && table.Find("tau_knee") >= 0;
}

void EmbedOneJoint(CsvTable* table) {
  for (const char* hip : {"q_hip", "tau_hip"}) {
    table->names.push_back(hip);
    table->columns.emplace_back(table->rows(), 0.0);
  }
}

CsvTable TableAsRecorded(const MeasuredData& data) {
  if (!data.one_joint) return data.table;
  CsvTable out;
  out.line_of_row = data.table.line_of_row;
  for (size_t c = 0; c < data.table.names.size(); ++c) {
    const std::string& n = data.table.names[c];
    if (n == "q_hip" || n == "tau_hip") continue;
    out.names.push_back(n);
    out.columns.push_back(data.table.columns[c]);
  }
  return out;
}

namespace {

// The bound on the values of schema column n (DESIGN.md "What the CSV reader accepts") and its unit.
double ValueLimit(const std::string& n, std::string* unit) {
  if (n == "q_hip" || n == "q_knee") return *unit = "rad", kMaxRecordedAngle;
  if (n == "tau_hip" || n == "tau_knee" || n.rfind("cmd_", 0) == 0) return *unit = "N m", 1000;
  if (n.rfind("emg_", 0) == 0) return *unit = "V", 100;
  return unit->clear(), 1e6;
}

}  // namespace

MeasuredData MeasuredFromTable(CsvTable table, const std::string& source, size_t min_samples) {
  MeasuredData d;
  d.source = source;
  d.one_joint = IsOneJointTable(table);
  if (d.one_joint) EmbedOneJoint(&table);
  d.table = std::move(table);
  d.BindRequired();
  const CsvTable& t = d.table;
  if (t.rows() < min_samples)
    throw InputError(source + ": " + std::to_string(t.rows()) + " samples, expected at least " +
                     std::to_string(min_samples));
  auto Check = [&](const std::string& n, size_t r, double v) {
    std::string unit;
    const double limit = ValueLimit(n, &unit);
    if (!std::isfinite(v))
      throw InputError(Where(source, t, r, n) + "value is not finite, expected a finite number");
    if (std::abs(v) > limit)
      throw InputError(Where(source, t, r, n) + "value " + NumberText(v) + " out of range, expected |x| <= " +
                       std::to_string(limit) + " " + unit);
  };
  // In file order: the columns the reader left out (their first failing value, CsvTable::dropped)
  // among those it kept.
  size_t next_dropped = 0;
  auto CheckDropped = [&](size_t before) {
    for (; next_dropped < t.dropped.size() && t.dropped[next_dropped].before <= before; ++next_dropped) {
      const CsvTable::Dropped& x = t.dropped[next_dropped];
      if (IsMeasuredColumn(x.name) && x.bad_row < t.rows()) Check(x.name, x.bad_row, x.bad_value);
    }
  };
  for (size_t c = 0; c < t.names.size(); ++c) {
    CheckDropped(c);
    const std::string& n = t.names[c];
    if (!IsMeasuredColumn(n)) continue;
    for (size_t r = 0; r < t.rows(); ++r) Check(n, r, t.columns[c][r]);
  }
  CheckDropped(t.names.size());
  const auto& tc = t.columns[t.Find("t")];
  for (size_t r = 1; r < tc.size(); ++r)
    if (!(tc[r] > tc[r - 1]))
      throw InputError(Where(source, t, r, "t") + std::to_string(tc[r]) + " not greater than the previous " +
                       std::to_string(tc[r - 1]) + ", expected strictly increasing time");
  return d;
}

double MedianStep(const std::vector<double>& t) {
  if (t.size() < 2) throw std::invalid_argument("MedianStep: fewer than 2 times");
  const size_t m = t.size() - 1, k = m / 2;  // the median: the k-th smallest of the m steps
  // Radix selection on the steps' bit patterns, which order as the values do where every step is
  // positive: the patterns in [lo, hi] hold the k-th smallest (rank k among them); each pass counts
  // them by the 12 bits below the prefix lo and hi share and keeps the bin where rank k falls, then
  // narrows [lo, hi] to that bin's least and largest pattern, until one pattern is left. A few passes
  // over t (a time base's steps take few distinct values), no copy. A step that is not positive
  // (times out of order, NaN): the selection below.
  auto Bits = [&](size_t i) {
    const double d = t[i + 1] - t[i];
    uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    return b;
  };
  bool positive = true;
  uint64_t lo = ~uint64_t{0}, hi = 0;
  for (size_t i = 0; i < m; ++i) {
    positive &= t[i + 1] - t[i] > 0;
    const uint64_t b = Bits(i);
    lo = std::min(lo, b), hi = std::max(hi, b);
  }
  if (positive) {
    size_t rank = k;
    while (lo != hi) {
      constexpr int kBits = 12;
      const int below_prefix = 64 - __builtin_clzll(lo ^ hi);
      const int shift = std::max(0, below_prefix - kBits);
      std::vector<size_t> count(size_t{1} << kBits, 0);
      for (size_t i = 0; i < m; ++i) {
        const uint64_t b = Bits(i);
        if (b >= lo && b <= hi) ++count[(b >> shift) & ((uint64_t{1} << kBits) - 1)];
      }
      size_t bin = 0;
      while (rank >= count[bin]) rank -= count[bin++];
      // The bin's patterns: lo and hi's prefix, then bin; its least and largest taken in one more pass.
      const uint64_t bin_lo = std::max(lo, ((lo >> (shift + kBits)) << (shift + kBits)) | (uint64_t{bin} << shift));
      const uint64_t bin_hi = std::min(hi, bin_lo | ((uint64_t{1} << shift) - 1));
      uint64_t new_lo = ~uint64_t{0}, new_hi = 0;
      for (size_t i = 0; i < m; ++i) {
        const uint64_t b = Bits(i);
        if (b >= bin_lo && b <= bin_hi) new_lo = std::min(new_lo, b), new_hi = std::max(new_hi, b);
      }
      lo = new_lo, hi = new_hi;
    }
    double d;
    std::memcpy(&d, &lo, sizeof d);
    return d;
  }
  std::vector<double> d(t.size() - 1);
  for (size_t i = 0; i + 1 < t.size(); ++i) d[i] = t[i + 1] - t[i];
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

MeasuredData ReadMeasuredCsv(const std::string& path, size_t min_samples) {
  return MeasuredFromTable(ReadCsv(path), path, min_samples);
}

MeasuredData ReadMeasuredCsv(const std::string& path, size_t min_samples, const MeasuredColumns& keep) {
  if (!keep) return ReadMeasuredCsv(path, min_samples);
  CsvColumnFilter f;
  f.keep = [&](const std::string& n) {
    return n == "t" || n == "q_hip" || n == "q_knee" || n == "tau_hip" || n == "tau_knee" || keep(n);
  };
  f.check = [](const std::string& n, double v) {
    std::string unit;
    return !IsMeasuredColumn(n) || (std::isfinite(v) && std::abs(v) <= ValueLimit(n, &unit));
  };
  return MeasuredFromTable(ReadCsv(path, f), path, min_samples);
}

void CheckHumanJointRange(const MeasuredData& data) {
  const std::pair<const char*, const std::vector<double>*> angles[] = {{"q_hip", &data.q_hip()},
                                                                      {"q_knee", &data.q_knee()}};
  for (const auto& [name, q] : angles)
    for (size_t r = 0; r < q->size(); ++r)
      if (std::abs((*q)[r]) > kMaxHumanJointAngle)
        throw InputError(Where(data.source, data.table, r, name) + "angle " + NumberText((*q)[r]) +
                         " rad is beyond a human joint's range, expected |q| <= " +
                         std::to_string(kMaxHumanJointAngle) +
                         " rad (2 pi) for a model with a human: block (a record of the device alone may "
                         "turn further: drop the human: block)");
}

namespace {

// Throws unless cutoff_hz is below half the sample rate of s.
void CheckCutoff(const Sampling& s, double cutoff_hz, const std::string& source) {
  if (!(cutoff_hz < 0.5 / s.dt))
    throw InputError(source + ": sample period " + NumberText(s.dt) + " s is too long for the " +
                     NumberText(cutoff_hz) + " Hz derivative filter, expected a sample rate above " +
                     NumberText(2 * cutoff_hz) + " Hz");
}

}  // namespace

Sampling ExamineSampling(const std::vector<double>& t, const std::string& source) {
  Sampling s;
  const size_t n = t.size();
  s.dt = MedianStep(t);
  if (!(s.dt >= 1e-6))
    throw InputError(source + ": column 't': median sample period " + NumberText(s.dt) +
                     " s, expected at least 1e-6 s (a sample rate up to 1 MHz)");
  for (size_t i = 0; i + 1 < n; ++i)
    if (std::abs(t[i + 1] - t[i] - s.dt) > 0.01 * s.dt) { s.uniform = false; break; }
  if (!s.uniform) {
    const double span = t.back() - t.front();
    const double points = std::floor(span / s.dt) + 1;
    if (!(points <= std::max(100.0 * static_cast<double>(n), 1e6)))
      throw InputError(source + ": column 't': sampling too irregular to resample (median step " +
                       NumberText(s.dt) + " s over " + NumberText(span) + " s needs " + NumberText(points) +
                       " grid points for " + std::to_string(n) +
                       " samples), expected roughly uniform sampling without long gaps");
    const size_t m = static_cast<size_t>(points);
    s.grid.resize(m);
    for (size_t i = 0; i < m; ++i) s.grid[i] = t.front() + s.dt * static_cast<double>(i);
  }
  return s;
}

TimeBaseLowPass::TimeBaseLowPass(const std::vector<double>& t, double cutoff_hz, const std::string& source)
    : TimeBaseLowPass(ExamineSampling(t, source), t, cutoff_hz, source) {}

TimeBaseLowPass::TimeBaseLowPass(const Sampling& s, const std::vector<double>& t, double cutoff_hz,
                                 const std::string& source)
    : uniform_(s.uniform) {
  CheckCutoff(s, cutoff_hz, source);
  sos_ = dsp::DesignButterworth(2, dsp::BandType::kLowPass, 1.0 / s.dt, cutoff_hz);
  if (!uniform_) t_ = t, grid_ = s.grid;
}

void TimeBaseLowPass::Apply(std::vector<double>* const* xs, size_t count) const {
  if (uniform_) {
    dsp::FiltFiltInPlace(sos_, xs, count);
    return;
  }
  std::vector<std::vector<double>> on_grid(count);
  std::vector<std::vector<double>*> ptr(count);
  for (size_t k = 0; k < count; ++k) on_grid[k] = Interpolate(t_, *xs[k], grid_), ptr[k] = &on_grid[k];
  dsp::FiltFiltInPlace(sos_, ptr.data(), count);
  for (size_t k = 0; k < count; ++k) *xs[k] = Interpolate(grid_, on_grid[k], t_);
}

void TimeBaseLowPass::ApplyGenerated(std::vector<double>* const* xs, size_t count,
                                     const std::function<void(size_t begin, size_t end)>& fill) const {
  if (uniform_) {
    dsp::FiltFiltGenerated(sos_, xs, count, fill);
    return;
  }
  if (count > 0) fill(0, xs[0]->size());
  Apply(xs, count);
}

void TimeBaseLowPass::Apply(std::vector<double>& x) const {
  std::vector<double>* one = &x;
  Apply(&one, 1);
}

std::vector<double> LowPassOnTimeBase(const std::vector<double>& t, const std::vector<double>& x,
                                      double cutoff_hz, const std::string& source) {
  return TimeBaseLowPass(t, cutoff_hz, source)(x);
}

AngleRates DeriveAngleRates(const Sampling& s, const std::vector<double>& t, const std::vector<double>& q,
                            double cutoff_hz, const std::string& source) {
  AngleRates r;
  DeriveAngleRatesInto(s, t, q, cutoff_hz, source, &r);
  return r;
}

void DeriveAngleRatesInto(const Sampling& s, const std::vector<double>& t, const std::vector<double>& q,
                          double cutoff_hz, const std::string& source, AngleRates* out) {
  CheckCutoff(s, cutoff_hz, source);
  AngleRates& r = *out;
  if (s.uniform) {
    dsp::ZeroPhaseRates(q, s.dt, cutoff_hz, &r.qd, &r.qdd);
    return;
  }
  dsp::ZeroPhaseRates(Interpolate(t, q, s.grid), s.dt, cutoff_hz, &r.qd, &r.qdd);
  r.qd = Interpolate(s.grid, r.qd, t);
  r.qdd = Interpolate(s.grid, r.qdd, t);
}

namespace {

// DeriveKinematics on k (t, q and emg already set from the record; qd_* / qdd_* columns given or
// null; `source` names the record in messages).
void Derive(const std::vector<double>* measured[2][2], const std::string& source, double cutoff_hz,
            Kinematics* out) {
  Kinematics& k = *out;
  bool all_measured = true;
  for (int j = 0; j < 2; ++j) {
    if (measured[j][0] && measured[j][1]) {
      k.qd[j] = *measured[j][0];
      k.qdd[j] = *measured[j][1];
    } else {
      all_measured = false;
    }
  }
  if (all_measured) {
    k.derivative_source = "measured columns";
    return;
  }
  const Sampling s = ExamineSampling(k.t, source);
  CheckCutoff(s, cutoff_hz, source);
  k.resampled = !s.uniform;
  // The two angles on two threads (each into vectors sized here: a worker allocates nothing
  // record-long on a uniform record), the same bits as one after the other.
  AngleRates r[2];
  for (int j = 0; j < 2; ++j) r[j].qd.reserve(k.t.size()), r[j].qdd.reserve(k.t.size());
  const int threads = k.t.size() < kMinSamplesToSplit ? 1 : 2;
  ParallelFor(2, threads, [&](size_t j) { DeriveAngleRatesInto(s, k.t, k.q[j], cutoff_hz, source, &r[j]); });
  for (int j = 0; j < 2; ++j) {
    const auto* qd = measured[j][0];
    const auto* qdd = measured[j][1];
    if (qd) k.qd[j] = *qd;
    else k.qd[j] = std::move(r[j].qd);
    if (qdd) k.qdd[j] = *qdd;
    else k.qdd[j] = std::move(r[j].qdd);
  }
  k.derivative_source = "butterworth " + NumberText(cutoff_hz) + " Hz";
}

bool IsEmgChannel(const std::string& name) { return name.rfind("emg_", 0) == 0 && name.size() > 4; }

}  // namespace

Kinematics DeriveKinematics(const MeasuredData& data, double cutoff_hz) {
  Kinematics k;
  k.t = data.t();
  if (!k.t.empty()) k.t_start = k.t.front();
  k.q[0] = data.q_hip();
  k.q[1] = data.q_knee();
  for (size_t c = 0; c < data.table.names.size(); ++c)
    if (IsEmgChannel(data.table.names[c])) k.emg[data.table.names[c].substr(4)] = data.table.columns[c];
  const char* names[2] = {"hip", "knee"};
  const std::vector<double>* measured[2][2];
  for (int j = 0; j < 2; ++j) {
    measured[j][0] = data.Column(std::string("qd_") + names[j]);
    measured[j][1] = data.Column(std::string("qdd_") + names[j]);
  }
  Derive(measured, data.source, cutoff_hz, &k);
  return k;
}

Kinematics DeriveKinematics(MeasuredData&& data, double cutoff_hz) {
  Kinematics k;
  k.t = std::move(data.column_at(kColT));
  if (!k.t.empty()) k.t_start = k.t.front();
  k.q[0] = std::move(data.column_at(kColQHip));
  k.q[1] = std::move(data.column_at(kColQKnee));
  CsvTable& tab = data.table;
  const char* names[2] = {"hip", "knee"};
  std::vector<double> columns[2][2];  // qd_*, qdd_* when recorded
  const std::vector<double>* measured[2][2] = {{nullptr, nullptr}, {nullptr, nullptr}};
  for (int j = 0; j < 2; ++j)
    for (int d = 0; d < 2; ++d) {
      const int c = tab.Find(std::string(d == 0 ? "qd_" : "qdd_") + names[j]);
      if (c < 0) continue;
      columns[j][d] = std::move(tab.columns[c]);
      measured[j][d] = &columns[j][d];
    }
  for (size_t c = 0; c < tab.names.size(); ++c)
    if (IsEmgChannel(tab.names[c])) k.emg[tab.names[c].substr(4)] = std::move(tab.columns[c]);
  const std::string source = std::move(data.source);
  data = MeasuredData();
  Derive(measured, source, cutoff_hz, &k);
  return k;
}

}  // namespace exotwin
