// Loading what the viewer renders: a SCENE.json with its volumes, or a bare volume framed by the
// camera; placements as matrices; bad input named by file and field.
#include "viewer/loaded_scene.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

Volume tinyVolume(bool with_grad = true) {
  Volume v;
  v.grid.dims = glm::ivec3(4);
  v.grid.bounds_min = glm::dvec3(-1, 0, -1);
  v.grid.bounds_max = glm::dvec3(1, 2, 1);
  Field& ior = v.addField("ior", 1);
  std::fill(ior.data.begin(), ior.data.end(), 1.5f);
  if (with_grad) v.addField("ior_grad", 3);
  return v;
}

TEST(LoadedScene, PlacementIsTranslateRotateScale) {
  SceneObjectSpec o;
  o.translate = glm::dvec3(1, 2, 3);
  o.rotate_deg = glm::dvec3(0, 90, 0);
  o.scale = glm::dvec3(2.0);
  const glm::dvec4 p = objectToWorld(o) * glm::dvec4(1, 0, 0, 1);
  // x → scaled to 2 → turned 90° about y to −z → moved.
  EXPECT_NEAR(p.x, 1, 1e-12);
  EXPECT_NEAR(p.y, 2, 1e-12);
  EXPECT_NEAR(p.z, 1, 1e-12);
}

TEST(LoadedScene, BareVolumeIsFramedAndLitByItsBake) {
  test_support::TempDir dir;
  Volume v = tinyVolume();
  v.metadata["light"] = {{"type", "directional"}, {"direction", {0, 0, -2}}, {"irradiance", {3, 3, 3}}};
  writeVolume(v, dir.path() / "glass.vol.json");
  const LoadedScene scene = loadScene(dir.path() / "glass.vol.json");
  EXPECT_TRUE(scene.bare_volume);
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].object_to_world, glm::dmat4(1.0));
  // The camera looks at the box's centre from far enough to see all of it.
  const Camera camera = scene.camera();
  EXPECT_EQ(camera.target, glm::dvec3(0, 1, 0));
  const double distance = glm::length(camera.eye - camera.target);
  EXPECT_GT(std::sin(camera.fov_y_deg / 2 * 3.14159265358979 / 180) * distance, std::sqrt(3.0) - 1e-9);
  ASSERT_EQ(scene.scene.lights.size(), 1u);
  EXPECT_EQ(scene.scene.lights[0].direction, glm::dvec3(0, 0, -1));
  EXPECT_EQ(scene.scene.lights[0].irradiance, glm::dvec3(3.0));
  ASSERT_TRUE(scene.scene.environment.uniform);
  EXPECT_EQ(*scene.scene.environment.uniform, glm::dvec3(1.0));
}

TEST(LoadedScene, SceneFileWithSeveralObjects) {
  test_support::TempDir dir;
  writeVolume(tinyVolume(), dir.path() / "a.vol.json");
  test_support::writeFile(dir.path() / "scene.json", R"({
    "objects": [{"volume": "a.vol.json"}, {"volume": "a.vol.json", "translate": [3, 0, 0], "scale": 0.5}],
    "ground": {"point": [0, 0, 0], "normal": [0, 1, 0], "albedo": [0.5, 0.5, 0.5], "half_extent": 2}
  })");
  const LoadedScene scene = loadScene(dir.path() / "scene.json");
  EXPECT_FALSE(scene.bare_volume);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(glm::dvec3(scene.objects[1].object_to_world[3]), glm::dvec3(3, 0, 0));
  EXPECT_EQ(scene.objects[1].object_to_world[0][0], 0.5);
  ASSERT_TRUE(scene.scene.ground);
}

TEST(LoadedScene, BadInputNamesTheFileAndField) {
  test_support::TempDir dir;
  writeVolume(tinyVolume(false), dir.path() / "nograd.vol.json");
  writeVolume(tinyVolume(), dir.path() / "a.vol.json");
  test_support::writeFile(dir.path() / "empty.json", R"({"objects": []})");
  test_support::writeFile(dir.path() / "typo.json", R"({"objects": [{"volume": "a.vol.json", "scael": 2}]})");
  struct Case {
    const char* file;
    const char* expected;
  };
  for (const Case& c : {Case{"nograd.vol.json", "ior_grad"}, Case{"empty.json", "objects"},
                        Case{"typo.json", "scael"}, Case{"missing.json", "missing.json"}}) {
    try {
      loadScene(dir.path() / c.file);
      ADD_FAILURE() << c.file << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace eik
