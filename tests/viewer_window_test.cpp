// `viewer` without --render as a user runs it: with no display a clear error naming --render (exit
// 2); `--bench N --stats FILE.json` prints and writes its figures; misused window and bench flags
// exit 2. (The window itself against headless output: viewer/window_test.cpp, under Xvfb.)
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "tests/program_runner.h"

namespace eik::test {
namespace {

// Unsets an environment variable for a scope (the child inherits the environment).
class Unset {
 public:
  explicit Unset(const char* name) : name_(name) {
    if (const char* v = std::getenv(name)) old_ = v;
    ::unsetenv(name);
  }
  ~Unset() {
    if (old_) ::setenv(name_.c_str(), old_->c_str(), 1);
  }

 private:
  std::string name_;
  std::optional<std::string> old_;
};

void makeBall(const TempDir& dir) {
  ProgramResult r = runProgram(VOXELIZE_EXE, {"procedural:sphere,r=0.5,ior=1.5,sigma_a=0:0.5:1", "-o", "ball.vol.json",
                                              "--res", "24", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
}

TEST(ViewerWindowCli, WithoutADisplayAsksForRender) {
  TempDir dir;
  makeBall(dir);
  Unset display("DISPLAY"), wayland("WAYLAND_DISPLAY");
  ProgramResult r = runProgram(VIEWER_EXE, {"ball.vol.json"}, dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no display"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--render"), std::string::npos) << r.output;
}

TEST(ViewerWindowCli, BenchPrintsAndWritesItsFigures) {
  TempDir dir;
  makeBall(dir);
  ProgramResult r = runProgram(
      VIEWER_EXE, {"ball.vol.json", "--bench", "3", "--size", "40x30", "--stats", "bench.json"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("full/bare"), std::string::npos) << r.output;
  nlohmann::json j = nlohmann::json::parse(readFile(dir / "bench.json"));
  EXPECT_EQ(j["frames"], 3);
  EXPECT_EQ(j["size"], nlohmann::json::array({40, 30}));
  EXPECT_FALSE(j["gl_renderer"].get<std::string>().empty());
  EXPECT_EQ(j["full"]["frame_ms"].size(), 3u);
  EXPECT_EQ(j["bare"]["frame_ms"].size(), 3u);
  // Steps counted: at least one ray crosses the ball (the framing camera looks at it), and no ray
  // takes more than the march's bound; the full renderer's figure uses the same count.
  const double steps = j["bare"]["steps_per_frame"];
  EXPECT_GT(steps, 40.0 * 30.0 * 0.1 * 24);
  EXPECT_EQ(j["full"]["steps_per_frame"].get<double>(), steps);
  EXPECT_GT(j["ratio_full_over_bare"].get<double>(), 0.0);
}

TEST(ViewerWindowCli, MisusedFlagsExitTwo) {
  TempDir dir;
  makeBall(dir);
  struct Case {
    std::vector<std::string> args;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {{"ball.vol.json", "--bench", "2", "--render", "x.png"}, "--bench"},
      {{"ball.vol.json", "--render", "x.png", "--stats", "s.json"}, "--stats"},
      {{"ball.vol.json", "--window-frames", "2"}, "--save"},
      {{"ball.vol.json", "--render", "x.png", "--window-frames", "2", "--save", "y.exr"}, "--window-frames"},
      {{"ball.vol.json", "--window-frames", "2", "--save", "y.jpg"}, "--save"},
      {{"ball.vol.json", "--bench", "0"}, "--bench"},
      {{"ball.vol.json", "--window-orbit", "5"}, "--window-orbit"},
      {{"ball.vol.json", "--window-frames", "2", "--save", "y.exr", "--window-orbit", "5"}, "--window-orbit"},
  };
  for (const Case& c : cases) {
    ProgramResult r = runProgram(VIEWER_EXE, c.args, dir.path());
    EXPECT_EQ(r.exit_code, 2) << c.args[1] << ": " << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << r.output;
  }
}

}  // namespace
}  // namespace eik::test
