#include "core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace eik {

bool ProgressBar::stderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::string label, bool enabled)
    : label_(std::move(label)),
      enabled_(enabled && stderrIsTerminal()),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_ - std::chrono::seconds(1)) {}

ProgressBar::~ProgressBar() {
  if (enabled_ && !finished_) std::fputc('\n', stderr);
}

void ProgressBar::update(double fraction) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  draw(fraction, false);
}

void ProgressBar::finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  draw(1.0, true);
  finished_ = true;
}

ProgressFn ProgressBar::callback() {
  return [this](double f) { update(f); };
}

void ProgressBar::draw(double fraction, bool final) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  constexpr int kWidth = 30;
  int filled = static_cast<int>(fraction * kWidth + 0.5);
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  char eta[32];
  if (final)
    std::snprintf(eta, sizeof eta, "%.1fs", elapsed);
  else if (fraction > 0.01)
    std::snprintf(eta, sizeof eta, "ETA %.1fs", elapsed * (1.0 - fraction) / fraction);
  else
    std::snprintf(eta, sizeof eta, "ETA --");
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  std::fprintf(stderr, "\r%-12s [%s] %5.1f%%  %-14s", label_.c_str(), bar.c_str(), fraction * 100.0, eta);
  if (final) std::fputc('\n', stderr);
  std::fflush(stderr);
}

}  // namespace eik
