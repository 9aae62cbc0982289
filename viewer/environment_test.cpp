// The environment's CPU side: the --env flag, the kinds' radiance (the shader's twin), the diffuse
// radiance a Lambertian surface receives from it, and bad maps.
#include "viewer/environment.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

TEST(EnvironmentFlag, ParsesEveryKind) {
  SceneEnvironmentSpec env;
  applyEnvironmentFlag("uniform:0.5,1,2", env);
  ASSERT_TRUE(env.uniform);
  EXPECT_EQ(*env.uniform, glm::dvec3(0.5, 1, 2));
  EXPECT_TRUE(env.procedural.empty());
  applyEnvironmentFlag("checker", env);
  EXPECT_EQ(env.procedural, "checker");
  EXPECT_EQ(*env.uniform, glm::dvec3(1.0));
  env.intensity = 3;
  applyEnvironmentFlag("sky", env);
  EXPECT_EQ(env.procedural, "sky");
  EXPECT_FALSE(env.uniform);
  EXPECT_EQ(env.intensity, 3) << "the scene's intensity stays";
  applyEnvironmentFlag("maps/studio.exr", env);
  EXPECT_EQ(env.file, "maps/studio.exr");
  EXPECT_TRUE(env.procedural.empty());
  for (const char* bad : {"nebula", "uniform:1,2", "uniform:-1,0,0", "checker:a,b,c", "sky:2", ""})
    EXPECT_THROW(applyEnvironmentFlag(bad, env), InputError) << bad;
}

TEST(Environment, UniformAndCheckerRadiance) {
  SceneEnvironmentSpec spec;
  spec.uniform = glm::dvec3(0.2, 0.4, 0.8);
  spec.intensity = 2;
  const Environment uniform(spec, ".");
  EXPECT_EQ(uniform.kind(), EnvironmentKind::Uniform);
  EXPECT_EQ(uniform.radiance({0, 1, 0}), glm::vec3(0.4f, 0.8f, 1.6f));
  // A Lambertian surface under a uniform sky L has radiance ρL.
  const glm::vec3 diffuse = uniform.diffuseRadiance({0, 1, 0});
  EXPECT_NEAR(diffuse.z, 1.6f, 1e-6f);

  applyEnvironmentFlag("checker:1,1,1", spec);
  const Environment checker(spec, ".");
  EXPECT_EQ(checker.kind(), EnvironmentKind::Checker);
  // Neighbouring cells (15° apart in longitude) alternate between 1 and 0.2.
  const double a = 0.5 * 15.0 * 3.14159265358979 / 180.0;
  const float c1 = checker.radiance({std::cos(a), 0.1, std::sin(a)}).x;
  const float c2 = checker.radiance({std::cos(3 * a), 0.1, std::sin(3 * a)}).x;
  EXPECT_NEAR(std::max(c1, c2), 1.0f, 1e-6f);
  EXPECT_NEAR(std::min(c1, c2), 0.2f, 1e-6f);
  // Half the cells bright: the diffuse radiance is the mean, 0.6.
  EXPECT_NEAR(checker.diffuseRadiance({0, 1, 0}).x, 0.6f, 0.02f);
}

TEST(Environment, RotationTurnsItAboutUp) {
  // rotate_deg = 15 (one checker cell) turns the environment about +y: what was seen along d is
  // then seen along d turned by 15°.
  SceneEnvironmentSpec spec;
  applyEnvironmentFlag("checker:1,1,1", spec);
  const Environment still(spec, ".");
  spec.rotate_deg = 15;
  const Environment turned(spec, ".");
  const double c = std::cos(15 * 3.14159265358979 / 180), s = std::sin(15 * 3.14159265358979 / 180);
  int differ = 0;
  for (int i = 0; i < 64; ++i) {
    const double a = 0.1 + i * 0.097, y = std::sin(i * 0.37) * 0.9;
    const double r = std::sqrt(1 - y * y);
    const glm::dvec3 d(r * std::cos(a), y, r * std::sin(a));
    const glm::dvec3 d_turned(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
    EXPECT_NEAR(turned.radiance(d_turned).x, still.radiance(d).x, 1e-6) << i;
    differ += turned.radiance(d) != still.radiance(d);
  }
  EXPECT_GT(differ, 40) << "turned by one cell, most directions see the other colour";
}

TEST(Environment, SkyIsBrighterAboveAndHasTheSun) {
  SceneEnvironmentSpec spec;
  applyEnvironmentFlag("sky", spec);
  const Environment sky(spec, ".");
  EXPECT_EQ(sky.kind(), EnvironmentKind::Sky);
  const glm::dvec3 light(0, -1, -1);  // travelling down and away: the sun is up and behind (+z)
  const glm::vec3 up = sky.radiance({0, 1, 0}, light, false);
  const glm::vec3 down = sky.radiance({0, -1, 0}, light, false);
  EXPECT_GT(up.z, down.z);
  EXPECT_GT(up.z, up.x) << "blue";
  // Looking at the sun: its disk delivers the light's irradiance, E / solid angle (1° radius).
  const glm::dvec3 to_sun = -glm::normalize(light);
  const double solid_angle = 2 * 3.14159265358979 * (1 - std::cos(3.14159265358979 / 180));
  const glm::vec3 with_sun = sky.radiance(to_sun, light, true, glm::dvec3(2.0));
  const glm::vec3 without = sky.radiance(to_sun, light, false, glm::dvec3(2.0));
  EXPECT_NEAR(with_sun.x - without.x, 2.0 / solid_angle, 1e-3 * 2.0 / solid_angle);
}

TEST(Environment, MapsAreReadAndBadOnesRejected) {
  test_support::TempDir dir;
  Image map;
  map.width = 8;
  map.height = 4;
  map.channels = 3;
  map.pixels.assign(8 * 4 * 3, 0.0f);
  for (int x = 0; x < 8; ++x) map.at(x, 0)[0] = 5.0f;  // the top row: red, straight up
  writeImage(dir.path() / "map.exr", map);
  SceneEnvironmentSpec spec;
  spec.uniform.reset();
  spec.file = "map.exr";
  spec.intensity = 0.5;
  // A good map needs GL to upload (scene_renderer_test: EnvironmentMapIsSeenInvertedThroughABallLens);
  // a bad one fails before.
  SceneEnvironmentSpec missing = spec;
  missing.file = "missing.exr";
  try {
    Environment bad(missing, dir.path(), "scene.json");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("scene.json"), std::string::npos) << what;
    EXPECT_NE(what.find("environment.file"), std::string::npos) << what;
    EXPECT_NE(what.find("missing.exr"), std::string::npos) << what;
  }
  SceneEnvironmentSpec unknown;
  unknown.procedural = "nebula";
  EXPECT_THROW(Environment(unknown, dir.path()), InputError);
  SceneEnvironmentSpec negative;
  negative.intensity = -1;
  EXPECT_THROW(Environment(negative, dir.path()), InputError);
}

}  // namespace
}  // namespace eik
