#include "sim/subjects.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/rng.h"
#include "sim/paper_tables.h"
#include "sim/realizability.h"

// Population model. The paper's 10 subjects are the only data, so the population is the Gaussian
// they define, made physically consistent by rejection:
//   v = [W, L1, L2, J_H1, J_H2, X_H1, X_H2, Y_H1, Y_H2] ~ N(mean, covariance) of Tables 2 + 4 (keeps
//     e.g. the weight-X_H1 and J_H1-X_H1 correlations, and Y's spread). The covariance uses the
//     divisor n, not n - 1: Table 4's printed SD row is the divisor-n SD of its columns for X_H1,
//     X_H2, Y_H1, Y_H2 (0.44, 0.15, 0.14, 0.07; with n - 1 they would read 0.46, 0.16, 0.15, 0.08),
//     and the population is meant to reproduce the printed spread;
//   exo | L1, L2 ~ conditional Gaussian of [L1, L2, exo 6] from Tables 2 + 3 (the exoskeleton links
//     are adjusted to the subject, so its parameters follow the leg lengths; Table 3 spread kept);
//   [height, age] | W, L1, L2 ~ conditional Gaussian of Tables 2's columns.
// A draw is rejected and redrawn unless W, L1, L2, height > 0 and both human and exo lumped
// parameters are realizable for L1 (realizability.h). Normals: Marsaglia's polar method on 53-bit
// uniforms from std::mt19937_64 (both fully specified, so the bits do not depend on the standard
// library; std::normal_distribution would). Each (seed, index) seeds its own engine via MixSeed (SplitMix64).

namespace exotwin {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Standard normals by the polar method (core/rng.h).
using SubjectRng = NormalRng<NormalPolar>;

// n standard normals, drawn in index order.
VectorXd Normals(SubjectRng& z, int n) {
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = z.Normal();
  return v;
}

// F with F F^T = C for a symmetric positive semi-definite C (eigen-decomposition, negative
// round-off eigenvalues clamped to 0).
MatrixXd CovarianceFactor(const MatrixXd& C) {
  Eigen::SelfAdjointEigenSolver<MatrixXd> es(C);
  VectorXd d = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return es.eigenvectors() * d.asDiagonal();
}

// x_drawn | x_given for a Gaussian with the mean and covariance (divisor n) of the rows of `data`.
// Columns [0, n_given) are the given ones.
class ConditionalGaussian {
 public:
  ConditionalGaussian(const MatrixXd& data, int n_given) : ng_(n_given) {
    const int n = static_cast<int>(data.rows());
    const VectorXd mu = data.colwise().mean();
    const MatrixXd c = data.rowwise() - mu.transpose();
    const MatrixXd S = c.transpose() * c / static_cast<double>(n);
    const int nd = static_cast<int>(data.cols()) - ng_;
    mu_g_ = mu.head(ng_);
    mu_d_ = mu.tail(nd);
    if (ng_ > 0) {
      const MatrixXd Sgg = S.topLeftCorner(ng_, ng_);
      const MatrixXd Sdg = S.bottomLeftCorner(nd, ng_);
      B_ = Sgg.ldlt().solve(Sdg.transpose()).transpose();
      F_ = CovarianceFactor(S.bottomRightCorner(nd, nd) - B_ * Sdg.transpose());
    } else {
      F_ = CovarianceFactor(S);
    }
  }
  VectorXd Draw(const VectorXd& given, SubjectRng& z) const {
    VectorXd m = mu_d_;
    if (ng_ > 0) m += B_ * (given - mu_g_);
    return m + F_ * Normals(z, static_cast<int>(F_.cols()));
  }

