// Progress bar with ETA on a terminal (stderr), silent otherwise or with --quiet (docs/programs.md).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>

namespace eik {

// Reports the fraction of a piece of work done, in [0, 1]. Passed into long-running algorithms;
// may be empty. Must be safe to call from several threads.
using ProgressFn = std::function<void(double fraction)>;

class ProgressBar {
 public:
  // enabled = false (or stderr not a terminal) draws nothing.
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(double fraction);   // thread-safe; redraws at most ~10 times per second
  void finish();                  // draws 100 % and ends the line
  ProgressFn callback();          // a ProgressFn that forwards to update()

  static bool stderrIsTerminal();

 private:
  void draw(double fraction, bool final);

  std::string label_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mutex_;
};

}  // namespace eik
