// Shared helpers of the identification tests: the paper's subjects read from data/*.csv (Table 2 L1,
// Table 3 exo, Table 4 human), seeded random subjects around them, and recovery-error metrics.
#pragma once
#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <exception>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "model/lumped_params.h"
#include "sim/realization.h"

namespace exotwin::testing {

struct NamedSubject {
  std::string name;
  LegParams truth;  // L1, exo, human; passive riener1999
};

// Rows of data/<file> as strings (comments and header skipped).
inline std::vector<std::vector<std::string>> ReadDataRows(const std::string& file) {
  std::ifstream in(std::string(EXOTWIN_SOURCE_DIR) + "/data/" + file);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string x;
    while (std::getline(ss, x, ',')) f.push_back(x);
    rows.push_back(f);
  }
  return rows;
}

inline LumpedParams Lumped(const std::vector<std::string>& r, size_t first) {
  LumpedParams p;
  p.J1 = std::stod(r[first]);
  p.J2 = std::stod(r[first + 1]);
  p.X1 = std::stod(r[first + 2]);
  p.X2 = std::stod(r[first + 3]);
  p.Y1 = std::stod(r[first + 4]);
  p.Y2 = std::stod(r[first + 5]);
  return p;
}

// S1..S10: L1 from Table 2, exo from Table 3, human from Table 4 (identified columns).
inline std::vector<NamedSubject> PaperSubjects() {
  const auto t2 = ReadDataRows("hwang2015_table2_subjects.csv");
  const auto t3 = ReadDataRows("hwang2015_table3_exo_identified.csv");
  const auto t4 = ReadDataRows("hwang2015_table4_human_identified.csv");
  std::vector<NamedSubject> out;
  for (size_t i = 0; i < t2.size() && i < t3.size() && i < t4.size(); ++i) {
    if (t2[i][0] != t3[i][0] || t2[i][0] != t4[i][0] || t2[i][0][0] != 'S') continue;
    NamedSubject s;
    s.name = t2[i][0];
    s.truth.L1 = std::stod(t2[i][5]);
    s.truth.exo = Lumped(t3[i], 1);
    s.truth.human = Lumped(t4[i], 1);
    s.truth.passive = PassiveModel::kRiener1999;
    out.push_back(s);
  }
  return out;
}

inline bool Realizable(const LumpedParams& p, double L1) {
  try {
    RealizeLumped(p, L1, "x");
    return true;
  } catch (const InputError&) {
    return false;
  }
}

// Random valid subjects: a paper subject (cycling S1..S10) with J, X scaled by 1 + 0.15 N(0,1) and Y
// shifted by 0.1 N(0,1) kg m (human), exo J, X, Y scaled by 1 + 0.03 N(0,1), L1 + 0.01 N(0,1) m;
// kept only when RealizeLumped accepts both the human and the exo.
inline std::vector<NamedSubject> RandomSubjects(int n, uint64_t seed) {
  const auto base = PaperSubjects();
  NormalRng<NormalBoxMuller<BoxMullerU1::kMidpoint>> rng(seed);
  auto normal = [&rng]() { return rng.Normal(); };
  std::vector<NamedSubject> out;
  for (int tries = 0; static_cast<int>(out.size()) < n && tries < 100 * n; ++tries) {
    const NamedSubject& b = base[out.size() % base.size()];
    NamedSubject s;
    s.name = "R" + std::to_string(out.size() + 1) + "(" + b.name + ")";
    s.truth.L1 = b.truth.L1 + 0.01 * normal();
    s.truth.passive = PassiveModel::kRiener1999;
    LumpedParams h = *b.truth.human, e = b.truth.exo;
    for (double* v : {&h.J1, &h.J2, &h.X1, &h.X2}) *v *= 1 + 0.15 * normal();
    for (double* v : {&h.Y1, &h.Y2}) *v += 0.1 * normal();
    for (double* v : {&e.J1, &e.J2, &e.X1, &e.X2, &e.Y1, &e.Y2}) *v *= 1 + 0.03 * normal();
    if (!Realizable(h, s.truth.L1) || !Realizable(e, s.truth.L1)) continue;
    s.truth.exo = e;
    s.truth.human = h;
    out.push_back(s);
  }
  return out;
}

// Runs f(0) on this thread and f(1) on a second one; rethrows the first exception after both end.
inline void RunOnTwoThreads(const std::function<void(int)>& f) {
  std::exception_ptr err[2];
  std::thread t([&] {
    try {
      f(1);
    } catch (...) {
      err[1] = std::current_exception();
    }
  });
  try {
    f(0);
  } catch (...) {
    err[0] = std::current_exception();
  }
  t.join();
  for (auto& e : err)
    if (e) std::rethrow_exception(e);
}

// Recovery errors of one system: relative for J and X, absolute (kg m) for Y.
struct RecoveryError {
  double J = 0, X = 0, Y = 0;
  void Max(const RecoveryError& o) {
    J = std::max(J, o.J);
    X = std::max(X, o.X);
    Y = std::max(Y, o.Y);
  }
};

inline RecoveryError Error(const LumpedParams& est, const LumpedParams& truth) {
  RecoveryError e;
  e.J = std::max(std::abs(est.J1 / truth.J1 - 1), std::abs(est.J2 / truth.J2 - 1));
  e.X = std::max(std::abs(est.X1 / truth.X1 - 1), std::abs(est.X2 / truth.X2 - 1));
  e.Y = std::max(std::abs(est.Y1 - truth.Y1), std::abs(est.Y2 - truth.Y2));
  return e;
}

}  // namespace exotwin::testing
