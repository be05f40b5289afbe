// Reference trajectories for the joint position controllers: exciting trajectories for identification
// (sums of harmonics, Hwang & Jeon 2015 sec. 3.3), physiological gait at 2 km/h (sec. 3.4, gait
// pattern from Winter's marker data), a recorded motion (TabulatedTrajectory), a held joint, and
// compositions of them.
//
// Conventions (DESIGN.md): hip th1 = 0 hanging, flexion positive; knee th2 = 0 straight, flexion
// negative; rad, rad/s, rad/s^2, s.
//
// Real-time: every Sample()/At() is const, allocation-free and exception-free. Constructors and
// factories run at set-up and throw exotwin::InputError on bad input.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace exotwin::controller {

// Desired state of one joint at one instant.
struct JointSetpoint {
  double q = 0;    // rad
  double qd = 0;   // rad/s
  double qdd = 0;  // rad/s^2
};

// One joint's reference, q(t) with analytic derivatives.
class JointTrajectory {
 public:
  virtual ~JointTrajectory() = default;
  // Setpoint at time t (s, finite). Real-time safe.
  virtual JointSetpoint At(double t) const = 0;
};

// Reference for the whole leg (hip and knee).
class LegTrajectory {
 public:
  virtual ~LegTrajectory() = default;
  // Writes the hip and knee setpoints at time t (s, finite). hip, knee non-null. Real-time safe.
  virtual void Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const = 0;
};

// Truncated Fourier series q(t) = c0 + sum_k [a_k sin(2 pi k f0 t) + b_k cos(2 pi k f0 t)].
// Derivatives are analytic (term-by-term). Periodic with period 1/f0.
class FourierSeries {
 public:
  struct Term {
    int k = 1;       // harmonic number >= 1
    double a = 0;    // sine coefficient, rad
    double b = 0;    // cosine coefficient, rad
  };
  FourierSeries() = default;
  // f0 > 0 Hz (fundamental), k >= 1 for every term, all values finite; throws InputError otherwise.
  FourierSeries(double c0, double f0, std::vector<Term> terms);
  // Value and first two time derivatives at t (s). Real-time safe.
  JointSetpoint Eval(double t) const;
  double c0() const { return c0_; }
  double f0() const { return f0_; }
  const std::vector<Term>& terms() const { return terms_; }
  // Triangle-inequality bound on |d^n q/dt^n| (n >= 1) over all t: sum_k (2 pi k f0)^n sqrt(a^2+b^2).
  double DerivativeBound(int n) const;

 private:
  double c0_ = 0, f0_ = 1;
  std::vector<Term> terms_;
};

// Excitation design limits for one joint (Design()). Angles rad, speeds rad/s, accelerations rad/s^2.
struct ExcitationSpec {
  double q_min = 0, q_max = 0;  // joint range the trajectory must stay in
  double qd_max = 0;            // |qd| limit
  double qdd_max = 0;           // |qdd| limit
  double f0_hz = 0.1;           // fundamental; period 1/f0 = 10 s
  int k_min = 3, k_max = 15;    // harmonics used: f = k f0 in [0.3, 1.5] Hz (paper sec. 3.1)
  double band_lo_hz = 0.3, band_hi_hz = 1.5;  // every k f0 must lie in this band (gait frequencies)
  double fill = 0.98;           // fraction of the binding limit actually used (tracking margin)
  // Paper sec. 3.3: hip 5..40 deg, |qd| <= 120 deg/s; qdd_max = 1000 deg/s^2 (not in the paper: about
  // the acceleration of a 1.5 Hz sine at the speed limit).
  static ExcitationSpec PaperHip();
  // Paper sec. 3.3: knee -70..-5 deg, |qd| <= 165 deg/s; qdd_max = 1500 deg/s^2 (our choice, as hip).
  static ExcitationSpec PaperKnee();
};

