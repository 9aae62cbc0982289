// `viewer` headless as a user runs it: a rendered EXR with the right numbers, a PNG, and exit code 2
// with a clear message for bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "core/volume.h"
#include "tests/program_runner.h"

namespace eik::test {
namespace {

// A sphere of radius 0.5 with σa = (0, 0.5, 1) per unit, 32³.
void makeSphere(const TempDir& dir) {
  ProgramResult r = runProgram(VOXELIZE_EXE,
                               {"procedural:sphere,r=0.5,ior=1.5,sigma_a=0:0.5:1", "-o", "ball.vol.json", "--res", "32", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
}

TEST(ViewerCli, RendersBeerLambertThroughTheCentre) {
  TempDir dir;
  makeSphere(dir);
  // Looking straight through the centre along -z: the central ray is not bent and crosses 2r = 1
  // of material, so it keeps exp(-σa·1) of the white environment (the first viewer has no Fresnel).
  ProgramResult r = runProgram(VIEWER_EXE,
                               {"ball.vol.json", "--render", "ball.exr", "--size", "65x65", "--camera",
                                "0,0,4:0,0,0:30", "--env", "uniform:1,1,1", "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image image = readImage(dir / "ball.exr");
  ASSERT_EQ(image.width, 65);
  ASSERT_EQ(image.height, 65);
  const float* centre = image.at(32, 32);
  EXPECT_NEAR(centre[0], 1.0f, 0.01f);
  EXPECT_NEAR(centre[1], std::exp(-0.5f), 0.02f);
  EXPECT_NEAR(centre[2], std::exp(-1.0f), 0.02f);
  const float* corner = image.at(0, 0);  // misses the sphere: the environment itself
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(corner[c], 1.0f, 1e-3f);

  r = runProgram(VIEWER_EXE, {"ball.vol.json", "--render", "ball.png", "--size", "48x32", "--quiet"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Image png = readImage(dir / "ball.png");
  EXPECT_EQ(png.width, 48);
  EXPECT_EQ(png.height, 32);
}

TEST(ViewerCli, BadInputExitsTwo) {
  TempDir dir;
  makeSphere(dir);
  struct Case {
    std::vector<std::string> args;
    const char* expected;
  };
  writeFile(dir / "unknown_key.json", R"({"objects": [{"volume": "ball.vol.json"}], "camera": {"fov": 40}})");
  writeFile(dir / "wrong_type.json", R"({"objects": [{"volume": "ball.vol.json", "scale": "big"}]})");
  writeFile(dir / "no_volume.json", R"({"objects": [{"volume": "missing.vol.json"}]})");
  // A volume without ior_grad.
  Volume v = readVolume(dir / "ball.vol.json");
  v.fields.erase("ior_grad");
  writeVolume(v, dir / "nograd.vol.json");
  const std::vector<Case> cases = {
      {{"unknown_key.json", "--render", "x.png"}, "camera.fov"},
      {{"wrong_type.json", "--render", "x.png"}, "objects[0].scale"},
      {{"no_volume.json", "--render", "x.png"}, "missing.vol.json"},
      {{"nograd.vol.json", "--render", "x.png"}, "ior_grad"},
      {{"ball.vol.json", "--render", "x.png", "--size", "10by10"}, "--size"},
      {{"ball.vol.json", "--render", "x.jpg"}, ".png or .exr"},
      {{"ball.vol.json", "--render", "x.png", "--env", "sky"}, "--env"},
      {{"ball.vol.json", "--render", "x.png", "--camera", "0,0,1:0,0"}, "--camera"},
  };
  for (const Case& c : cases) {
    ProgramResult r = runProgram(VIEWER_EXE, c.args, dir.path());
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << ": " << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
  }
}

}  // namespace
}  // namespace eik::test