 private:
  int ng_;
  VectorXd mu_g_, mu_d_;
  MatrixXd B_, F_;
};

LumpedParams FromVector(const VectorXd& v, int k) {
  LumpedParams p;
  p.J1 = v[k];
  p.J2 = v[k + 1];
  p.X1 = v[k + 2];
  p.X2 = v[k + 3];
  p.Y1 = v[k + 4];
  p.Y2 = v[k + 5];
  return p;
}

void PutParams(MatrixXd& m, int row, int col, const LumpedParams& p) {
  m.block(row, col, 1, 6) << p.J1, p.J2, p.X1, p.X2, p.Y1, p.Y2;
}

struct PopulationModel {
  ConditionalGaussian body;    // [W, L1, L2, J_H1..Y_H2]
  ConditionalGaussian exo;     // [L1, L2 | exo 6]
  ConditionalGaussian extras;  // [W, L1, L2 | height, age]
};

PopulationModel BuildPopulation() {
  const auto& t2 = PaperTable2();
  const auto& t3 = PaperTable3();
  const auto& t4 = PaperTable4();
  const int n = kPaperSubjects;
  MatrixXd body(n, 9), exo(n, 8), extras(n, 5);
  for (int i = 0; i < n; ++i) {
    body.block(i, 0, 1, 3) << t2[i].weight, t2[i].L1, t2[i].L2;
    PutParams(body, i, 3, t4[i].identified);
    exo.block(i, 0, 1, 2) << t2[i].L1, t2[i].L2;
    PutParams(exo, i, 2, t3[i].exo);
    extras.row(i) << t2[i].weight, t2[i].L1, t2[i].L2, t2[i].height, t2[i].age;
  }
  return {ConditionalGaussian(body, 0), ConditionalGaussian(exo, 2), ConditionalGaussian(extras, 3)};
}

const PopulationModel& Population() {
  static const PopulationModel model = BuildPopulation();
  return model;
}

}  // namespace

std::vector<std::string> PresetNames() {
  std::vector<std::string> names;
  for (const auto& r : PaperTable2()) names.emplace_back(r.subject);
  return names;
}

Subject PresetSubject(const std::string& name) {
  for (int i = 0; i < kPaperSubjects; ++i) {
    const Table2Row& r = PaperTable2()[i];
    if (name != r.subject) continue;
    Subject s;
    s.name = r.subject;
    s.age = r.age;
    s.height = r.height;
    s.weight = r.weight;
    s.L1 = r.L1;
    s.L2 = r.L2;
    s.human = PaperTable4()[i].identified;
    s.exo = PaperTable3()[i].exo;
    return s;
  }
  std::ostringstream os;
  os << "subject: unknown preset '" << name << "', expected one of";
  for (const auto& n : PresetNames()) os << ' ' << n;
  throw InputError(os.str());
}

Subject DrawSubject(uint64_t seed, int index) {
  if (index < 0) throw InputError("subject: index = " + std::to_string(index) + ", expected >= 0");
  const PopulationModel& pop = Population();
  SubjectRng z(MixSeed(seed ^ MixSeed(static_cast<uint64_t>(index))));
  constexpr int kMaxAttempts = 10000;  // acceptance is > 95 %, so this is never reached
  for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
    const VectorXd b = pop.body.Draw(VectorXd(), z);
    const VectorXd lens = b.segment(1, 2);
    const VectorXd e = pop.exo.Draw(lens, z);
    const VectorXd x = pop.extras.Draw(b.head(3), z);
    Subject s;
    s.name = "virtual-" + std::to_string(seed) + "-" + std::to_string(index);
    s.weight = b[0];
    s.L1 = b[1];
    s.L2 = b[2];
    s.human = FromVector(b, 3);
    s.exo = FromVector(e, 0);
    s.height = x[0];
    s.age = x[1];
    if (!(s.weight > 0 && s.L1 > 0 && s.L2 > 0 && s.height > 0)) continue;
    if (!IsRealizable(s.human, s.L1) || !IsRealizable(s.exo, s.L1)) continue;
    return s;
  }
  throw std::logic_error("DrawSubject: no realizable draw in 10000 attempts");
}

LegParams SubjectLegParams(const Subject& s) {
  LegParams p;
  p.L1 = s.L1;
  p.exo = s.exo;
  p.human = s.human;
  return p;
}

}  // namespace exotwin
