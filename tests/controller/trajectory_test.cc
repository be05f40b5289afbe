// Tests of controller/trajectory.h: analytic derivatives against finite differences, designed
// exciting trajectories within their limits for many seeds, the hold / composition / fade-in
// wrappers, and the Winter gait against angles computed directly from marker values.
#include "controller/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <random>
#include <memory>

#include "core/error.h"
#include "core/units.h"
#include "tests/temp_dir.h"

namespace exotwin::controller {
namespace {


// Central differences of q and qd against the analytic qd and qdd.
void ExpectDerivativesMatch(const std::function<JointSetpoint(double)>& f, double t0, double t1,
                            double tol_rel) {
  const double h = 1e-5;
  for (int i = 0; i <= 200; ++i) {
    const double t = t0 + (t1 - t0) * i / 200.0;
    const JointSetpoint p = f(t), m = f(t - h), pl = f(t + h);
    const double qd_fd = (pl.q - m.q) / (2 * h);
    const double qdd_fd = (pl.qd - m.qd) / (2 * h);
    EXPECT_NEAR(p.qd, qd_fd, tol_rel * (1 + std::abs(p.qd))) << "t=" << t;
    EXPECT_NEAR(p.qdd, qdd_fd, tol_rel * (1 + std::abs(p.qdd))) << "t=" << t;
  }
}

TEST(FourierSeries, AnalyticDerivativesMatchFiniteDifferences) {
  FourierSeries s(0.3, 0.1, {{3, 0.1, -0.05}, {7, 0.02, 0.03}, {15, -0.01, 0.004}});
  ExpectDerivativesMatch([&](double t) { return s.Eval(t); }, 0.0, 10.0, 1e-6);
  // Large t: phase reduction keeps the accuracy.
  ExpectDerivativesMatch([&](double t) { return s.Eval(t); }, 1e5, 1e5 + 1.0, 1e-5);
}

TEST(FourierSeries, RejectsBadInput) {
  EXPECT_THROW(FourierSeries(0, 0.0, {}), InputError);
  EXPECT_THROW(FourierSeries(0, 0.1, {{0, 1, 1}}), InputError);
  EXPECT_THROW(FourierSeries(NAN, 0.1, {}), InputError);
}

// Independent limit check: a grid finer than Design's and shifted by a non-commensurate offset.
void ExpectWithinLimits(const HarmonicTrajectory& tr, const ExcitationSpec& spec) {
  const int n = 60000;
  const double period = tr.Period();
  double qmin = 1e9, qmax = -1e9, qd = 0, qdd = 0;
  for (int i = 0; i < n; ++i) {
    const JointSetpoint p = tr.At((i + 0.3183) * period / n);
    qmin = std::min(qmin, p.q);
    qmax = std::max(qmax, p.q);
    qd = std::max(qd, std::abs(p.qd));
    qdd = std::max(qdd, std::abs(p.qdd));
  }
  EXPECT_GE(qmin, spec.q_min);
  EXPECT_LE(qmax, spec.q_max);
  EXPECT_LE(qd, spec.qd_max);
  EXPECT_LE(qdd, spec.qdd_max);
  // One limit is binding (fill = 0.98 of it, minus grid effects).
  const double use = std::max({(qmax - qmin) / (spec.q_max - spec.q_min), qd / spec.qd_max,
                               qdd / spec.qdd_max});
  EXPECT_GT(use, 0.95);
}

TEST(HarmonicTrajectory, DesignRespectsPaperLimitsForManySeeds) {
  for (const ExcitationSpec& spec : {ExcitationSpec::PaperHip(), ExcitationSpec::PaperKnee()}) {
    for (uint64_t seed = 1; seed <= 60; ++seed) {
      const HarmonicTrajectory tr = HarmonicTrajectory::Design(spec, seed);
      SCOPED_TRACE(seed);
      ExpectWithinLimits(tr, spec);
      // All harmonics within the gait band 0.3-1.5 Hz.
      for (const auto& term : tr.series().terms()) {
        EXPECT_GE(term.k * tr.series().f0(), 0.3 - 1e-12);
        EXPECT_LE(term.k * tr.series().f0(), 1.5 + 1e-12);
      }
      // Starts (and restarts every period) at rest.
      const JointSetpoint s0 = tr.At(0.0), s1 = tr.At(tr.Period());
      EXPECT_NEAR(s0.qd, 0.0, 1e-12);
      EXPECT_NEAR(s0.qdd, 0.0, 1e-11);
      EXPECT_NEAR(s1.q, s0.q, 1e-12);
      EXPECT_DOUBLE_EQ(tr.StartPose(), s0.q);
    }
  }
}

TEST(HarmonicTrajectory, DerivativesAndOtherBasis) {
  ExcitationSpec spec = ExcitationSpec::PaperKnee();
  spec.f0_hz = 0.3;  // f0 = 0.3 Hz, k = 1..5: the other basis of the documented choice
  spec.k_min = 1;
  spec.k_max = 5;
  const HarmonicTrajectory tr = HarmonicTrajectory::Design(spec, 7);
  ExpectWithinLimits(tr, spec);
  ExpectDerivativesMatch([&](double t) { return tr.At(t); }, 0.0, tr.Period(), 1e-6);
}

TEST(HarmonicTrajectory, SeededAndDeterministic) {
  const auto spec = ExcitationSpec::PaperHip();
  const HarmonicTrajectory a = HarmonicTrajectory::Design(spec, 123);
  const HarmonicTrajectory b = HarmonicTrajectory::Design(spec, 123);
  const HarmonicTrajectory c = HarmonicTrajectory::Design(spec, 124);
  ASSERT_EQ(a.series().terms().size(), 13u);  // k = 3..15 at f0 = 0.1 Hz
  bool differs = false;
  for (size_t i = 0; i < a.series().terms().size(); ++i) {
    EXPECT_EQ(a.series().terms()[i].a, b.series().terms()[i].a);  // bit-identical
    EXPECT_EQ(a.series().terms()[i].b, b.series().terms()[i].b);
    differs |= a.series().terms()[i].a != c.series().terms()[i].a;
  }
  EXPECT_TRUE(differs);
  // std::mt19937_64 itself is fully specified: 10000th output of the default seed (C++ standard).
  std::mt19937_64 rng;
  rng.discard(9999);
  EXPECT_EQ(rng(), 9981545732273789042ull);
}

TEST(HarmonicTrajectory, DesignRejectsBadSpecs) {
  ExcitationSpec s = ExcitationSpec::PaperHip();
  s.q_max = s.q_min;
  EXPECT_THROW(HarmonicTrajectory::Design(s, 1), InputError);
  s = ExcitationSpec::PaperHip();
  s.qd_max = 0;
  EXPECT_THROW(HarmonicTrajectory::Design(s, 1), InputError);
  s = ExcitationSpec::PaperHip();
  s.k_max = 20;  // 2 Hz, outside the gait band
  EXPECT_THROW(HarmonicTrajectory::Design(s, 1), InputError);
  s = ExcitationSpec::PaperHip();
  s.fill = 1.5;
  EXPECT_THROW(HarmonicTrajectory::Design(s, 1), InputError);
}

TEST(Composition, KneeSwingsWithHipHeldAt90Degrees) {
  auto knee = std::make_shared<HarmonicTrajectory>(
      HarmonicTrajectory::Design(ExcitationSpec::PaperKnee(), 3));
  auto hip = std::make_shared<HoldTrajectory>(90 * kRadPerDeg);
  JointwiseTrajectory leg(hip, knee);
  for (double t : {0.0, 1.3, 7.7}) {
    JointSetpoint h, k;
    leg.Sample(t, &h, &k);
    EXPECT_DOUBLE_EQ(h.q, M_PI / 2);
    EXPECT_EQ(h.qd, 0.0);
    EXPECT_EQ(h.qdd, 0.0);
    EXPECT_DOUBLE_EQ(k.q, knee->At(t).q);
  }
  EXPECT_THROW(JointwiseTrajectory(hip, nullptr), InputError);
  EXPECT_THROW(HoldTrajectory(NAN), InputError);
}

TEST(FadeIn, StartsAtRestAndJoinsTheInnerTrajectory) {
  auto gait = std::make_shared<GaitTrajectory>(
      GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath()));
  const double T = 2.0;
  FadeInTrajectory f(gait, T);
  JointSetpoint h, k, gh, gk;
  gait->Sample(0.0, &gh, &gk);
  for (double t : {-1.0, 0.0}) {
    f.Sample(t, &h, &k);
    EXPECT_DOUBLE_EQ(h.q, gh.q);
    EXPECT_DOUBLE_EQ(k.q, gk.q);
    EXPECT_EQ(h.qd, 0.0);
    EXPECT_EQ(k.qdd, 0.0);
  }
  for (double t : {T, T + 0.37, 5.0}) {
    f.Sample(t, &h, &k);
    gait->Sample(t, &gh, &gk);
    EXPECT_DOUBLE_EQ(h.q, gh.q);
    EXPECT_DOUBLE_EQ(k.qd, gk.qd);
  }
  // Continuity of q, qd, qdd at the end of the fade and analytic derivatives during it.
  f.Sample(T - 1e-9, &h, &k);
  gait->Sample(T, &gh, &gk);
  EXPECT_NEAR(h.q, gh.q, 1e-8);
  EXPECT_NEAR(h.qd, gh.qd, 1e-7);
  EXPECT_NEAR(k.qdd, gk.qdd, 1e-6);
  for (int joint = 0; joint < 2; ++joint)
    ExpectDerivativesMatch(
        [&](double t) {
          JointSetpoint a, b;
          f.Sample(t, &a, &b);
          return joint == 0 ? a : b;
        },
        0.01, T - 0.01, 1e-5);
  EXPECT_THROW(FadeInTrajectory(gait, 0.0), InputError);
}

// ---------------------------------------------------------------- gait

TEST(GaitTrajectory, WinterStrideDetectedAndFitted) {
  const GaitTrajectory g = GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath());
  // Right heel contacts at frames 28 and 97 of Winter's table: 69 frames of 1.501/105 s.
  EXPECT_NEAR(g.data_stride_period_s(), 69 * 1.501 / 105, 0.015);
  std::printf("Winter stride %.4f s, fit rms hip %.2f deg, knee %.2f deg\n", g.data_stride_period_s(),
              g.fit_rms_hip() / kRadPerDeg, g.fit_rms_knee() / kRadPerDeg);
  EXPECT_LT(g.fit_rms_hip(), 1.5 * kRadPerDeg);
  EXPECT_LT(g.fit_rms_knee(), 1.5 * kRadPerDeg);
}

