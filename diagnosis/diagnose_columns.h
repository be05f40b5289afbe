// Candidate explanations of a twin residual as columns of a linear model (first order in each
// effect of DESIGN.md "Effects"); used by Diagnose (diagnose.h).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "formats/measured_data.h"
#include "model/lumped_params.h"

namespace exotwin {

// One candidate effect: the columns (indices into ColumnBank::X) whose coefficients give its value.
struct Candidate {
  std::string name, axis;  // axis: gravity_error only
  int joint = 0;           // 0 hip, 1 knee
  std::vector<int> cols;
  double ripple_f = 0;                // torque_ripple: cycles per rad found by search
  std::vector<std::string> channels;  // muscle_activity: EMG channel of each column
  std::string Label() const;          // e.g. "gravity_error.Y(knee)"
};

// A low-pass of *xs[0 .. count) in place (n samples each), each signal the same bits as filtered alone;
// called from up to ColumnBank::threads threads at once on disjoint signals.
using ColumnFilter = std::function<void(std::vector<double>* const* xs, size_t count)>;

// Columns on the fit rows. Row layout: X has 2 m rows, hip rows 0..m-1 then knee rows m..2m-1;
// rows are weighted by 1/noise of their joint (so the stacked least squares are balanced).
struct ColumnBank {
  std::vector<size_t> sample;  // m sample indices of the fit rows
  std::vector<bool> train;     // m flags: row in the fitting part
  Eigen::MatrixXd X;           // 2m x columns (weighted)
  Eigen::VectorXd r;           // 2m weighted residual
  std::vector<Candidate> candidates;
  int used = 0;                // columns in use (X may be over-allocated while building)
  int constant[2] = {-1, -1};  // each joint's constant column (1 on its rows, 0 on the other's, weighted)
  // The residual's low-pass (parallel filtering): every column is evaluated on all n samples and
  // filtered by it before its fit rows are taken. Empty: no filter.
  ColumnFilter filter;
  size_t n = 0;                // samples of the record
  int threads = 1;             // threads evaluating a column on the n samples (the same bits on any count)
};

// Builds every candidate for both joints: per joint its constant column, the columns of the families
// linear in their value, then those of the families with their own (FitFamily::add_columns), in the
// registry's order. tau_S: the twin's prediction (N m) on all samples (its rigid
// tau_R, ActuatorTorque, is evaluated where a column needs it); resid[j]: measured - predicted
// tau_S, released (left empty) once the fit rows' values are taken; w[j]: row weights (1/N m);
// split: first held-out sample; threads: ColumnBank::threads (0: every core).
ColumnBank BuildColumns(const LegParams& params, const Kinematics& kin, const std::vector<double> tau_S[2],
                        std::vector<double> resid[2], const double w[2], size_t split,
                        size_t max_rows,
                        ColumnFilter filter = {}, int threads = 0);

// Stores column c of the bank from per-sample values v[0] (hip rows), v[1] (knee rows), n each,
// filtered by bank.filter when set and weighted by w.
void SetColumn(ColumnBank& b, int c, const double w[2], std::vector<double> v[2]);

// Adds the candidates whose columns are searched on a target (FitFamily::add_searched_columns: the
// ripple's frequency) to every bank (one per record of one device, the same columns), the search on the
// train rows of `targets` pooled (per bank 2m weighted rows, e.g. the residual of all other columns).
void AddSearchedCandidates(std::vector<ColumnBank>& banks, const std::vector<const Kinematics*>& kins,
                           const std::vector<Eigen::VectorXd>& targets);

}  // namespace exotwin
