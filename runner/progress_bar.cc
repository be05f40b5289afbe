#include "runner/progress_bar.h"

#include <cmath>
#include <cstdio>

#include <unistd.h>

namespace exotwin {

ProgressBar::ProgressBar(size_t total, std::string label, bool enabled)
    : total_(total), label_(std::move(label)), enabled_(enabled && isatty(2)),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

std::string ProgressBar::FormatDuration(double s) {
  const long t = std::lround(std::max(0.0, s));
  char buf[32];
  if (t >= 3600) std::snprintf(buf, sizeof(buf), "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else if (t >= 60) std::snprintf(buf, sizeof(buf), "%ldm%02lds", t / 60, t % 60);
  else std::snprintf(buf, sizeof(buf), "%lds", t);
  return buf;
}

void ProgressBar::Update(size_t done, size_t failed) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && drawn_ && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double el = std::chrono::duration<double>(now - start_).count();
  const double frac = total_ ? static_cast<double>(done) / total_ : 1.0;
  constexpr int kWidth = 30;
  const int fill = static_cast<int>(frac * kWidth);
  std::string bar(fill, '#');
  bar += std::string(kWidth - fill, '.');
  const std::string eta = done > 0 ? FormatDuration(el * (total_ - done) / done) : "?";
  std::fprintf(stderr, "\r%s [%s] %zu/%zu %3.0f%%%s  elapsed %s  eta %s   ", label_.c_str(), bar.c_str(),
               done, total_, 100 * frac, failed ? (" (" + std::to_string(failed) + " failed)").c_str() : "",
               FormatDuration(el).c_str(), eta.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::Finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace exotwin
