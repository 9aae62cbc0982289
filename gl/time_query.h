// GPU time: TimeQuery, the RAII owner of one GL_TIME_ELAPSED query object (GL 3.3 core), and
// PhaseTimer, which times the named phases of a run of GPU work with them (or with glFinish and the
// wall clock) and adds the seconds per phase into a map (lightsim's SimulationStats::phase_seconds).
//
// PhaseTimer modes:
//   Queries  one GL_TIME_ELAPSED query per phase, collected asynchronously by collect(): it does
//            not serialise the GPU. Query objects are reused once their result has been read.
//   Finish   glFinish at the end of each phase and the wall-clock time since its start
//            (core/stopwatch.h): exact, but it stalls the pipeline after every phase.
//   Off      records nothing.
// Only one GL_TIME_ELAPSED query can be active at a time, so phases do not nest: start() ends the
// running phase. Needs a current context for its whole life (gl/handle.h conventions).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/stopwatch.h"
#include "gl/handle.h"

namespace eik::gl {

namespace detail {
struct QueryTraits {
  static void destroy(GLuint name) { glDeleteQueries(1, &name); }
};
}  // namespace detail

class TimeQuery {
 public:
  TimeQuery() = default;  // no query object
  static TimeQuery create();

  // glBeginQuery(GL_TIME_ELAPSED, id()): GPU time from here to end().
  void begin() const;
  // glEndQuery(GL_TIME_ELAPSED): ends the active time query, whichever it is.
  static void end();
  // Whether the result is there (GL_QUERY_RESULT_AVAILABLE; does not wait).
  bool available() const;
  // The elapsed GPU time in nanoseconds (GL_QUERY_RESULT; waits for it).
  std::uint64_t nanoseconds() const;

  GLuint id() const { return handle_.get(); }
  explicit operator bool() const { return bool(handle_); }

 private:
  explicit TimeQuery(GLuint name) : handle_(name) {}
  GlHandle<detail::QueryTraits> handle_;
};

class PhaseTimer {
 public:
  enum class Mode { Off, Queries, Finish };

  // Adds the seconds of each phase into out[name] (out must outlive the timer).
  PhaseTimer(Mode mode, std::map<std::string, double>& out) : mode_(mode), out_(out) {}
  // Leaves no query active (results that were not collected are dropped).
  ~PhaseTimer();
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

  Mode mode() const { return mode_; }

  // Ends the running phase and starts `name`.
  void start(const char* name);
  // Ends the running phase (if any).
  void stop();
  // Adds the results of finished queries (all of them, waiting, with `wait`). Queries mode only.
  void collect(bool wait);

 private:
  struct Pending {
    std::string name;
    TimeQuery query;
  };
  Mode mode_;
  std::map<std::string, double>& out_;
  bool running_ = false;
  std::string name_;
  Stopwatch watch_;               // Finish: since the start of the running phase
  std::vector<Pending> pending_;  // Queries: ended (and the running one), in order
  std::vector<TimeQuery> free_;   // Queries: collected, to be reused
};

}  // namespace eik::gl
