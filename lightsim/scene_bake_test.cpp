// The bake frame of a placed object (scene_bake.h): the scene's light and ground carried into the
// volume's axes, the volume's own lengths at world scale, and the bake's maps back. The physics of
// a placed bake is checked against exact optics in exact_optics_test.cpp
// (ExactOpticsSphere.APlacedVolumeBakesTheCausticWhereTheSceneStandsIt).
#include "lightsim/scene_bake.h"

#include <gtest/gtest.h>

#include "core/interfaces.h"
#include "lightsim/test_scenes.h"

namespace eik {
namespace {

SceneObjectSpec placement() {
  SceneObjectSpec object;
  object.translate = {0.4, -1.0, 2.0};
  object.rotate_deg = {10.0, -35.0, 60.0};
  object.scale = 2.5;
  return object;
}

// A light or plane carried into the bake frame and back by world = T + R·p_bake lands where it was:
// the frame is the placement without its scale.
TEST(BakeFrame, CarriesTheLightAndTheGroundIntoTheVolumesAxes) {
  const SceneObjectSpec object = placement();
  const BakeFrame frame = BakeFrame::of(object);
  EXPECT_EQ(frame.scale, 2.5);
  const glm::dmat4 m = objectToWorld(object);
  LightSpec sun;
  sun.direction = glm::normalize(glm::dvec3(0.3, -1.0, -0.35));
  sun.position = {1.0, 5.0, -2.0};
  const LightSpec in_frame = frame.light(sun);
  const glm::dvec3 back = glm::normalize(glm::dmat3(m) * in_frame.direction);  // the scale drops out
  EXPECT_NEAR(glm::length(back - sun.direction), 0.0, 1e-12);
  // A point light's position in the volume's own coordinates, once bakeToVolumeFrame divides it by s.
  BakeResult none;
  LightSpec point = in_frame;
  bakeToVolumeFrame(none, point, frame.scale);
  EXPECT_NEAR(glm::length(glm::dvec3(m * glm::dvec4(point.position, 1.0)) - sun.position), 0.0, 1e-12);
  ReceiverSpec ground;
  ground.point = {0.0, -0.5, 0.0};
  ground.normal = {0.0, 1.0, 0.0};
  ground.half_extent = 3.0;
  const ReceiverSpec plane = frame.receiver(ground);
  EXPECT_EQ(plane.half_extent, 3.0);  // world units in the bake frame
  EXPECT_NEAR(glm::length(frame.origin + frame.rotation * plane.point - ground.point), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(frame.rotation * plane.normal - ground.normal), 0.0, 1e-12);
}

// At world scale the grid's box is s times as large, a signed distance s times as long (and the
// band), ∇n 1/s as steep; n, σa and the rest stay (σa is per world unit already).
TEST(BakeFrame, TheVolumeAtWorldScale) {
  const Volume volume = test_scenes::sharpVolume("procedural:sphere,r=0.5,center=0.1:0:0,ior=1.5,sigma_a=0.3:0.3:0.3", 16);
  const Volume scaled = volumeAtWorldScale(volume, 2.5);
  EXPECT_EQ(scaled.grid.dims, volume.grid.dims);
  EXPECT_NEAR(glm::length(scaled.grid.bounds_min - 2.5 * volume.grid.bounds_min), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(scaled.grid.bounds_max - 2.5 * volume.grid.bounds_max), 0.0, 1e-12);
  EXPECT_NEAR(interfaceTable(scaled).band, 2.5 * interfaceTable(volume).band, 1e-12);
  for (const auto& [name, factor] : std::vector<std::pair<std::string, double>>{
           {"interfaces", 2.5}, {"ior_grad", 1.0 / 2.5}, {"ior", 1.0}, {"sigma_a", 1.0}}) {
    const std::vector<float>& a = volume.fields.at(name).data;
    const std::vector<float>& b = scaled.fields.at(name).data;
    ASSERT_EQ(a.size(), b.size()) << name;
    for (std::size_t i = 0; i < a.size(); i += 97) EXPECT_FLOAT_EQ(b[i], static_cast<float>(a[i] * factor)) << name;
  }
  // A map made in the bake frame, back in the volume's coordinates: lengths ÷ s, irradiance as it is.
  BakeResult result;
  ReceiverMap map;
  map.point = {1.0, -2.5, 0.5};
  map.origin = {-5.0, -4.0};
  map.pitch = 0.05;
  map.irradiance = {1.0f, 2.0f, 3.0f};
  result.receivers.push_back(map);
  LightSpec light;
  bakeToVolumeFrame(result, light, 2.5);
  EXPECT_NEAR(glm::length(result.receivers[0].point - map.point / 2.5), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(result.receivers[0].origin - map.origin / 2.5), 0.0, 1e-12);
  EXPECT_NEAR(result.receivers[0].pitch, 0.02, 1e-15);
  EXPECT_EQ(result.receivers[0].irradiance, map.irradiance);
}

}  // namespace
}  // namespace eik
