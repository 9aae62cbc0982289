// Wall-clock time of a phase of work, for --stats, --bench and the time per phase in a bake's
// manifest. (GPU phases are timed with gl/time_query.h, which does not serialise the GPU.)
#pragma once

#include <chrono>

namespace eik {

class Stopwatch {
 public:
  using Clock = std::chrono::steady_clock;

  Stopwatch() : start_(Clock::now()) {}

  // Seconds since construction or the last restart().
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  double milliseconds() const { return seconds() * 1e3; }

  // Seconds since construction or the last restart(), and starts counting again from now.
  double restart() {
    const Clock::time_point now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return elapsed;
  }

 private:
  Clock::time_point start_;
};

}  // namespace eik
