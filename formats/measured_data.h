// The measured-data CSV of DESIGN.md (input of predict / diagnose / identify) and the kinematics
// derived from it.
#pragma once
#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/interpolate.h"  // Interpolate

#include "formats/csv_table.h"
#include "dsp/butterworth.h"

namespace exotwin {

// The required columns of a record, in MeasuredData::column_at's numbering.
enum RequiredColumn { kColT = 0, kColQHip = 1, kColQKnee = 2, kColTauHip = 3, kColTauKnee = 4 };

// A record in the measured-data schema. The table is the one home of every column (a long record's
// columns are not copied): t(), q_hip(), ... are views of the required columns in it. Built by
// MeasuredFromTable (validated) or MakeMeasuredData (trusted input); a default-constructed record is
// empty (size() == 0, the views empty).
struct MeasuredData {
  std::string source;  // file name, for messages
  CsvTable table;      // every column as read, in file order (t, q_*, tau_*, qd_*, cmd_*, emg_*, ...)
  // A record of a one-joint device (DESIGN.md "One-joint devices"): the file held t, q_knee, tau_knee
  // and no hip column; the table holds it embedded in the two-joint schema (q_hip = tau_hip = 0
  // appended: the joint as the knee of a leg whose hip is held still).
  bool one_joint = false;

  // The required columns: t (s, strictly increasing), q_hip, q_knee (rad), tau_hip, tau_knee (N m).
  const std::vector<double>& t() const { return Required(kColT); }
  const std::vector<double>& q_hip() const { return Required(kColQHip); }
  const std::vector<double>& q_knee() const { return Required(kColQKnee); }
  const std::vector<double>& tau_hip() const { return Required(kColTauHip); }
  const std::vector<double>& tau_knee() const { return Required(kColTauKnee); }
  // The same, writable (values only: the table keeps its shape). Precondition: bound (built by
  // MeasuredFromTable / MakeMeasuredData, or BindRequired called).
  std::vector<double>& column_at(int required) { return table.columns[at_[required]]; }

  size_t size() const { return t().size(); }
  // Optional column by name; nullptr if absent.
  const std::vector<double>* Column(const std::string& name) const;

  // Names the table's required columns (after the table was replaced). Throws InputError naming
  // `source` and the first missing column.
  void BindRequired();

