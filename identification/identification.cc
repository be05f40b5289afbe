#include "identification/identification.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/materiality.h"
#include "core/units.h"
#include "model/effect_families.h"
#include "model/passive_torque.h"
#include "model/regressors.h"
#include "formats/number_text.h"

namespace exotwin {

namespace {

std::string RangeText(const JointRanges& r, int j) {
  return FormatNumber("%.1f", r.min[j] * kDegPerRad) + ".." + FormatNumber("%.1f", r.max[j] * kDegPerRad) + " deg (range " +
         FormatNumber("%.1f", (r.max[j] - r.min[j]) * kDegPerRad) + ", mean " + FormatNumber("%.1f", r.mean[j] * kDegPerRad) + ")";
}

}  // namespace

const char* ConfigurationName(IdConfiguration c) {
  return c == IdConfiguration::kKneeSwing ? "knee swing (hip held)" : "hip swing (knee held)";
}

JointRanges ComputeJointRanges(const MeasuredData& data) {
  JointRanges r{};
  const std::vector<double>* q[2] = {&data.q_hip(), &data.q_knee()};
  for (int j = 0; j < 2; ++j) {
    const auto mm = std::minmax_element(q[j]->begin(), q[j]->end());
    r.min[j] = *mm.first;
    r.max[j] = *mm.second;
    double s = 0;
    for (double v : *q[j]) s += v;
    r.mean[j] = s / static_cast<double>(q[j]->size());
  }
  return r;
}

IdConfiguration ClassifyConfiguration(const MeasuredData& data, const IdentificationOptions& opt) {
  const JointRanges r = ComputeJointRanges(data);
  const double span[2] = {r.max[0] - r.min[0], r.max[1] - r.min[1]};
  if (span[1] >= opt.moving_min_range && span[0] <= opt.held_max_range)
    return IdConfiguration::kKneeSwing;
  if (span[0] >= opt.moving_min_range && span[1] <= opt.held_max_range)
    return IdConfiguration::kHipSwing;
  throw InputError(data.source + ": fits neither identification configuration: hip " +
                   RangeText(r, 0) + ", knee " + RangeText(r, 1) +
                   "; expected one joint moving over at least " + FormatNumber("%.1f", opt.moving_min_range * kDegPerRad) +
                   " deg while the other is held within " + FormatNumber("%.1f", opt.held_max_range * kDegPerRad) +
                   " deg (knee swing with the hip at 90 deg, or hip swing with the knee at -90 deg)");
}

void AppendSamples(const MeasuredData& data, bool select_passive, const IdentificationOptions& opt,
                   IdentificationSamples* into, const LegParams* exo) {
  const Kinematics kin = DeriveKinematics(data, opt.cutoff_hz);
  // The cuff torque tau_C and its rates by the angles' own chain: the human's knee angle q - c tau_C
  // then has the rates qd - c tau_C', qdd - c tau_C'' exactly (the chain is linear), for any c.
  std::vector<double> tau_c;
  AngleRates tau_c_rates;
  if (exo) {
    const Vector6 exo_v = ToVector(exo->exo);
    tau_c.resize(data.size());
    for (size_t i = 0; i < data.size(); ++i) {
      const Matrix26 Y = FullRegressor(exo->L1, exo->g, {kin.q[0][i], kin.q[1][i]},
                                       {kin.qd[0][i], kin.qd[1][i]}, {kin.qdd[0][i], kin.qdd[1][i]});
      tau_c[i] = -data.tau_knee()[i] - Y.row(1).dot(exo_v);  // u_knee = tau_R = -tau_S, HJ15 eq. 8
    }
    tau_c_rates = DeriveAngleRates(ExamineSampling(data.t(), data.source), data.t(), tau_c, opt.cutoff_hz,
                                   data.source);
  }
  std::vector<char> keep(data.size(), 1);
  if (select_passive) keep = SelectPassiveSamples(data, opt.selection).passive;
  const double t0 = data.t().front() + opt.trim_s, t1 = data.t().back() - opt.trim_s;
  const size_t before = into->size();
  for (int j = 0; j < 2; ++j)
    for (auto* v : {&into->q[j], &into->qd[j], &into->qdd[j], &into->u[j]}) v->reserve(before + data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    if (!keep[i] || data.t()[i] < t0 || data.t()[i] > t1) continue;
    for (int j = 0; j < 2; ++j) {
      into->q[j].push_back(kin.q[j][i]);
      into->qd[j].push_back(kin.qd[j][i]);
      into->qdd[j].push_back(kin.qdd[j][i]);
    }
    into->u[0].push_back(-data.tau_hip()[i]);  // tau_R = -tau_S, HJ15 eq. 8
    into->u[1].push_back(-data.tau_knee()[i]);
    if (exo) {
      into->tau_c.push_back(tau_c[i]);
      into->tau_c_d.push_back(tau_c_rates.qd[i]);
      into->tau_c_dd.push_back(tau_c_rates.qdd[i]);
    }
  }
  if (into->size() == before)
    throw InputError(data.source + ": no usable sample after trimming " + FormatNumber("%g", opt.trim_s) +
                     " s at both ends" + (select_passive ? " and the EMG selection of eq. (13)" : "") +
                     ", expected a longer recording of a relaxed subject");
  into->total += data.size();
  into->sources.push_back(data.source);
}

namespace {

// GeneralStepRow on a precomputed full regressor Y(q, qd, qdd).
StepRow RowFromRegressor(int step, const Matrix26& Y, const Vector6& known, PassiveModel passive,
                         const Eigen::Vector2d& q, double u) {
  const bool knee_row = step == 1 || step == 3;
  const int row = knee_row ? 1 : 0;
  const int c0 = knee_row ? 1 : 0;  // unknown columns c0, c0 + 2, c0 + 4
  StepRow r;
  r.u_star = u - Y.row(row).dot(known);  // known parameters to the left side
  if (step >= 3 && passive != PassiveModel::kNone) r.u_star -= PassiveElasticTorque(passive, q)[row];
  r.w << Y(row, c0), Y(row, c0 + 2), Y(row, c0 + 4);
  return r;
}

}  // namespace

StepRow GeneralStepRow(int step, double L1, double g, const Vector6& known, PassiveModel passive,
                       const Eigen::Vector2d& q, const Eigen::Vector2d& qd, const Eigen::Vector2d& qdd,
                       double u) {
  return RowFromRegressor(step, FullRegressor(L1, g, q, qd, qdd), known, passive, q, u);
}

namespace {

// SolveStep with M unknown columns: the paper's three, then (subject_passive) P^'s row (M >= 4) and the
// velocity (M = 5).
template <int M>
StepEstimate SolveColumns(int step, const IdentificationSamples& s, double L1, double g, const Vector6& known,
                          PassiveModel passive, const Eigen::Matrix3d* known_cov, const HumanSideRows* extra) {
  using MatM = Eigen::Matrix<double, M, M>;
  using VecM = Eigen::Matrix<double, M, 1>;
  const bool knee_row = step == 1 || step == 3;
  const int row = knee_row ? 1 : 0;
  const int held = knee_row ? 0 : 1;
  const bool human = step >= 3;
  const size_t n = s.size();
  StepEstimate e;
  e.step = step;
  e.segment = std::string(human ? "H" : "R") + (knee_row ? "2" : "1");
  e.samples_used = n;
  e.samples_total = s.total;
  e.sources = s.sources;
  if (n < static_cast<size_t>(M))
    throw InputError("step " + std::to_string(step) + ": fewer than " + std::to_string(M) + " samples");
  const double c = human && extra ? extra->knee_compliance : 0.0;
  if (c > 0 && s.tau_c.size() != n)
    throw std::logic_error("SolveStep: a compliant cuff needs samples prepared with the exoskeleton");
  // With the subject's factor on P^ a column, P^ is not subtracted from the row.
  const PassiveModel subtracted = M > 3 ? PassiveModel::kNone : passive;

  // Rows (u*, w) are kept for an exact residual pass (the shortcut u'u - 2 phi'W'u + phi'W'W phi
  // cancels down to ~1e-6 N m RMS). W'A (A = the known distal columns) for the propagated covariance.
  Eigen::Matrix<double, Eigen::Dynamic, M + 1> rows(n, M + 1);  // [w' u*]
  MatM WtW = MatM::Zero();
  Eigen::Matrix<double, M, 3> WtA = Eigen::Matrix<double, M, 3>::Zero();
  VecM Wtu = VecM::Zero();
  double held_sum = 0;
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector2d q(s.q[0][i], s.q[1][i]), qd(s.qd[0][i], s.qd[1][i]), qdd(s.qdd[0][i], s.qdd[1][i]);
    held_sum += q[held];
    Matrix26 Y = FullRegressor(L1, g, q, qd, qdd);
    double u = s.u[row][i];
    Vector6 known_here = known;
    if (c > 0) {
      // The exoskeleton's row at the measured state, the human's at q - c tau_C (HumanSideRows).
      u -= Y.row(row).dot(extra->exo);
      known_here -= extra->exo;
      q[1] -= c * s.tau_c[i];
      qd[1] -= c * s.tau_c_d[i];
      qdd[1] -= c * s.tau_c_dd[i];
      Y = FullRegressor(L1, g, q, qd, qdd);
    }
    const StepRow sr = RowFromRegressor(step, Y, known_here, subtracted, q, u);
    VecM w;
    w.template head<3>() = sr.w;
    if constexpr (M > 3) w[3] = PassiveElasticTorque(passive, q)[row];
    if constexpr (M > 4) w[4] = qd[row];
    rows.row(i) << w.transpose(), sr.u_star;
    WtW.template selfadjointView<Eigen::Lower>().rankUpdate(w);
    Wtu += w * sr.u_star;
    if (known_cov) WtA += w * Eigen::RowVector3d(Y(row, 1), Y(row, 3), Y(row, 5));
  }
  WtW = WtW.template selfadjointView<Eigen::Lower>();
  e.held_mean = held_sum / static_cast<double>(n);

