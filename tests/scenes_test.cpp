// Every scene in assets/ (issue "The thesis' scenes"): built and rendered the way the demo does it
// (scripts/scene.sh: voxelize, bake, render headless), at 24 voxels and 64x48 pixels, so none of
// them rots. Each must exit 0, bake a light that reaches its volumes, and render a picture with
// something in it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image_io.h"
#include "tests/program_runner.h"

namespace fs = std::filesystem;

namespace eik::test {
namespace {

const fs::path kAssets = fs::path(EIKONAL_SOURCE_DIR) / "assets";

std::vector<std::string> assetScenes() {
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(kAssets))
    if (fs::is_regular_file(entry.path() / "SCENE.json")) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(AssetScenes, ThereAreTheThesisScenes) {
  const std::vector<std::string> names = assetScenes();
  for (const char* name :
       {"amber_bunny", "colored_lights", "glass_sphere", "layered_cube", "logo_block", "museum", "prism",
        "prism_caustic", "sphere_ring", "wine_glass", "wine_glass_point"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
}

TEST(AssetScenes, AnUnknownSceneIsAClearError) {
  TempDir dir;
  ProgramResult r = runProgram("/bin/bash",
                               {(fs::path(EIKONAL_SOURCE_DIR) / "scripts" / "scene.sh").string(), "no_such_scene",
                                "--out", dir.path().string()},
                               dir.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no scene 'no_such_scene'"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir.path() / "no_such_scene"));
}

class AssetScene : public ::testing::TestWithParam<std::string> {};

TEST_P(AssetScene, BuildsBakesAndRendersTiny) {
  const std::string name = GetParam();
  TempDir dir;
  const fs::path build = fs::path(VOXELIZE_EXE).parent_path().parent_path();
  ProgramResult r = runProgram("/bin/bash",
                               {(fs::path(EIKONAL_SOURCE_DIR) / "scripts" / "scene.sh").string(), name, "--out",
                                dir.path().string(), "--res", "24", "--size", "64x48", "--build", build.string(),
                                "--quiet"},
                               dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;

  // Every baked volume the scene renders had light on it.
  const nlohmann::json scene = nlohmann::json::parse(std::ifstream(dir.path() / name / "SCENE.json"));
  for (const nlohmann::json& object : scene.at("objects")) {
    const fs::path volume = dir.path() / name / object.at("volume").get<std::string>();
    ASSERT_TRUE(fs::exists(volume)) << volume;
    const nlohmann::json manifest = nlohmann::json::parse(std::ifstream(volume));
    if (!manifest.contains("bake_stats")) continue;
    EXPECT_GT(manifest["bake_stats"]["flux"]["in"][1].get<double>(), 0.0) << volume << ": the light misses it";
    // Its light is in the volume, or (lightsim --volume-deposits auto: nothing in it reads the
    // volume's light) on the ground's map.
    EXPECT_TRUE(manifest["fields"].contains("irradiance") || !manifest.value("receivers", nlohmann::json()).empty())
        << volume;
  }

  // A 64x48 picture with something in it: not one flat colour, and nothing NaN.
  const Image image = readImage(dir.path() / (name + ".png"));
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 48);
  double sum = 0.0, sum2 = 0.0;
  int count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* p = image.at(x, y);
      const double luminance = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
      ASSERT_TRUE(std::isfinite(luminance));
      sum += luminance;
      sum2 += luminance * luminance;
      ++count;
    }
  const double mean = sum / count, deviation = std::sqrt(std::max(0.0, sum2 / count - mean * mean));
  EXPECT_GT(mean, 0.02) << name << ": the picture is black";
  EXPECT_GT(deviation, 0.02) << name << ": the picture is one flat colour";
  EXPECT_TRUE(fs::exists(dir.path() / name / "times.json"));
}

INSTANTIATE_TEST_SUITE_P(EveryScene, AssetScene, ::testing::ValuesIn(assetScenes()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace eik::test