 private:
  const std::vector<double>& Required(int k) const;
  int at_[5] = {-1, -1, -1, -1, -1};  // table column of t, q_hip, q_knee, tau_hip, tau_knee
};

// A MeasuredData of a table holding at least t, q_hip, q_knee, tau_hip, tau_knee, without the value
// checks of MeasuredFromTable (tables exotwin made itself). Throws InputError for a missing column.
MeasuredData MakeMeasuredData(CsvTable table, const std::string& source);

// Sanity bound on a recorded angle, rad: a record of an exoskeleton or a rig alone may turn a joint
// through several revolutions (the DFKI double pendulum's second link turns through 11 rad); beyond
// 1e4 rad the column is not an angle in rad (encoder counts, degrees declared as rad, ...).
inline constexpr double kMaxRecordedAngle = 1e4;
// A human joint's range, rad: the angle of a leg stays within one revolution.
inline constexpr double kMaxHumanJointAngle = 2 * M_PI;

// True for the column names of the measured-data schema (DESIGN.md): t, q_hip, q_knee, tau_hip,
// tau_knee, qd_*, qdd_*, cmd_* of hip and knee, and emg_<channel>.
bool IsMeasuredColumn(const std::string& name);

// True for a table of one joint: q_knee and tau_knee, and none of q_hip, tau_hip, qd_hip, qdd_hip,
// cmd_hip.
bool IsOneJointTable(const CsvTable& table);

// Appends the one-joint embedding's columns q_hip = 0 and tau_hip = 0 to a one-joint table.
void EmbedOneJoint(CsvTable* table);

// The columns of `data` as its file holds them: a one-joint record without the embedding's q_hip,
// tau_hip (what a command writes back).
CsvTable TableAsRecorded(const MeasuredData& data);

// Validates a table in the measured-data schema and returns it as MeasuredData (`source` names it in
// messages; the table's line_of_row gives the lines): required columns t, q_hip, q_knee, tau_hip,
// tau_knee, or t, q_knee, tau_knee of a one-joint table (IsOneJointTable: embedded, one_joint set); strictly increasing t; finite values in every schema column; angles within
// +-kMaxRecordedAngle rad; torques within +-1000 N m; EMG within +-100 V; at least `min_samples`
// rows. Throws InputError naming file, line and column.
MeasuredData MeasuredFromTable(CsvTable table, const std::string& source, size_t min_samples = 20);

// Reads a measured-data CSV and validates it as MeasuredFromTable does.
MeasuredData ReadMeasuredCsv(const std::string& path, size_t min_samples = 20);
// The columns a caller reads besides t, q_*, tau_* (which are always kept); empty: every column.
using MeasuredColumns = std::function<bool(const std::string& name)>;
// The same, storing only the columns `keep` names (a long record's columns no stage of the caller
// reads, e.g. a run's ref_*, state: memory). The columns left out are still read as numbers and a
// schema column's values validated: the same errors as ReadMeasuredCsv(path, min_samples).
MeasuredData ReadMeasuredCsv(const std::string& path, size_t min_samples, const MeasuredColumns& keep);

// The check for records of a human wearing the device (predict / identify / diagnose with a
// `human:` block): |q_hip|, |q_knee| <= kMaxHumanJointAngle. Throws InputError naming the file,
// the line and the column of the first angle beyond it.
void CheckHumanJointRange(const MeasuredData& data);

// Joint kinematics on the measured time base.
struct Kinematics {
  std::vector<double> t;
  // The record's first time (s, before any trim or window): a term's t counts from it; NaN: t.front().
  double t_start = std::nan("");
  std::vector<double> q[2], qd[2], qdd[2];  // [0] hip, [1] knee; rad, rad/s, rad/s^2
  bool resampled = false;                    // the input was non-uniform and went through a grid
  std::string derivative_source;             // "measured columns" or "butterworth 20 Hz"
  std::map<std::string, std::vector<double>> emg;  // emg_<channel> columns (V) by channel, e.g. "VM"
};

// Uses qd_*/qdd_* columns when present, else derives them as in Hwang & Jeon sec. 3.2: the angle is
// filtered by a zero-phase 2nd-order Butterworth low-pass at 20 Hz (forward-backward) and
// differentiated by central differences (dsp::ZeroPhaseDerivatives). Non-uniform sampling (any step off the median by more than
// 1 %) is handled by resampling the angles onto a uniform grid at the median step (linear
// interpolation), differentiating there, and interpolating back onto the measured times.
Kinematics DeriveKinematics(const MeasuredData& data, double cutoff_hz = 20.0);
// The same, taking the record's columns instead of copying them (t, q_*, emg_*; the other columns
// are released before the derivatives are computed): for a caller done with `data` (predict of a
// long record). `data` is left empty.
Kinematics DeriveKinematics(MeasuredData&& data, double cutoff_hz = 20.0);

// x (one value per time of t) filtered exactly as DeriveKinematics filters the angles: the
// zero-phase 2nd-order Butterworth low-pass at cutoff_hz, on a uniform grid at the median step when
// t is non-uniform. Used to filter measured and predicted torque alike (parallel filtering, so that
// the noise differentiation injects above the cutoff never shows as a discrepancy). `source` names
// the record in messages.
std::vector<double> LowPassOnTimeBase(const std::vector<double>& t, const std::vector<double>& x,
                                      double cutoff_hz, const std::string& source);

// The sampling of a record's times t as DeriveKinematics and LowPassOnTimeBase see it: the median
// step, and whether every step is within 1 % of it (uniform: the filters run on t's own samples;
// else on a uniform grid at the median step, from t's first time).
struct Sampling {
  double dt = 0;              // median step, s
  bool uniform = true;
  std::vector<double> grid;   // non-uniform only: t.front() + i dt
};
// Throws InputError naming `source` for a median step below 1e-6 s or a record too irregular to
// resample (as DeriveKinematics does).
Sampling ExamineSampling(const std::vector<double>& t, const std::string& source);

// LowPassOnTimeBase for many signals on one time base: the sampling examined and the filter
// designed once. Apply(x) gives LowPassOnTimeBase(t, x, cutoff_hz, source) bit for bit, without
// copying x. Keeps a copy of t when t is non-uniform (else no reference to it).
class TimeBaseLowPass {
 public:
  TimeBaseLowPass(const std::vector<double>& t, double cutoff_hz, const std::string& source);
  // With t's sampling already examined (s = ExamineSampling(t, source)).
  TimeBaseLowPass(const Sampling& s, const std::vector<double>& t, double cutoff_hz, const std::string& source);
  void Apply(std::vector<double>& x) const;  // x (one value per time of t) filtered in place
  // Apply to *xs[0] .. *xs[count - 1], faster than one by one (dsp::FiltFiltInPlace of several).
  void Apply(std::vector<double>* const* xs, size_t count) const;
  // Apply to count (1 .. 8) signals that fill(begin, end) writes block by block into (*xs[k])[begin ..
  // end) (dsp::FiltFiltGenerated; each *xs[k] sized as t): the same bits as fill(0, n) then Apply.
  void ApplyGenerated(std::vector<double>* const* xs, size_t count,
                      const std::function<void(size_t begin, size_t end)>& fill) const;
  std::vector<double> operator()(std::vector<double> x) const {
    Apply(x);
    return x;
  }

 private:
  bool uniform_ = true;
  std::vector<double> t_, grid_;  // non-uniform only
  std::vector<dsp::Biquad> sos_;
};

// The velocity and acceleration DeriveKinematics derives from angle q (one value per time of t)
// at cutoff_hz, on t's sampling s = ExamineSampling(t, source). Throws InputError naming `source`
// when cutoff_hz is not below half the sample rate.
struct AngleRates {
  std::vector<double> qd, qdd;
};
AngleRates DeriveAngleRates(const Sampling& s, const std::vector<double>& t, const std::vector<double>& q,
                            double cutoff_hz, const std::string& source);
// The same into *out, its vectors' storage reused (a caller deriving at several cutoffs), bit for bit.
void DeriveAngleRatesInto(const Sampling& s, const std::vector<double>& t, const std::vector<double>& q,
                          double cutoff_hz, const std::string& source, AngleRates* out);

// Median sample period (s) of strictly increasing times (>= 2 samples: else std::invalid_argument).
double MedianStep(const std::vector<double>& t);


}  // namespace exotwin