  VecM d;
  for (int k = 0; k < M; ++k) d[k] = WtW(k, k) > 0 ? 1.0 / std::sqrt(WtW(k, k)) : 0.0;
  const MatM S = d.asDiagonal() * WtW * d.asDiagonal();  // (W D)'(W D)
  const Eigen::SelfAdjointEigenSolver<MatM> eig(S, Eigen::EigenvaluesOnly);
  const double lmin = eig.eigenvalues()[0], lmax = eig.eigenvalues()[M - 1];
  if (!(lmin > 1e-14 * lmax) || d.minCoeff() == 0.0)
    throw InputError("step " + std::to_string(step) + " (" + e.segment +
                     "): the regressor is rank deficient, expected an exciting motion (several "
                     "harmonics over a wide range) of the moving joint");
  e.condition_number = std::sqrt(lmax / lmin);
  const Eigen::LDLT<MatM> ldlt(S);
  const VecM b = d.asDiagonal() * ldlt.solve(d.asDiagonal() * Wtu);  // HJ15 eq. 21
  e.phi = b.template head<3>();

  const double rss = (rows.col(M) - rows.template leftCols<M>() * b).squaredNorm();
  e.residual_rms = std::sqrt(rss / static_cast<double>(n));
  const double sigma2 = n > static_cast<size_t>(M) ? rss / static_cast<double>(n - M) : 0.0;
  const MatM Sinv = ldlt.solve(MatM::Identity());
  const MatM WtWinv = d.asDiagonal() * Sinv * d.asDiagonal();
  MatM cov = sigma2 * WtWinv;
  if (known_cov) {
    const Eigen::Matrix<double, M, 3> G = WtWinv * WtA;
    cov += G * (*known_cov) * G.transpose();
  }
  e.cov = cov.template topLeftCorner<3, 3>();
  for (int k = 0; k < 3; ++k) e.se[k] = std::sqrt(std::max(0.0, e.cov(k, k)));
  if constexpr (M > 3) {
    e.passive_factor = b[3];
    e.passive_factor_se = std::sqrt(std::max(0.0, cov(3, 3)));
  }
  if constexpr (M > 4) {
    e.damping = b[4];
    e.damping_se = std::sqrt(std::max(0.0, cov(4, 4)));
  }
  return e;
}

}  // namespace

