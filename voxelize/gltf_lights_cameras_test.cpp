// glTF lights and cameras placed by their nodes' world transforms.
#include "voxelize/gltf_lights_cameras.h"

#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/testing.h"
#include "voxelize/scene_export.h"

namespace eik {
namespace {

using test_support::inputErrorOf;

tinygltf::Value lightRef(int index) { return tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(index)}}); }

TEST(GltfLightsCameras, LightsTakeTheNodesPlaceAndDirection) {
  tinygltf::Model model;
  tinygltf::Light spot;
  spot.type = "spot";
  spot.color = {1.0, 0.5, 0.25};
  spot.intensity = 20.0;
  spot.spot.innerConeAngle = 0.1;
  spot.spot.outerConeAngle = 0.4;
  model.lights.push_back(spot);
  tinygltf::Light area;
  area.type = "area";
  model.lights.push_back(area);
  tinygltf::Node node;
  node.name = "lamp";
  // At (1, 2, 3), turned −90° about x: −Z (the light's direction) becomes −Y.
  const glm::dmat4 world = glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(1, 2, 3)), -glm::half_pi<double>(),
                                       glm::dvec3(1, 0, 0));
  std::vector<std::string> warnings;
  const GltfDiagnostics diag{"s.gltf", &warnings};
  const std::optional<SceneLight> light = gltfLight(model, node, lightRef(0), "nodes[4]", world, diag);
  ASSERT_TRUE(light);
  EXPECT_EQ(light->type, SceneLight::Type::Spot);
  EXPECT_EQ(light->name, "lamp") << "unnamed light: the node's name";
  EXPECT_NEAR(glm::length(light->position - glm::dvec3(1, 2, 3)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(light->direction - glm::dvec3(0, -1, 0)), 0.0, 1e-12);
  EXPECT_EQ(light->intensity, 20.0);
  EXPECT_EQ(light->outer_cone_rad, 0.4);

  EXPECT_FALSE(gltfLight(model, node, lightRef(1), "nodes[4]", world, diag));
  EXPECT_EQ(warnings, std::vector<std::string>{"s.gltf: KHR_lights_punctual.lights[1]: type 'area' skipped"});
  EXPECT_EQ(inputErrorOf([&] { gltfLight(model, node, lightRef(2), "nodes[4]", world, diag); }),
            "s.gltf: nodes[4].extensions.KHR_lights_punctual.light: light 2 is not an index of the file's 2 lights");
  // A real beyond int (converting it was undefined behaviour) and a fraction are refused alike.
  for (const double bad : {1e20, -1.0, 0.5}) {
    const tinygltf::Value ref(tinygltf::Value::Object{{"light", tinygltf::Value(bad)}});
    EXPECT_CONTAINS(inputErrorOf([&] { gltfLight(model, node, ref, "nodes[4]", world, diag); }),
                    "is not an index of the file's 2 lights");
  }
  EXPECT_EQ(inputErrorOf([&] { gltfLight(model, node, tinygltf::Value(), "nodes[4]", world, diag); }),
            "s.gltf: nodes[4].extensions.KHR_lights_punctual.light: missing or not a number");
}

TEST(GltfLightsCameras, CamerasLookAlongMinusZ) {
  tinygltf::Node node;
  node.camera = 0;
  tinygltf::Model model;
  model.cameras.resize(2);
  model.cameras[0].type = "perspective";
  model.cameras[0].name = "main";
  model.cameras[0].perspective.yfov = glm::radians(40.0);
  model.cameras[1].type = "orthographic";
  std::vector<std::string> warnings;
  const GltfDiagnostics diag{"s.gltf", &warnings};
  // Scaled non-uniformly: the up vector is orthonormalised.
  const glm::dmat4 world = glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 4)), glm::dvec3(1, 3, 2));
  const std::optional<SceneCamera> cam = gltfCamera(model, node, "nodes[2]", world, diag);
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->name, "main");
  EXPECT_EQ(cam->eye, glm::dvec3(0, 0, 4));
  EXPECT_EQ(cam->target, glm::dvec3(0, 0, 3));
  EXPECT_EQ(cam->up, glm::dvec3(0, 1, 0));
  EXPECT_NEAR(cam->fov_y_deg, 40.0, 1e-12);

  node.camera = 1;
  EXPECT_FALSE(gltfCamera(model, node, "nodes[2]", world, diag));
  EXPECT_EQ(warnings, std::vector<std::string>{"s.gltf: cameras[1]: orthographic camera skipped"});
  node.camera = 0;
  EXPECT_EQ(inputErrorOf([&] { gltfCamera(model, node, "nodes[2]", glm::dmat4(0.0), diag); }),
            "s.gltf: nodes[2]: camera transform is singular");
  node.camera = 7;
  EXPECT_EQ(inputErrorOf([&] { gltfCamera(model, node, "nodes[2]", world, diag); }),
            "s.gltf: nodes[2].camera: camera 7 out of range (the file has 2 cameras)");
}

// A glTF spot light goes into the scene as a spot (docs/programs.md "Lights and cameras"): its
// axis, its cone in degrees, its candela as W/sr at 683 lm/W, and no warning.
TEST(GltfLightsCameras, ASpotLightIsExportedWithItsCone) {
  MeshScene in;
  SceneLight spot;
  spot.type = SceneLight::Type::Spot;
  spot.name = "lamp";
  spot.position = {1.0, 2.0, 3.0};
  spot.direction = {0.0, -1.0, 0.0};
  spot.color = {1.0, 0.5, 0.25};
  spot.intensity = 683.0;
  spot.inner_cone_rad = 0.1;
  spot.outer_cone_rad = 0.4;
  in.lights.push_back(spot);
  GridSpec grid;
  grid.dims = {8, 8, 8};
  grid.bounds_max = glm::dvec3(1.0);
  const SceneExport out = exportScene({in}, "lamp.vol.json", grid);
  ASSERT_EQ(out.scene.lights.size(), 1u);
  const SceneLightSpec& l = out.scene.lights[0];
  EXPECT_EQ(l.type, SceneLightSpec::Type::Spot);
  EXPECT_EQ(l.position, glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_EQ(l.direction, glm::dvec3(0.0, -1.0, 0.0));
  EXPECT_NEAR(l.inner_cone_deg, glm::degrees(0.1), 1e-12);
  EXPECT_NEAR(l.outer_cone_deg, glm::degrees(0.4), 1e-12);
  EXPECT_NEAR(glm::length(l.intensity - glm::dvec3(1.0, 0.5, 0.25)), 0.0, 1e-12);
  EXPECT_TRUE(out.warnings.empty());
}

}  // namespace
}  // namespace eik
