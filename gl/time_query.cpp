// GL_TIME_ELAPSED queries and the phase timer over them (see time_query.h).
#include "gl/time_query.h"

#include <cstddef>
#include <utility>

namespace eik::gl {

TimeQuery TimeQuery::create() {
  GLuint id = 0;
  glGenQueries(1, &id);
  return TimeQuery(id);
}

void TimeQuery::begin() const { glBeginQuery(GL_TIME_ELAPSED, handle_.get()); }

void TimeQuery::end() { glEndQuery(GL_TIME_ELAPSED); }

bool TimeQuery::available() const {
  GLint available = 0;
  glGetQueryObjectiv(handle_.get(), GL_QUERY_RESULT_AVAILABLE, &available);
  return available != 0;
}

std::uint64_t TimeQuery::nanoseconds() const {
  GLuint64 ns = 0;
  glGetQueryObjectui64v(handle_.get(), GL_QUERY_RESULT, &ns);
  return ns;
}

PhaseTimer::~PhaseTimer() {
  if (mode_ == Mode::Queries && running_) TimeQuery::end();
}

void PhaseTimer::start(const char* name) {
  stop();
  if (mode_ != Mode::Finish && mode_ != Mode::Queries) return;
  running_ = true;
  name_ = name;
  if (mode_ == Mode::Finish) {
    watch_.restart();
  } else {
    if (free_.empty()) free_.push_back(TimeQuery::create());
    pending_.push_back({name_, std::move(free_.back())});
    free_.pop_back();
    pending_.back().query.begin();
  }
}

void PhaseTimer::stop() {
  if (!running_) return;
  running_ = false;
  if (mode_ == Mode::Finish) {
    glFinish();
    out_[name_] += watch_.seconds();
  } else if (mode_ == Mode::Queries) {
    TimeQuery::end();
  }
}

void PhaseTimer::collect(bool wait) {
  if (mode_ != Mode::Queries) return;
  std::size_t done = 0;
  for (; done < pending_.size(); ++done) {
    Pending& p = pending_[done];
    if (running_ && done + 1 == pending_.size()) break;  // the active one
    if (!wait && !p.query.available()) break;
    out_[p.name] += static_cast<double>(p.query.nanoseconds()) * 1e-9;
    free_.push_back(std::move(p.query));
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(done));
}

}  // namespace eik::gl