TEST(GaitTrajectory, RangesAreWintersNormalGait) {
  const GaitTrajectory g = GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath());
  double hmin = 1e9, hmax = -1e9, kmin = 1e9, kmax = -1e9, hqd = 0, kqd = 0;
  for (int i = 0; i < 4000; ++i) {
    JointSetpoint h, k;
    g.Sample(i * 2.0 / 4000, &h, &k);
    hmin = std::min(hmin, h.q);
    hmax = std::max(hmax, h.q);
    kmin = std::min(kmin, k.q);
    kmax = std::max(kmax, k.q);
    hqd = std::max(hqd, std::abs(h.qd));
    kqd = std::max(kqd, std::abs(k.qd));
  }
  std::printf("hip %.1f..%.1f deg, knee %.1f..%.1f deg, max speed hip %.0f knee %.0f deg/s\n",
              hmin / kRadPerDeg, hmax / kRadPerDeg, kmin / kRadPerDeg, kmax / kRadPerDeg, hqd / kRadPerDeg, kqd / kRadPerDeg);
  // Thigh angle roughly -10..+25 deg (here -17..26), knee flexion roughly 0..65 deg.
  EXPECT_GT(hmin, -22 * kRadPerDeg);
  EXPECT_LT(hmin, -8 * kRadPerDeg);
  EXPECT_GT(hmax, 20 * kRadPerDeg);
  EXPECT_LT(hmax, 30 * kRadPerDeg);
  EXPECT_GT(kmin, -70 * kRadPerDeg);
  EXPECT_LT(kmin, -55 * kRadPerDeg);
  EXPECT_GT(kmax, -5 * kRadPerDeg);
  EXPECT_LT(kmax, 5 * kRadPerDeg);
  // Winter's ~1 s natural stride slowed to 2 s halves the speeds: hip ~120, knee ~200 deg/s.
  EXPECT_LT(hqd, 150 * kRadPerDeg);
  EXPECT_LT(kqd, 250 * kRadPerDeg);
}