// Exciting trajectory for identification: a Fourier series whose harmonics all lie in the gait band.
// Designed trajectories start (and end every period) at rest: qd(0) = qdd(0) = 0, so a PD holding
// the joint at StartPose() sees no step when the trajectory begins; repeating periods join smoothly.
class HarmonicTrajectory : public JointTrajectory {
 public:
  // From explicit coefficients (see FourierSeries). No limit checking.
  explicit HarmonicTrajectory(FourierSeries series);
  // Random design: a_k, b_k ~ U(-1, 1)/k from std::mt19937_64(seed) (own uniform from 53 raw bits,
  // identical on every standard library), projected so that sum k a_k = 0 (qd(0) = 0) and
  // sum k^2 b_k = 0 (qdd(0) = 0), then scaled by fill * the largest factor meeting the range, speed
  // and acceleration limits and offset to centre the range. Limits are verified on a grid of 20000
  // points per period plus the interpolation bound max|f''| dt^2/8, so they hold for every t.
  // Throws InputError on an inconsistent spec (q_min >= q_max, non-positive limits, harmonics outside
  // the band, fill outside (0, 1]).
  static HarmonicTrajectory Design(const ExcitationSpec& spec, uint64_t seed);
  JointSetpoint At(double t) const override;
  // Period 1/f0, s.
  double Period() const { return 1.0 / series_.f0(); }
  // q(0), rad: where the joint must be held before t = 0.
  double StartPose() const { return series_.Eval(0.0).q; }
  const FourierSeries& series() const { return series_; }

  // Extremes over all t (dense grid + interpolation bound), used by Design() and tests.
  struct Extremes {
    double q_min, q_max, qd_abs_max, qdd_abs_max;
  };
  static Extremes BoundExtremes(const FourierSeries& s);

 private:
  FourierSeries series_;
};

// A joint held still at q (e.g. hip at 90 deg flexion = pi/2 for the knee identification).
class HoldTrajectory : public JointTrajectory {
 public:
  // q in rad, finite (throws InputError otherwise).
  explicit HoldTrajectory(double q);
  JointSetpoint At(double t) const override { return {q_, 0.0, 0.0}; }

 private:
  double q_;
};

// Leg trajectory from two independent joint trajectories, e.g. knee swinging with the hip held.
class JointwiseTrajectory : public LegTrajectory {
 public:
  // Both non-null (throws InputError otherwise).
  JointwiseTrajectory(std::shared_ptr<const JointTrajectory> hip,
                      std::shared_ptr<const JointTrajectory> knee);
  void Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const override;

 private:
  std::shared_ptr<const JointTrajectory> hip_, knee_;
};

// Smooth start for any leg trajectory: q(t) = q_in(0) + w(t) (q_in(t) - q_in(0)), w the quintic
// smoothstep 10s^3 - 15s^4 + 6s^5 (s = t/T) with w = w' = w'' = 0 at t = 0 and 1, 0, 0 at t = T.
// Starts at rest at the inner trajectory's t = 0 pose; identical to the inner one for t >= T.
// The blend adds at most 1.875 |q_in - q_in(0)|/T to the speed during the fade. t < 0 gives the
// start pose at rest.
class FadeInTrajectory : public LegTrajectory {
 public:
  // inner non-null, fade_s > 0 (throws InputError otherwise).
  FadeInTrajectory(std::shared_ptr<const LegTrajectory> inner, double fade_s);
  void Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const override;

 private:
  std::shared_ptr<const LegTrajectory> inner_;
  double fade_s_;
  JointSetpoint hip0_, knee0_;
};

// Options for the gait trajectory.
struct GaitSpec {
  double stride_period_s = 2.0;     // output stride period (2 km/h in rehabilitation, paper sec. 3.4)
  int harmonics = 10;               // Fourier harmonics fitted per joint
  double data_stride_period_s = 0;  // stride period of the recording; 0 = detect from the data
  double phase_origin_s = 0.386;    // recording time mapped to t = 0: right heel contact (frame 28)
  double hip_offset = 0, knee_offset = 0;  // rad, added after scaling
  double amplitude_scale = 1.0;     // scales the excursion about each joint's stride mean
};

