#include "core/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

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
  EXPECT_NE(errorOf(R"({"lights": [{"type": "area"}]})").find("lights[0].type"), std::string::npos);
  // A spot light needs its position and axis, and a cone 0 ≤ inner < outer ≤ 90°; only it has one.
  EXPECT_NE(errorOf(R"({"lights": [{"type": "spot", "direction": [0, -1, 0]}]})").find("lights[0].position"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "spot", "position": [0, 1, 0]}]})").find("lights[0].direction"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0],
                                    "outer_cone_deg": 95}]})")
                .find("lights[0].outer_cone_deg"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0],
                                    "inner_cone_deg": 30, "outer_cone_deg": 20}]})")
                .find("lights[0].inner_cone_deg"),
            std::string::npos);
  EXPECT_NE(errorOf(R"({"lights": [{"type": "point", "position": [0, 1, 0], "outer_cone_deg": 20}]})")
                .find("only a spot light has a cone"),
            std::string::npos);
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

// A spot light (glTF KHR_lights_punctual's cone) reads and writes back as it was; its attenuation is
// 1 within the inner cone, 0 beyond the outer one, and ((cos θ − cos θo)/(cos θi − cos θo))² between.
TEST(Scene, ASpotLightRoundTripsWithItsCone) {
  const Scene scene = sceneFromJson(nlohmann::json::parse(R"({"lights": [{"type": "spot", "position": [0, 2, 0],
      "direction": [0, -1, 0], "intensity": [3, 3, 3], "inner_cone_deg": 20, "outer_cone_deg": 30}]})"),
                                    "test");
  ASSERT_EQ(scene.lights.size(), 1u);
  const SceneLightSpec& l = scene.lights[0];
  EXPECT_EQ(l.type, SceneLightSpec::Type::Spot);
  EXPECT_EQ(l.inner_cone_deg, 20.0);
  EXPECT_EQ(l.outer_cone_deg, 30.0);
  const Scene back = sceneFromJson(sceneToJson(scene), "back");
  EXPECT_EQ(back.lights.at(0).type, SceneLightSpec::Type::Spot);
  EXPECT_EQ(back.lights.at(0).outer_cone_deg, 30.0);
  EXPECT_EQ(back.lights.at(0).direction, l.direction);
  const double ci = std::cos(20.0 * std::numbers::pi / 180.0), co = std::cos(30.0 * std::numbers::pi / 180.0);
  EXPECT_EQ(spotAttenuation(std::cos(10.0 * std::numbers::pi / 180.0), ci, co), 1.0);
  EXPECT_EQ(spotAttenuation(std::cos(31.0 * std::numbers::pi / 180.0), ci, co), 0.0);
  const double mid = std::cos(25.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(spotAttenuation(mid, ci, co), ((mid - co) / (ci - co)) * ((mid - co) / (ci - co)), 1e-15);
}

// The sun's angular size round-trips; only a directional light has one, within [0, 20]°.
TEST(Scene, ASunsAngularDiameterRoundTrips) {
  const Scene scene = sceneFromJson(nlohmann::json::parse(R"({"lights": [{"type": "directional",
      "direction": [0, -1, 0], "irradiance": [3, 3, 3], "angular_diameter_deg": 0.53}]})"),
                                    "test");
  EXPECT_EQ(scene.lights.at(0).angular_diameter_deg, 0.53);
  EXPECT_EQ(sceneFromJson(sceneToJson(scene), "back").lights.at(0).angular_diameter_deg, 0.53);
  EXPECT_FALSE(sceneToJson(sceneFromJson(nlohmann::json::parse(R"({"lights": [{"type": "directional",
      "direction": [0, -1, 0]}]})"), "test"))["lights"][0].contains("angular_diameter_deg"));
  for (const char* bad : {R"({"lights": [{"type": "directional", "direction": [0, -1, 0], "angular_diameter_deg": -1}]})",
                          R"({"lights": [{"type": "directional", "direction": [0, -1, 0], "angular_diameter_deg": 21}]})",
                          R"({"lights": [{"type": "point", "position": [0, 1, 0], "angular_diameter_deg": 1}]})"})
    EXPECT_THROW(sceneFromJson(nlohmann::json::parse(bad), "test"), InputError) << bad;
}