TEST(GaitTrajectory, MatchesDirectMarkerComputationAtFrames) {
  const GaitTrajectory g = GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath());
  // Marker rows copied from data/WinterTableA1.txt: time, hip x y, knee x y, ankle x y (cm).
  struct Row { double t, hx, hy, kx, ky, ax, ay; };
  const Row rows[] = {
      {0.129, 62.78, 82.01, 73.22, 51.73, 48.15, 21.06},     // frame 10, swing
      {0.386, 101.53, 79.34, 112.34, 50.46, 124.94, 10.63},  // frame 28, heel contact
      {0.701, 142.02, 82.65, 140.11, 51.09, 130.56, 9.99},   // frame 50, late stance
      {1.072, 196.42, 80.10, 202.66, 49.31, 172.50, 23.61},  // frame 76, swing
  };
  for (const Row& r : rows) {
    // Direct definition: thigh from the downward vertical, knee = shank - thigh.
    const double thigh = std::atan2(r.kx - r.hx, r.hy - r.ky);
    const double knee = std::atan2(r.ax - r.kx, r.ky - r.ay) - thigh;
    const double t_out = (r.t - 0.386) * 2.0 / g.data_stride_period_s();
    JointSetpoint h, k;
    g.Sample(t_out, &h, &k);
    SCOPED_TRACE(r.t);
    EXPECT_NEAR(h.q, thigh, 2.5 * kRadPerDeg);
    EXPECT_NEAR(k.q, knee, 2.5 * kRadPerDeg);
  }
  // Signs at known events: heel contact hip flexed ~20 deg, knee nearly straight; swing knee flexed.
  JointSetpoint h, k;
  g.Sample(0.0, &h, &k);
  EXPECT_NEAR(h.q, 20 * kRadPerDeg, 3 * kRadPerDeg);
  EXPECT_NEAR(k.q, 0.0, 5 * kRadPerDeg);
}

