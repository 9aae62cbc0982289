#include "core/scene.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace eik {
namespace {

using nlohmann::json;

const char* kMinimal = R"({
  "camera":      {"eye": [0, 4, 6], "target": [0, 0.8, 0], "up": [0, 1, 0], "fov_y_deg": 40},
  "environment": {"uniform": [0.1, 0.1, 0.1]},
  "lights":      [{"type": "directional", "direction": [0, -2, 0], "irradiance": [1, 1, 1]}],
  "ground":      {"point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.8, 0.8, 0.8], "half_extent": 4},
  "objects":     [{"volume": "sphere.vol.json", "translate": [0, 0, 0], "rotate_deg": [0, 0, 0], "scale": 1}],
  "render":      {"size": [256, 128], "step_voxels": 0.5, "exposure": 0, "tonemap": "aces"}
})";

std::string errorOf(const std::string& text) {
  try {
    sceneFromJson(json::parse(text), "s.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, ParsesTheDesignExample) {
  Scene s = sceneFromJson(json::parse(kMinimal), "s.json");
  EXPECT_DOUBLE_EQ(s.camera.eye.y, 4.0);
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 40.0);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_DOUBLE_EQ(s.lights[0].direction.y, -1.0);  // normalised
  ASSERT_TRUE(s.ground.has_value());
  EXPECT_DOUBLE_EQ(s.ground->half_extent, 4.0);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].volume, "sphere.vol.json");
  EXPECT_EQ(s.render.size, glm::ivec2(256, 128));
  ASSERT_TRUE(s.environment.uniform.has_value());
  EXPECT_DOUBLE_EQ(s.environment.uniform->x, 0.1);
}

TEST(Scene, RoundTripsThroughJson) {
  Scene a = sceneFromJson(json::parse(kMinimal), "s.json");
  Scene b = sceneFromJson(sceneToJson(a), "again.json");
  EXPECT_EQ(sceneToJson(a), sceneToJson(b));
}

TEST(Scene, RejectsUnknownKeysNamingTheField) {
  std::string e = errorOf(R"({"camera": {"eye": [0,0,1], "fovy": 30}})");
  EXPECT_NE(e.find("s.json"), std::string::npos) << e;
  EXPECT_NE(e.find("camera.fovy"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
}

TEST(Scene, RejectsWrongTypes) {
  EXPECT_NE(errorOf(R"({"camera": {"eye": "up there"}})").find("camera.eye"), std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "directional", "direction": [0, 1]}]})").find("lights[0].direction"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "spot"}]})").find("lights[0].type"), std::string::npos);
  EXPECT_NE(errorOf(R"({"render": {"size": [0, 10]}})").find("render.size"), std::string::npos);
  EXPECT_NE(errorOf(R"({"render": {"tonemap": "filmic"}})").find("render.tonemap"), std::string::npos);
  // Integers beyond int are refused, not wrapped (4294967312 became 16); the step as viewer --step.
  EXPECT_NE(errorOf(R"({"render": {"size": [4294967312, 16]}})").find("render.size: has a value out of the integer range"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"render": {"step_voxels": 1e-300}})").find("render.step_voxels"), std::string::npos);
  EXPECT_NE(errorOf(R"({"objects": [{"translate": [0,0,0]}]})").find("objects[0].volume"), std::string::npos);
  EXPECT_NE(errorOf(R"({"objects": [{"volume": "a", "scale": -1}]})").find("objects[0].scale"), std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "directional", "direction": [0,0,0]}]})").find("zero vector"),
            std::string::npos);
  EXPECT_NE(errorOf(R"([1, 2])").find("expected an object"), std::string::npos);
  // Finite as doubles but not as floats (the viewer's uniforms, the bake's fields): refused where
  // read, naming the key; a light's power up to 1e30 (kMaxLightPower).
  EXPECT_NE(errorOf(R"({"camera": {"eye": [0, 0, 1e39]}})").find("camera.eye: beyond the range of a 32-bit float"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "directional", "direction": [0,-1,0], "irradiance": [1e300, 1, 1]}]})")
                .find("lights[0].irradiance"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "point", "position": [0,1,0], "intensity": [1, 1e31, 1]}]})")
                .find("lights[0].intensity: must be at most 1e30"),
            std::string::npos);
  EXPECT_EQ(errorOf(R"({"lights": [{"type": "point", "position": [0,1,0], "intensity": [1, 1e30, 1]}]})"), "");
}

TEST(Scene, EnvironmentKindsAreExclusive) {
  EXPECT_NE(errorOf(R"({"environment": {"uniform": [1,1,1], "file": "a.exr"}})").find("only one"), std::string::npos);
  Scene s = sceneFromJson(json::parse(R"({"environment": {"file": "sky.exr", "intensity": 2}})"), "s.json");
  EXPECT_EQ(s.environment.file, "sky.exr");
  EXPECT_FALSE(s.environment.uniform.has_value());
}

}  // namespace
}  // namespace eik
