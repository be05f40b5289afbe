#include "diagnosis/completeness.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "dsp/butterworth.h"
#include "dsp/statistics.h"

namespace exotwin {

namespace {

using Series = std::vector<double>;

// x standardized (mean 0, standard deviation 1); false (x untouched) when x is constant.
bool Standardize(Series* x) {
  const double n = static_cast<double>(x->size());
  if (x->empty()) return false;
  double mean = 0;
  for (double v : *x) mean += v;
  mean /= n;
  double ss = 0;
  for (double v : *x) ss += (v - mean) * (v - mean);
  const double sd = std::sqrt(ss / n);
  if (!(sd > 1e-12 * (std::abs(mean) + 1e-300))) return false;
  for (double& v : *x) v = (v - mean) / sd;
  return true;
}

// One correlation test's series per segment: a and b standardized, `ok` false where either is constant.
struct Pair {
  std::vector<Series> a, b;
  bool ok = true;
};

// z(k) = sum_s sum_i a_s(i) b_s(i + k) / sqrt(count) for k in [k_lo, k_hi]; max_k |z(k)|, the lags,
// and the correlation r = z / sqrt(count) at that lag.
double MaxAbsZ(const Pair& p, long k_lo, long k_hi, size_t* lags, double* r) {
  double best = 0;
  *lags = 0;
  *r = 0;
  for (long k = k_lo; k <= k_hi; ++k) {
    double sum = 0, count = 0;
    for (size_t s = 0; s < p.a.size(); ++s) {
      const long n = static_cast<long>(p.a[s].size());
      for (long i = std::max(0L, -k); i < n && i + k < n; ++i) sum += p.a[s][i] * p.b[s][i + k], count += 1;
    }
    if (count < 1) continue;
    ++*lags;
    const double z = std::abs(sum) / std::sqrt(count);
    if (z > best) best = z, *r = std::abs(sum) / count;
  }
  return best;
}

// The signals of the tests by name, read from a segment.
struct Signal {
  const char* name;
  std::function<Series(const ResidualSegment&)> of;
};

const std::vector<Signal>& LinearSignals() {
  static const std::vector<Signal> s = {
      {"q", [](const ResidualSegment& g) { return g.q; }},
      {"qd", [](const ResidualSegment& g) { return g.qd; }},
      {"qdd", [](const ResidualSegment& g) { return g.qdd; }},
      {"tau_R", [](const ResidualSegment& g) { return g.tau_R; }},
      {"q_other", [](const ResidualSegment& g) { return g.q_other; }},
      {"qd_other", [](const ResidualSegment& g) { return g.qd_other; }},
      {"t", [](const ResidualSegment& g) { return g.t; }},
      {"sgn_qd",
       [](const ResidualSegment& g) {
         Series x(g.qd.size());
         for (size_t i = 0; i < x.size(); ++i) x[i] = g.qd[i] > 0 ? 1.0 : g.qd[i] < 0 ? -1.0 : 0.0;
         return x;
       }},
      {"abs_tau_R",
       [](const ResidualSegment& g) {
         Series x(g.tau_R.size());
         for (size_t i = 0; i < x.size(); ++i) x[i] = std::abs(g.tau_R[i]);
         return x;
       }},
  };
  return s;
}

// The signals of the nonlinear tests: the first six linear ones; of e_eu, q, qd and tau_R.
constexpr size_t kNonlinearSignals = 6;
const char* const kProductSignals[] = {"q", "qd", "tau_R"};

Series Squared(Series x) {
  for (double& v : x) v *= v;
  return x;
}

}  // namespace

size_t DecimationStep(const std::vector<double>& acf, double tol) {
  size_t k = acf.size();
  while (k > 1 && std::abs(acf[k - 1]) <= tol) --k;
  return std::max<size_t>(k, 1);
}

size_t CompletenessStep(double fs, double cutoff_hz) {
  if (!(cutoff_hz > 0) || !(fs > 0)) return 1;
  // The impulse response of the zero-phase filter (forward-backward, as LowPassOnTimeBase), on a
  // support of 40 periods of the cutoff each side, and its autocorrelation.
  const size_t half = static_cast<size_t>(std::ceil(40 * fs / cutoff_hz));
  std::vector<double> x(2 * half + 1, 0.0);
  x[half] = 1;
  const std::vector<double> h = dsp::FiltFilt(dsp::DesignButterworth(2, dsp::BandType::kLowPass, fs, cutoff_hz), x);
  std::vector<double> acf(half);
  for (size_t k = 0; k < half; ++k) {
    double c = 0;
    for (size_t i = 0; i + k < h.size(); ++i) c += h[i] * h[i + k];
    acf[k] = c;
  }
  for (size_t k = 1; k < half; ++k) acf[k] /= acf[0];
  acf[0] = 1;
  return DecimationStep(acf, kCompletenessAcfTol);
}

JointCompleteness AssessCompleteness(const std::vector<ResidualSegment>& segments, size_t step,
                                     double material_floor, double alpha) {
  if (!(alpha > 0 && alpha < 1)) throw std::invalid_argument("AssessCompleteness: alpha outside (0, 1)");
  if (!(material_floor >= 0)) throw std::invalid_argument("AssessCompleteness: material floor below 0");
  JointCompleteness out;
  out.step = step;
  out.alpha = alpha;
  out.floor = material_floor;
  std::vector<const ResidualSegment*> segs;
  for (const ResidualSegment& s : segments)
    if (s.e.size() >= kMinSegmentRows) segs.push_back(&s), out.rows += s.e.size();
  if (segs.empty()) return out;
  out.assessed = true;
  const double rows = static_cast<double>(out.rows);

  // The residual, its square and the signals standardized per segment.
  std::vector<Series> e, e2;
  double ss = 0;
  for (const ResidualSegment* s : segs) {
    Series x = s->e;
    double mean = 0;
    for (double v : x) mean += v / static_cast<double>(x.size());
    for (double v : x) ss += (v - mean) * (v - mean);
    if (!Standardize(&x)) x.assign(x.size(), 0.0);  // a residual of zeros: no structure
    Series x2 = Squared(x);
    if (!Standardize(&x2)) x2.assign(x.size(), 0.0);
    e.push_back(std::move(x)), e2.push_back(std::move(x2));
  }
  out.rms = std::sqrt(ss / rows);
  // A signal's series per segment, transformed and standardized; ok false if constant on any segment.
  auto Of = [&](const Signal& sig, const std::function<Series(Series, size_t)>& transform, bool* ok) {
    std::vector<Series> v;
    for (size_t s = 0; s < segs.size(); ++s) {
      Series x = transform(sig.of(*segs[s]), s);
      if (x.size() != e[s].size()) throw std::invalid_argument(std::string("AssessCompleteness: signal ") + sig.name + " of another length than the residual");
      *ok = Standardize(&x) && *ok;
      v.push_back(std::move(x));
    }
    return v;
  };
  const auto same = [](Series x, size_t) { return x; };
  const auto square = [](Series x, size_t) { return Squared(std::move(x)); };
  const long L = static_cast<long>(kCompletenessLags);

  struct Pending {
    std::string name;
    Pair pair;
    long k_lo, k_hi;
  };
  std::vector<Pending> pend;
  const std::vector<Signal>& sigs = LinearSignals();
  for (const Signal& sig : sigs) {
    Pending p{std::string("xcorr_") + sig.name, {}, -L, L};
    p.pair.a = Of(sig, same, &p.pair.ok), p.pair.b = e;
    pend.push_back(std::move(p));
  }
  pend.push_back({"e_e2", {e, e2, true}, 1, L});
  for (size_t k = 0; k < kNonlinearSignals; ++k) {
    Pending p{std::string("u2_e_") + sigs[k].name, {}, -L, L};
    p.pair.a = Of(sigs[k], square, &p.pair.ok), p.pair.b = e;
    Pending p2{std::string("u2_e2_") + sigs[k].name, {p.pair.a, e2, p.pair.ok}, -L, L};
    pend.push_back(std::move(p)), pend.push_back(std::move(p2));
  }
  for (const char* name : kProductSignals) {
    const Signal& sig = *std::find_if(sigs.begin(), sigs.end(), [&](const Signal& s) { return std::string(s.name) == name; });
    // phi_(e (e u))(k): a = e at i, b = (e u)' at i - 1 - k, i.e. z over lags -(1 + k).
    Pending p{std::string("e_eu_") + name, {}, -(L + 1), -1};
    bool u_ok = true;
    const std::vector<Series> u = Of(sig, same, &u_ok);
    p.pair.a = e;
    for (size_t s = 0; s < segs.size(); ++s) {
      Series x(e[s].size());
      for (size_t i = 0; i < x.size(); ++i) x[i] = e[s][i] * u[s][i];
      p.pair.ok = Standardize(&x) && p.pair.ok;
      p.pair.b.push_back(std::move(x));
    }
    p.pair.ok = p.pair.ok && u_ok;
    pend.push_back(std::move(p));
  }

  size_t tests = 1;  // whiteness
  for (const Pending& p : pend) tests += p.pair.ok;
  const double level = alpha / static_cast<double>(tests);

  {  // whiteness: Ljung-Box summed over the segments
    double q = 0, dof = 0, r2 = 0;
    for (const Series& x : e) {
      const size_t m = std::min(kWhitenessLags, x.size() / 4);
      q += LjungBoxQ(x.data(), x.size(), m);
      dof += static_cast<double>(m);
      for (double r : SampleAutocorrelation(x.data(), x.size(), m)) r2 += r * r * static_cast<double>(x.size()) / rows;
    }
    CompletenessTest t;
    t.name = "whiteness";
    t.statistic = q;
    t.threshold = ChiSquareUpperQuantile(level, dof);
    t.p_value = ChiSquareSurvival(q, dof);
    t.size = std::sqrt(r2) * out.rms;
    t.pass = t.p_value >= level || t.size < material_floor;
    out.tests.push_back(t);
  }
  for (const Pending& p : pend) {
    if (!p.pair.ok) continue;
    size_t lags = 0;
    double r = 0;
    CompletenessTest t;
    t.name = p.name;
    t.statistic = MaxAbsZ(p.pair, p.k_lo, p.k_hi, &lags, &r);
    const double K = static_cast<double>(std::max<size_t>(lags, 1));
    t.threshold = NormalQuantile(1 - level / (2 * K));
    t.p_value = std::min(1.0, 2 * K * NormalSurvival(t.statistic));
    t.size = r * out.rms;
    t.pass = t.p_value >= level || t.size < material_floor;
    out.tests.push_back(t);
  }
  for (const CompletenessTest& t : out.tests) out.complete = out.complete && t.pass;
  return out;
}

}  // namespace exotwin