TEST(GaitTrajectory, PeriodicDerivativesAndOptions) {
  GaitSpec spec;
  spec.stride_period_s = 2.5;
  spec.harmonics = 8;
  spec.amplitude_scale = 0.5;
  spec.knee_offset = -5 * kRadPerDeg;
  const GaitTrajectory g = GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath(), spec);
  GaitSpec ref_spec;
  ref_spec.harmonics = 8;
  const GaitTrajectory ref = GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath(), ref_spec);
  for (double t : {0.0, 0.4, 1.9}) {
    JointSetpoint h0, k0, h1, k1, hr, kr;
    g.Sample(t, &h0, &k0);
    g.Sample(t + 2.5, &h1, &k1);
    EXPECT_NEAR(h0.q, h1.q, 1e-12);
    EXPECT_NEAR(k0.qd, k1.qd, 1e-11);
    // Half the excursion about the stride mean, time-scaled, offset.
    ref.Sample(t * 2.0 / 2.5, &hr, &kr);
    EXPECT_NEAR(h0.q - g.hip().c0(), 0.5 * (hr.q - ref.hip().c0()), 1e-12);
    EXPECT_NEAR(g.knee().c0(), ref.knee().c0() - 5 * kRadPerDeg, 1e-12);
  }
  for (int joint = 0; joint < 2; ++joint)
    ExpectDerivativesMatch(
        [&](double t) {
          JointSetpoint a, b;
          g.Sample(t, &a, &b);
          return joint == 0 ? a : b;
        },
        0.0, 2.5, 1e-6);
}

