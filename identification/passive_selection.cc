#include "identification/passive_selection.h"

#include <cmath>

#include "core/error.h"

namespace exotwin {

namespace {

// Centered moving average of width w samples (w odd >= 1), shrinking at the ends.
std::vector<double> MovingAverage(const std::vector<double>& x, size_t w) {
  if (w <= 1) return x;
  const size_t n = x.size(), h = w / 2;
  std::vector<double> prefix(n + 1, 0.0), out(n);
  for (size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + x[i];
  for (size_t i = 0; i < n; ++i) {
    const size_t lo = i >= h ? i - h : 0, hi = std::min(n, i + h + 1);
    out[i] = (prefix[hi] - prefix[lo]) / static_cast<double>(hi - lo);
  }
  return out;
}

}  // namespace

PassiveSelection SelectPassiveSamples(const MeasuredData& data, const PassiveSelectionOptions& opt) {
  PassiveSelection sel;
  const size_t n = data.size();
  sel.passive.assign(n, 1);
  const CsvTable& tab = data.table;
  std::vector<int> cols;
  for (size_t c = 0; c < tab.names.size(); ++c)
    if (tab.names[c].rfind("emg_", 0) == 0) {
      cols.push_back(static_cast<int>(c));
      sel.channels.push_back(tab.names[c]);
    }
  if (cols.empty() || n == 0) {
    sel.kept = n;
    return sel;
  }
  const double dt = n > 1 ? (data.t().back() - data.t().front()) / static_cast<double>(n - 1) : 1e-3;
  size_t w = opt.envelope_s > 0 ? static_cast<size_t>(std::lround(opt.envelope_s / dt)) : 1;
  if (w % 2 == 0) ++w;
  size_t n_ref = 0;
  while (n_ref < n && data.t()[n_ref] - data.t().front() < opt.reference_s) ++n_ref;

  for (size_t k = 0; k < cols.size(); ++k) {
    const std::string& name = sel.channels[k];
    std::vector<double> chi(n);
    for (size_t i = 0; i < n; ++i) chi[i] = std::abs(tab.columns[cols[k]][i]);
    chi = MovingAverage(chi, w);
    double Z;
    auto given = opt.thresholds.find(name.substr(4));
    if (given == opt.thresholds.end()) given = opt.thresholds.find(name);
    if (given == opt.thresholds.end()) given = opt.thresholds.find("*");
    if (given != opt.thresholds.end()) {
      Z = given->second;
    } else {
      if (n_ref < 10)
        throw InputError(data.source + ": column '" + name + "': the relaxed EMG reference (first " +
                         std::to_string(opt.reference_s) + " s) holds " + std::to_string(n_ref) +
                         " samples, expected at least 10 (or give a threshold)");
      double mean = 0, sq = 0;
      for (size_t i = 0; i < n_ref; ++i) mean += chi[i];
      mean /= static_cast<double>(n_ref);
      for (size_t i = 0; i < n_ref; ++i) sq += (chi[i] - mean) * (chi[i] - mean);
      Z = mean + opt.n_sd * std::sqrt(sq / static_cast<double>(n_ref - 1));
    }
    sel.thresholds.push_back(Z);
    for (size_t i = 0; i < n; ++i)
      if (chi[i] >= Z) sel.passive[i] = 0;  // HJ15 eq. 13: A_ch = 1 when chi >= Z
  }
  for (char p : sel.passive) sel.kept += p ? 1 : 0;
  return sel;
}

}  // namespace exotwin