StepEstimate SolveStep(int step, const IdentificationSamples& s, double L1, double g, const Vector6& known,
                       PassiveModel passive, const Eigen::Matrix3d* known_cov, const HumanSideRows* rows) {
  if (step >= 3 && rows && rows->subject_passive) {
    if (passive == PassiveModel::kNone)
      throw InputError("step " + std::to_string(step) +
                       ": the subject's factor on the passive model needs one, expected riener1999");
    // A damping must not feed energy (a plant refuses it): below 0 it is held at 0.
    const StepEstimate e = SolveColumns<5>(step, s, L1, g, known, passive, known_cov, rows);
    return e.damping >= 0 ? e : SolveColumns<4>(step, s, L1, g, known, passive, known_cov, rows);
  }
  return SolveColumns<3>(step, s, L1, g, known, passive, known_cov, rows);
}

IdentificationResult IdentifyExo(const IdentificationSamples& knee, const IdentificationSamples& hip,
                                 double L1, double g) {
  IdentificationResult r;
  r.params.L1 = L1;
  r.params.g = g;
  const StepEstimate s1 = SolveStep(1, knee, L1, g, Vector6::Zero(), PassiveModel::kNone);
  LumpedParams& exo = r.params.exo;
  exo.J2 = s1.phi[0];
  exo.X2 = s1.phi[1];
  exo.Y2 = s1.phi[2];
  const StepEstimate s2 = SolveStep(2, hip, L1, g, ToVector(exo), PassiveModel::kNone, &s1.cov);
  exo.J1 = s2.phi[0];
  exo.X1 = s2.phi[1];
  exo.Y1 = s2.phi[2];
  r.steps = {s1, s2};
  return r;
}

