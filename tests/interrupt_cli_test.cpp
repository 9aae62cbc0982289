// Interrupts at every point of each program's write phase (issue "Reliability"; docs/programs.md
// "Outputs"): a test hook (core/interrupt.h testSignalPoint, EIKONAL_TEST_SIGNAL_AT=SIG@N) raises
// SIGKILL or SIGINT at the N-th step of the atomic writes: each file staged, each rename, each
// removal of a superseded file. For every N up to the last step, starting from a finished old
// result, the result under its final names must read back as the old one or the new one in full,
// never a mix or a part; after SIGINT no temporary is left, and after SIGKILL the next run removes
// what was left.
#include <signal.h>
#include <stdlib.h>

#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/volume.h"
#include "tests/program_runner.h"

namespace eik::test {
namespace {

namespace fs = std::filesystem;

// Every value a volume holds: its fields and receiver maps (not the metadata, which holds times).
using Contents = std::map<std::string, std::vector<float>>;

Contents contentsOf(const fs::path& manifest) {
  const Volume volume = readVolume(manifest);
  Contents contents;
  for (const auto& [name, field] : volume.fields) contents["field " + name] = field.data;
  for (const ReceiverMap& map : volume.receivers) contents["receiver " + map.name] = map.irradiance;
  return contents;
}

bool hasTemporaries(const TempDir& dir) {
  for (const std::string& name : dir.entries())
    if (name.find(".tmp-") != std::string::npos) return true;
  return false;
}

// Files of `stem`'s volume under final names that the manifest does not name (other generations).
std::vector<std::string> unnamedFiles(const TempDir& dir, const std::string& stem) {
  const std::string manifest = readFile(dir / (stem + ".vol.json"));
  std::vector<std::string> unnamed;
  for (const std::string& name : dir.entries()) {
    if (name.rfind(stem + ".", 0) != 0 || name == stem + ".vol.json") continue;
    if (manifest.find("\"" + name + "\"") == std::string::npos) unnamed.push_back(name);
  }
  return unnamed;
}

struct SignalAt {
  SignalAt(int signal_number, int step) {
    ::setenv("EIKONAL_TEST_SIGNAL_AT", (std::to_string(signal_number) + "@" + std::to_string(step)).c_str(), 1);
  }
  ~SignalAt() { ::unsetenv("EIKONAL_TEST_SIGNAL_AT"); }
};

// Runs `make_old` (the previous result), then `make_new` with the signal at step 1, 2, ... until a
// run finishes before the step comes; checks the result after each. Returns the number of steps.
int expectAllOrNothing(const TempDir& dir, const std::string& exe, const std::vector<std::string>& make_old,
                       const std::vector<std::string>& make_new, const std::string& stem, int signal_number) {
  const fs::path manifest = dir / (stem + ".vol.json");
  ProgramResult r = runProgram(exe, make_new, dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const Contents fresh = contentsOf(manifest);
  r = runProgram(exe, make_old, dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const Contents old = contentsOf(manifest);
  EXPECT_NE(old, fresh) << "the two runs must differ for the test to see a mix";
  // The old result's files, copied back before each step (faster than running make_old again).
  TempDir saved;
  auto isResultFile = [&](const std::string& name) {
    return name.rfind(stem + ".", 0) == 0 || name.rfind("." + stem + ".", 0) == 0;
  };
  for (const std::string& name : dir.entries())
    if (isResultFile(name)) fs::copy_file(dir / name, saved / name);
  int saw_old = 0, saw_new = 0, step = 1;
  for (;; ++step) {
    for (const std::string& name : dir.entries())
      if (isResultFile(name)) fs::remove(dir / name);
    for (const std::string& name : saved.entries()) fs::copy_file(saved / name, dir / name);
    {
      SignalAt at(signal_number, step);
      r = runProgram(exe, make_new, dir.path());
    }
    if (r.exit_code == 0) break;  // the write has fewer steps
    EXPECT_EQ(r.exit_code, 128 + signal_number) << "step " << step << ": " << r.output;
    Contents now;
    try {
      now = contentsOf(manifest);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "step " << step << ": the result does not read back: " << e.what();
    }
    if (now == old) ++saw_old;
    else if (now == fresh) ++saw_new;
    else ADD_FAILURE() << "step " << step << ": the result under the final names is neither the old nor the new one";
    if (signal_number != SIGKILL) {
      EXPECT_FALSE(hasTemporaries(dir)) << "step " << step;
    }
    if (step > 200) {
      ADD_FAILURE() << "no end to the write's steps";
      break;
    }
  }
  // A switch point exists: stopped before it, the old result stays; after it, the new one is there.
  EXPECT_GT(saw_old, 0);
  EXPECT_GT(saw_new, 0);
  // The finished run removed what the killed ones left: no temporaries, no files of other writes.
  EXPECT_FALSE(hasTemporaries(dir)) << ::testing::PrintToString(dir.entries());
  EXPECT_TRUE(unnamedFiles(dir, stem).empty()) << ::testing::PrintToString(unnamedFiles(dir, stem));
  return step - 1;
}

TEST(Interrupts, VoxelizeResultIsOldOrNewAtEveryStepOfItsWrite) {
  for (int signal_number : {SIGKILL, SIGINT}) {
    TempDir dir;
    const int steps = expectAllOrNothing(
        dir, VOXELIZE_EXE, {"procedural:sphere,r=0.5,ior=1.3", "-o", "v.vol.json", "--res", "12", "--quiet"},
        {"procedural:sphere,r=0.4,ior=1.5,sigma_a=0.1:0.2:0.3", "-o", "v.vol.json", "--res", "12", "--quiet"}, "v",
        signal_number);
    // Stage and rename each field and the manifest, then remove the old files: more than 8 steps.
    EXPECT_GT(steps, 8) << "signal " << signal_number;
  }
}

TEST(Interrupts, LightsimResultIsOldOrNewAtEveryStepOfItsWrite) {
  for (int signal_number : {SIGKILL, SIGINT}) {
    TempDir dir;
    ProgramResult r = runProgram(
        VOXELIZE_EXE, {"procedural:sphere,r=0.5,ior=1.5", "-o", "ball.vol.json", "--res", "12", "--quiet"}, dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::vector<std::string> common = {"ball.vol.json", "-o", "b.vol.json", "--backend", "cpu",
                                             "--receiver", "0,-0.6,0:0,1,0", "--quiet"};
    std::vector<std::string> make_old = common, make_new = common;
    make_old.insert(make_old.end(), {"--light", "directional:0,-1,0"});
    make_new.insert(make_new.end(), {"--light", "directional:0.3,-1,0"});
    const int steps = expectAllOrNothing(dir, LIGHTSIM_EXE, make_old, make_new, "b", signal_number);
    EXPECT_GT(steps, 8) << "signal " << signal_number;
  }
}

// The viewer writes one file: at every step the image is absent (none before) or complete.
TEST(Interrupts, ViewerImageIsAbsentOrCompleteAtEveryStepOfItsWrite) {
  TempDir dir;
  ProgramResult r = runProgram(
      VOXELIZE_EXE, {"procedural:sphere,r=0.5,ior=1.5", "-o", "ball.vol.json", "--res", "12", "--quiet"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> args = {"ball.vol.json", "--render", "out.png", "--size", "16x16"};
  r = runProgram(VIEWER_EXE, args, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string complete = readFile(dir / "out.png");
  int step = 1;
  for (; step < 20; ++step) {
    fs::remove(dir / "out.png");
    {
      SignalAt at(SIGINT, step);
      r = runProgram(VIEWER_EXE, args, dir.path());
    }
    if (r.exit_code == 0) break;
    EXPECT_EQ(r.exit_code, 130) << r.output;
    if (fs::exists(dir / "out.png")) {
      EXPECT_EQ(readFile(dir / "out.png"), complete) << "step " << step;
    }
    EXPECT_FALSE(hasTemporaries(dir)) << "step " << step;
  }
  EXPECT_GE(step, 3) << "stage, rename and the end of the commit are steps";
  EXPECT_EQ(readFile(dir / "out.png"), complete);
}

}  // namespace
}  // namespace eik::test