TEST(Scene, APointLightsRadiusRoundTrips) {
  const Scene scene = sceneFromJson(nlohmann::json::parse(R"({"lights": [{"type": "point", "position": [0, 3, 0],
      "radius": 0.25}, {"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0], "radius": 0.5}]})"),
                                    "test");
  EXPECT_EQ(scene.lights.at(0).radius, 0.25);
  EXPECT_EQ(scene.lights.at(1).radius, 0.5);
  const Scene back = sceneFromJson(sceneToJson(scene), "back");
  EXPECT_EQ(back.lights.at(0).radius, 0.25);
  EXPECT_EQ(back.lights.at(1).radius, 0.5);
  EXPECT_FALSE(sceneToJson(sceneFromJson(nlohmann::json::parse(R"({"lights": [{"type": "point",
      "position": [0, 1, 0]}]})"), "test"))["lights"][0].contains("radius"));
  for (const char* bad : {R"({"lights": [{"type": "point", "position": [0, 1, 0], "radius": -1}]})",
                          R"({"lights": [{"type": "point", "position": [0, 1, 0], "radius": 2000}]})",
                          R"({"lights": [{"type": "directional", "direction": [0, -1, 0], "radius": 1}]})"})
    EXPECT_THROW(sceneFromJson(nlohmann::json::parse(bad), "test"), InputError) << bad;
}

// An object's scale: one number (uniform, written back as one) or [x, y, z] along the volume's own
// axes, which objectToWorld applies before the turn.
TEST(Scene, AnObjectsScaleAlongItsAxesRoundTrips) {
  const Scene scene = sceneFromJson(nlohmann::json::parse(R"({"objects": [{"volume": "a", "scale": 2},
      {"volume": "b", "scale": [1.5, 0.75, 1.2], "rotate_deg": [0, 90, 0]}]})"),
                                    "test");
  EXPECT_TRUE(scene.objects[0].uniformScale());
  EXPECT_EQ(scene.objects[0].scale, glm::dvec3(2.0));
  EXPECT_FALSE(scene.objects[1].uniformScale());
  EXPECT_EQ(scene.objects[1].scale, glm::dvec3(1.5, 0.75, 1.2));
  const nlohmann::json j = sceneToJson(scene);
  EXPECT_TRUE(j["objects"][0]["scale"].is_number());
  EXPECT_TRUE(j["objects"][1]["scale"].is_array());
  EXPECT_EQ(sceneFromJson(j, "back").objects[1].scale, glm::dvec3(1.5, 0.75, 1.2));
  // The volume's x (scaled 1.5) turned 90° about y lies along world −z.
  const glm::dvec3 x = glm::dmat3(objectToWorld(scene.objects[1])) * glm::dvec3(1.0, 0.0, 0.0);
  EXPECT_NEAR(glm::length(x - glm::dvec3(0.0, 0.0, -1.5)), 0.0, 1e-12);
  const glm::dvec3 y = glm::dmat3(objectToWorld(scene.objects[1])) * glm::dvec3(0.0, 1.0, 0.0);
  EXPECT_NEAR(glm::length(y - glm::dvec3(0.0, 0.75, 0.0)), 0.0, 1e-12);
  for (const char* bad : {R"({"objects": [{"volume": "a", "scale": [1, 0, 1]}]})",
                          R"({"objects": [{"volume": "a", "scale": [1, 2]}]})",
                          R"({"objects": [{"volume": "a", "scale": "big"}]})"}) {
    EXPECT_THROW(sceneFromJson(nlohmann::json::parse(bad), "test"), InputError) << bad;
    try {
      sceneFromJson(nlohmann::json::parse(bad), "test");
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("objects[0].scale"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace eik