IdentificationResult IdentifyHuman(const IdentificationSamples& knee, const IdentificationSamples& hip,
                                   const LegParams& known, PassiveModel passive, const HumanSideFit& fit) {
  IdentificationResult r;
  r.params = known;
  r.params.human.reset();
  r.params.effects.clear();
  HumanSideRows rows;
  rows.exo = ToVector(known.exo);
  rows.subject_passive = fit.subject_passive;
  auto step3 = [&](double c) {
    rows.knee_compliance = c;
    return SolveStep(3, knee, known.L1, known.g, ToVector(known.exo), passive, nullptr, &rows);
  };
  StepEstimate s3 = step3(0.0);
  r.rigid_cuff_residual_rms = s3.residual_rms;
  const double c_max = fit.max_knee_compliance;
  if (c_max > 0 && knee.tau_c.size() == knee.size() && hip.tau_c.size() == hip.size()) {
    // Golden-section search of step 3's residual over c in [0, max] (unimodal: the residual grows
    // with the distance of c from the strap's, about |c - c*|, once the deflection dominates it), to
    // 1e-4 of max (0.1 % of a 1100 N m/rad strap's compliance at max 0.01).
    const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = 0, b = c_max;
    double x1 = b - phi * (b - a), x2 = a + phi * (b - a);
    double f1 = step3(x1).residual_rms, f2 = step3(x2).residual_rms;
    const double tolerance = 1e-4 * c_max;
    while (b - a > tolerance) {
      if (f1 <= f2) {
        b = x2, x2 = x1, f2 = f1;
        x1 = b - phi * (b - a);
        f1 = step3(x1).residual_rms;
      } else {
        a = x1, x1 = x2, f1 = f2;
        x2 = a + phi * (b - a);
        f2 = step3(x2).residual_rms;
      }
    }
    const StepEstimate best = step3(0.5 * (a + b));
    // Material only: the cuff's RMS deflection at least kMaterialShare of the knee angle's RMS about
    // its mean (the motion fit's materiality of a strap, diagnosis/diagnose_select.cc).
    double tau_c2 = 0, q_sum = 0, q2 = 0;
    for (size_t i = 0; i < knee.size(); ++i) {
      tau_c2 += knee.tau_c[i] * knee.tau_c[i];
      q_sum += knee.q[1][i];
      q2 += knee.q[1][i] * knee.q[1][i];
    }
    const double n = static_cast<double>(knee.size()), q_mean = q_sum / n;
    const double deflection_rms = rows.knee_compliance * std::sqrt(tau_c2 / n);
    const double angle_rms = std::sqrt(std::max(0.0, q2 / n - q_mean * q_mean));
    if (deflection_rms >= kMaterialShare * angle_rms && best.residual_rms < s3.residual_rms) {
      s3 = best;
      r.knee_compliance = rows.knee_compliance;
    }
  }
  rows.knee_compliance = r.knee_compliance;
  LumpedParams h;
  h.J2 = s3.phi[0];
  h.X2 = s3.phi[1];
  h.Y2 = s3.phi[2];
  const StepEstimate s4 =
      SolveStep(4, hip, known.L1, known.g, ToVector(known.exo) + ToVector(h), passive, &s3.cov, &rows);
  h.J1 = s4.phi[0];
  h.X1 = s4.phi[1];
  h.Y1 = s4.phi[2];
  r.params.human = h;
  r.params.passive = passive;
  if (fit.subject_passive) {
    const std::pair<const char*, const StepEstimate*> per_joint[2] = {{"hip", &s4}, {"knee", &s3}};
    for (const auto& [joint, st] : per_joint) {
      r.params.effects.push_back({kPassiveMoment, joint, st->passive_factor - 1.0, FindFamily(kPassiveMoment)->unit, {}, ""});
      r.params.effects.push_back({kViscousFriction, joint, st->damping, FindFamily(kViscousFriction)->unit, {}, ""});
    }
  }
  r.steps = {s3, s4};
  return r;
}