// Physiological gait (Winter, Biomechanics and Motor Control of Human Movement, Table A.1) fitted
// with a periodic Fourier series by least squares and time-scaled to the chosen stride period.
// hip = angle of the thigh (hip -> knee marker) to the downward vertical, positive with the knee in
// front of the hip (walking towards +x); knee = shank angle (knee -> ankle) minus thigh angle, i.e.
// flexion negative. Phase 0 = right heel contact. Note Winter's knee reaches about +2 deg (slight
// hyperextension) in stance; use knee_offset if the exoskeleton stops at 0.
class GaitTrajectory : public LegTrajectory {
 public:
  // Reads Winter's table (whitespace-separated, two quoted header lines, columns FRAME TIME RIB x y
  // HIP x y KNEE x y FIBULA x y ANKLE x y ..., cm) and fits. Throws InputError naming file and line.
  static GaitTrajectory FromWinterFile(const std::string& path, const GaitSpec& spec = GaitSpec());
  // The shipped recording, data/WinterTableA1.txt of the data folder (core/data_dir.h).
  static std::string DefaultWinterPath();
  void Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const override;
  const FourierSeries& hip() const { return hip_; }
  const FourierSeries& knee() const { return knee_; }
  double data_stride_period_s() const { return data_period_s_; }  // detected or given, s
  double fit_rms_hip() const { return rms_hip_; }    // rad, least-squares residual on the recording
  double fit_rms_knee() const { return rms_knee_; }  // rad

  // Joint angles of one marker frame (cm or any length unit), as defined above. Public for tests.
  static void AnglesFromMarkers(double hip_x, double hip_y, double knee_x, double knee_y,
                                double ankle_x, double ankle_y, double* th1, double* th2);

 private:
  FourierSeries hip_, knee_;
  double data_period_s_ = 0, rms_hip_ = 0, rms_knee_ = 0;
};

// A recorded leg motion sampled uniformly (e.g. an OpenSim motion file's stride, read and resampled
// by the runner: the controller reads no file): sample i at t = i dt. Derivatives for the
// feed-forward as the project takes them from recorded angles (dsp/derivatives.h
// ZeroPhaseDerivatives: zero-phase 2nd-order Butterworth at cutoff_hz, central differences); the
// reference q is the filtered angle. Between samples q and qd are cubic Hermite interpolants of
// (q, qd) and (qd, qdd), qdd is linear, so q, qd are continuous.
// Beyond the samples (t >= (n - 1) dt):
//  - kLoop: the samples repeat with period n dt (the last sample is followed by the first: a file
//    holding one stride without repeating its first pose at the end); derivatives are taken on the
//    periodic extension (three copies, the middle one kept), so the seam has no filter transient.
//  - kHold: the last (filtered) pose, at rest (qd = qdd = 0).
// t < 0 gives the first pose at rest.
class TabulatedTrajectory : public LegTrajectory {
 public:
  enum class Extend { kLoop, kHold };
  // dt > 0 s; q_hip, q_knee of equal size >= 2, finite (rad); 0 < cutoff_hz < 1/(2 dt). Throws
  // InputError otherwise.
  TabulatedTrajectory(double dt, const std::vector<double>& q_hip, const std::vector<double>& q_knee,
                      Extend extend, double cutoff_hz);
  void Sample(double t, JointSetpoint* hip, JointSetpoint* knee) const override;
  // kLoop: the period n dt; kHold: the span (n - 1) dt covered by the samples. s.
  double Duration() const;
  size_t size() const { return q_[0].size(); }
  double dt() const { return dt_; }

 private:
  JointSetpoint At(int joint, size_t i, size_t j, double s) const;
  double dt_;
  Extend extend_;
  std::vector<double> q_[2], qd_[2], qdd_[2];  // [0] hip, [1] knee: filtered angle and derivatives
};

}  // namespace exotwin::controller