TEST(GaitTrajectory, BadFilesAreInputErrors) {
  EXPECT_THROW(GaitTrajectory::FromWinterFile("/nonexistent/winter.txt"), InputError);
  const testing::ScopedTempDir tmp("trajectory");
  const std::string path = tmp.File("winter_bad.txt");
  {
    std::ofstream out(path);
    out << "'FRAME' 'TIME'\n1 0 1 2 3 4 5 6 7\n";
  }
  try {
    GaitTrajectory::FromWinterFile(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2:"), std::string::npos) << e.what();
  }
  GaitSpec spec;
  spec.stride_period_s = -1;
  EXPECT_THROW(GaitTrajectory::FromWinterFile(GaitTrajectory::DefaultWinterPath(), spec), InputError);
}

}  // namespace
}  // namespace exotwin::controller

// ---------------------------------------------------------------- TabulatedTrajectory

namespace exotwin::controller {
namespace {

// One period of q(t) = c + a sin(2 pi t / T) + b cos(4 pi t / T), sampled every dt over [0, T).
struct Periodic {
  double T = 1.2, dt = 0.01;
  std::vector<double> hip, knee;
  Periodic() {
    for (int i = 0; i < 120; ++i) {
      hip.push_back(Q(0.1, 0.3, 0.05, i * dt));
      knee.push_back(Q(-0.6, 0.4, -0.1, i * dt));
    }
  }
  double w() const { return 2 * M_PI / T; }
  // Bound on |d^n q_knee / dt^n|: 0.4 w^n + 0.1 (2 w)^n.
  double KneeBound(int n) const { return 0.4 * std::pow(w(), n) + 0.1 * std::pow(2 * w(), n); }
  double Q(double c, double a, double b, double t) const { return c + a * std::sin(w() * t) + b * std::cos(2 * w() * t); }
  JointSetpoint Exact(double c, double a, double b, double t) const {
    return {Q(c, a, b, t), a * w() * std::cos(w() * t) - 2 * b * w() * std::sin(2 * w() * t),
            -a * w() * w() * std::sin(w() * t) - 4 * b * w() * w() * std::cos(2 * w() * t)};
  }
};

TEST(TabulatedTrajectory, LoopedStrideFollowsTheSignalAndItsDerivativesAcrossTheSeam) {
  const Periodic p;
  // 20 Hz cutoff on a 0.83 / 1.67 Hz signal: the zero-phase filter's gain there is 1 - 1e-7.
  const TabulatedTrajectory tr(p.dt, p.hip, p.knee, TabulatedTrajectory::Extend::kLoop, 20.0);
  EXPECT_DOUBLE_EQ(tr.Duration(), 1.2);
  double worst[3] = {0, 0, 0};
  for (int i = 1; i < 4000; ++i) {  // three periods and more, off the sample instants
    const double t = i * 0.000917;
    JointSetpoint h, k;
    tr.Sample(t, &h, &k);
    const JointSetpoint eh = p.Exact(0.1, 0.3, 0.05, t), ek = p.Exact(-0.6, 0.4, -0.1, t);
    worst[0] = std::max({worst[0], std::abs(h.q - eh.q), std::abs(k.q - ek.q)});
    worst[1] = std::max({worst[1], std::abs(h.qd - eh.qd), std::abs(k.qd - ek.qd)});
    worst[2] = std::max({worst[2], std::abs(h.qdd - eh.qdd), std::abs(k.qdd - ek.qdd)});
  }
  // Central differences at dt = 10 ms put qd off by max|q^(3)| dt^2 / 6 at the samples and qdd (the
  // gradient of the gradient, a step of 2 dt) by max|q^(4)| dt^2 / 3; the linear qdd between samples
  // adds max|q^(4)| dt^2 / 8, and the zero-phase filter scales a harmonic at f by 1 / (1 + (f / 20 Hz)^4).
  // The knee's bounds: 2.9e-3 rad/s, 0.070 rad/s^2 (of 55).
  const double filter = std::pow(2.0 / p.T / 20.0, 4);
  EXPECT_LT(worst[0], 2e-5);
  EXPECT_LT(worst[1], p.KneeBound(3) * p.dt * p.dt / 6 + p.KneeBound(1) * filter);
  EXPECT_LT(worst[2], p.KneeBound(4) * p.dt * p.dt * (1.0 / 3 + 1.0 / 8) + p.KneeBound(2) * filter);
}

TEST(TabulatedTrajectory, QAndQdAreContinuousAndConsistent) {
  const Periodic p;
  const TabulatedTrajectory tr(p.dt, p.hip, p.knee, TabulatedTrajectory::Extend::kLoop, 20.0);
  // Across sample instants (including the seam at 1.2 s) q and qd are continuous.
  for (double ts : {0.05, 0.5, 1.19, 1.2, 2.4}) {
    JointSetpoint a, b, k;
    tr.Sample(ts - 1e-9, &a, &k);
    tr.Sample(ts + 1e-9, &b, &k);
    EXPECT_NEAR(a.q, b.q, 1e-8) << ts;
    EXPECT_NEAR(a.qd, b.qd, 1e-6) << ts;
  }
  // qd against the slope of q, qdd against the slope of qd: they differ by the derivative estimates'
  // errors e at the samples (bounds above): mid-interval, the slope of the cubic through (q, qd) is
  // 3/2 (q1 - q0) / dt - (qd0 + qd1) / 4, off by -e/2 where the interpolated qd is off by e.
  const double h = 1e-5;
  for (double t = 0.013; t < 2.5; t += 0.0123) {
    JointSetpoint m, c, pl, k;
    tr.Sample(t - h, &k, &m);
    tr.Sample(t, &k, &c);
    tr.Sample(t + h, &k, &pl);
    EXPECT_NEAR(c.qd, (pl.q - m.q) / (2 * h), 1.5 * p.KneeBound(3) * p.dt * p.dt / 6) << t;
    EXPECT_NEAR(c.qdd, (pl.qd - m.qd) / (2 * h), p.KneeBound(4) * p.dt * p.dt * (1.0 / 3 + 1.0 / 8)) << t;
  }
}

TEST(TabulatedTrajectory, HoldKeepsTheLastPoseAtRestAndStartsAtRest) {
  const Periodic p;
  const TabulatedTrajectory tr(p.dt, p.hip, p.knee, TabulatedTrajectory::Extend::kHold, 20.0);
  EXPECT_NEAR(tr.Duration(), 1.19, 1e-12);
  JointSetpoint h, k, h_end, k_end;
  tr.Sample(1.19 - 1e-12, &h_end, &k_end);
  tr.Sample(5.0, &h, &k);
  EXPECT_NEAR(h.q, h_end.q, 1e-9);
  EXPECT_NEAR(k.q, p.knee.back(), 2e-3);  // filtered, one-sided at the end
  EXPECT_EQ(h.qd, 0.0);
  EXPECT_EQ(k.qdd, 0.0);
  tr.Sample(-1.0, &h, &k);
  EXPECT_EQ(h.qd, 0.0);
  EXPECT_NEAR(h.q, p.hip[0], 2e-3);
}

TEST(TabulatedTrajectory, RejectsBadSamples) {
  const std::vector<double> two = {0, 1}, one = {0};
  using E = TabulatedTrajectory::Extend;
  EXPECT_THROW(TabulatedTrajectory(0.0, two, two, E::kLoop, 1.0), InputError);
  EXPECT_THROW(TabulatedTrajectory(0.01, one, one, E::kLoop, 1.0), InputError);
  EXPECT_THROW(TabulatedTrajectory(0.01, two, one, E::kLoop, 1.0), InputError);
  EXPECT_THROW(TabulatedTrajectory(0.01, {0, NAN}, two, E::kHold, 1.0), InputError);
  EXPECT_THROW(TabulatedTrajectory(0.01, two, two, E::kHold, 50.0), InputError);  // at Nyquist
  EXPECT_NO_THROW(TabulatedTrajectory(0.01, two, two, E::kHold, 49.0));
}

}  // namespace
}  // namespace exotwin::controller