IdentificationResult Identify(const std::vector<MeasuredData>& files, const LegParams* known,
                              double L1, const IdentificationOptions& opt) {
  IdentificationSamples knee, hip;
  knee.config = IdConfiguration::kKneeSwing;
  hip.config = IdConfiguration::kHipSwing;
  const bool human = known != nullptr;
  for (const MeasuredData& f : files) {
    const IdConfiguration c = ClassifyConfiguration(f, opt);
    // tau_C only where the knee cuff is fitted.
    AppendSamples(f, human, opt, c == IdConfiguration::kKneeSwing ? &knee : &hip,
                  human && opt.human_side.max_knee_compliance > 0 ? known : nullptr);
  }
  auto missing = [&](IdConfiguration c) {
    std::string got;
    for (const MeasuredData& f : files) got += (got.empty() ? "" : ", ") + f.source;
    throw InputError(std::string("identify: no ") + ConfigurationName(c) + " recording among [" + got +
                     "]; expected one knee swing with the hip held at 90 deg and one hip swing with "
                     "the knee held at -90 deg");
  };
  if (knee.size() == 0) missing(IdConfiguration::kKneeSwing);
  if (hip.size() == 0) missing(IdConfiguration::kHipSwing);
  if (human) return IdentifyHuman(knee, hip, *known, opt.passive, opt.human_side);
  return IdentifyExo(knee, hip, L1, 9.81);
}

