// Tests of GL_TIME_ELAPSED queries and the phase timer (time_query.h): the query object's life, and
// what each PhaseTimer mode records. Times are checked for presence and sign, never for size,
// except the wall-clock floor of Finish mode.
#include "gl/time_query.h"

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <string>
#include <thread>

#include "gl/framebuffer.h"

namespace eik::gl {
namespace {

class TimeQueryTest : public ::testing::Test {
 protected:
  // Error checks on whatever the build type.
  GlContext context_{ContextOptions{.backend = glBackendFromEnvironment(GlBackend::OSMesa), .debug = true}};
  Framebuffer target_{{64, 64}, {TextureFormat::RGBA32F}};

  // A little GPU work to time.
  void work() {
    for (int i = 0; i < 4; ++i) target_.clear(0, glm::vec4(static_cast<float>(i)));
  }
};

GLuint activeTimeQuery() {
  GLint name = -1;
  glGetQueryiv(GL_TIME_ELAPSED, GL_CURRENT_QUERY, &name);
  return static_cast<GLuint>(name);
}

TEST_F(TimeQueryTest, QueryObjectLivesWithItsOwner) {
  GLuint name = 0;
  {
    TimeQuery query = TimeQuery::create();
    ASSERT_TRUE(query);
    name = query.id();
    query.begin();
    EXPECT_EQ(activeTimeQuery(), name);
    work();
    TimeQuery::end();
    EXPECT_EQ(activeTimeQuery(), 0u);
    EXPECT_TRUE(glIsQuery(name));
    glFinish();
    EXPECT_TRUE(query.available());
    (void)query.nanoseconds();
    TimeQuery moved = std::move(query);
    EXPECT_FALSE(query);
    EXPECT_EQ(moved.id(), name);
  }
  EXPECT_FALSE(glIsQuery(name));
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(TimeQueryTest, QueriesModeRecordsEveryPhaseOnCollect) {
  std::map<std::string, double> seconds;
  {
    PhaseTimer timer(PhaseTimer::Mode::Queries, seconds);
    EXPECT_EQ(timer.mode(), PhaseTimer::Mode::Queries);
    for (int round = 0; round < 3; ++round) {  // the second round on reuses collected queries
      timer.start("clear");
      work();
      timer.start("again");
      work();
      EXPECT_NE(activeTimeQuery(), 0u);
      timer.collect(true);  // everything but the running phase
      EXPECT_EQ(seconds.count("clear"), 1u);
      if (round == 0) {
        EXPECT_EQ(seconds.count("again"), 0u);
      }
      timer.stop();
      EXPECT_EQ(activeTimeQuery(), 0u);
      timer.collect(false);  // whatever is done already
    }
    timer.collect(true);
  }
  ASSERT_EQ(seconds.size(), 2u);
  EXPECT_GE(seconds["clear"], 0.0);
  EXPECT_GE(seconds["again"], 0.0);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(TimeQueryTest, DestroyingARunningQueriesTimerEndsItsQuery) {
  std::map<std::string, double> seconds;
  {
    PhaseTimer timer(PhaseTimer::Mode::Queries, seconds);
    timer.start("running");
    work();
    EXPECT_NE(activeTimeQuery(), 0u);
  }
  EXPECT_EQ(activeTimeQuery(), 0u);
  EXPECT_TRUE(seconds.empty());  // never collected
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(TimeQueryTest, FinishModeAddsTheWallClockTimeOfEachPhase) {
  std::map<std::string, double> seconds;
  PhaseTimer timer(PhaseTimer::Mode::Finish, seconds);
  timer.start("sleep");
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  timer.start("work");
  work();
  EXPECT_EQ(activeTimeQuery(), 0u);  // no queries in this mode
  timer.start("sleep");
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  timer.stop();
  timer.collect(true);  // nothing to collect
  ASSERT_EQ(seconds.size(), 2u);
  EXPECT_GE(seconds["sleep"], 0.040);
  EXPECT_GE(seconds["work"], 0.0);
}

TEST_F(TimeQueryTest, OffModeRecordsNothing) {
  std::map<std::string, double> seconds;
  PhaseTimer timer(PhaseTimer::Mode::Off, seconds);
  timer.start("update");
  work();
  EXPECT_EQ(activeTimeQuery(), 0u);
  timer.stop();
  timer.collect(true);
  EXPECT_TRUE(seconds.empty());
}

}  // namespace
}  // namespace eik::gl
