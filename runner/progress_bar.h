// A one-line progress bar with ETA on stderr, drawn only when stderr is a terminal.
#pragma once
#include <chrono>
#include <cstddef>
#include <string>

namespace exotwin {

class ProgressBar {
 public:
  // `total` units of work; `label` prefixes the line. Draws only if enabled and stderr is a tty.
  ProgressBar(size_t total, std::string label, bool enabled = true);
  // Reports `done` (<= total) units finished; redraws at most every 0.2 s (and at the end).
  void Update(size_t done, size_t failed = 0);
  // Ends the line (newline) if anything was drawn.
  void Finish();
  // "1h02m", "3m05s", "12s": a duration (s >= 0) in words for humans.
  static std::string FormatDuration(double s);

 private:
  size_t total_;
  std::string label_;
  bool enabled_, drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace exotwin