namespace {

std::string Num(double v) {
  std::ostringstream os;
  os.precision(8);
  os << v;
  return os.str();
}

std::string List(const Eigen::Vector3d& v) {
  return "[" + Num(v[0]) + ", " + Num(v[1]) + ", " + Num(v[2]) + "]";
}

std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string IdentificationYaml(const IdentificationResult& r, const IdentificationOptions& opt) {
  std::ostringstream os;
  const bool human = !r.steps.empty() && r.steps[0].step >= 3;
  os << "identification:\n";
  os << "  method: \"least squares, Hwang & Jeon 2015 eq. (18)-(21); full regressor restricted to "
        "the unknown columns, known parameters on the left (re-derived signs)\"\n";
  os << "  derivatives: \"zero-phase 2nd-order Butterworth " << Num(opt.cutoff_hz)
     << " Hz, central differences; " << Num(opt.trim_s) << " s trimmed at both ends of each file\"\n";
  if (human) {
    os << "  passive_model: " << PassiveModelName(opt.passive) << "\n";
    if (opt.selection.thresholds.empty())
      os << "  passive_selection: \"eq. (13): every |emg_*| below mean + " << Num(opt.selection.n_sd)
         << " SD of the first " << Num(opt.selection.reference_s) << " s of each file";
    else
      os << "  passive_selection: \"eq. (13): every |emg_*| below the given thresholds";
    if (opt.selection.envelope_s > 0)
      os << " (moving average " << Num(opt.selection.envelope_s) << " s)";
    os << "; all samples when a file has no emg_* column\"\n";
    if (opt.human_side.max_knee_compliance > 0) {
      os << "  knee_cuff: \"the human's knee angle is the exoskeleton's less c tau_C, c in [0, "
         << Num(opt.human_side.max_knee_compliance) << "] rad/N m by step 3's residual, kept where material\"\n";
      os << "  knee_cuff_compliance: " << Num(r.knee_compliance) << "   # rad/N m";
      if (r.knee_compliance > 0) os << ", a strap of " << Num(1.0 / r.knee_compliance) << " N m/rad";
      os << "\n";
      os << "  rigid_cuff_step3_residual_rms: " << Num(r.rigid_cuff_residual_rms) << "   # N m\n";
    } else {
      os << "  knee_cuff: \"rigid (Hwang & Jeon 2015 as published)\"\n";
    }
  }
  os << "  condition_number: \"2-norm condition number of the column-scaled regressor W D\"\n";
  os << "  std_error: \"sqrt(diag(sigma^2 (W'W)^-1)) (+ propagated step-1/3 uncertainty in steps 2/4); "
        "white-residual assumption\"\n";
  os << "  steps:\n";
  for (const StepEstimate& s : r.steps) {
    const bool knee = s.step == 1 || s.step == 3;
    os << "    - step: " << s.step << "\n";
    os << "      segment: " << s.segment << "\n";
    os << "      parameters: " << (knee ? "[J2, X2, Y2]" : "[J1, X1, Y1]") << "\n";
    os << "      estimate: " << List(s.phi) << "\n";
    os << "      std_error: " << List(s.se) << "\n";
    os << "      condition_number: " << Num(s.condition_number) << "\n";
    os << "      residual_rms: " << Num(s.residual_rms) << "   # N m\n";
    os << "      held_joint_mean_deg: " << Num(s.held_mean * kDegPerRad) << "   # "
       << (knee ? "hip" : "knee") << "\n";
    if (opt.human_side.subject_passive && s.step >= 3) {
      os << "      passive_factor: " << Num(s.passive_factor) << "   # on " << PassiveModelName(opt.passive)
         << ", std_error " << Num(s.passive_factor_se) << "\n";
      os << "      damping: " << Num(s.damping) << "   # N m s/rad, std_error " << Num(s.damping_se) << "\n";
    }
    os << "      samples_used: " << s.samples_used << "\n";
    os << "      samples_total: " << s.samples_total << "\n";
    os << "      files: [";
    for (size_t i = 0; i < s.sources.size(); ++i) os << (i ? ", " : "") << Quote(s.sources[i]);
    os << "]\n";
  }
  return os.str();
}

}  // namespace exotwin
