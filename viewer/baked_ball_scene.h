// Test-only (header only): the scene of the viewer's re-bake tests (background_bake_test.cpp,
// window_test.cpp): the exact-optics ball over its floor, baked as `lightsim --scene` bakes it.
#pragma once

#include <glm/glm.hpp>

#include "lightsim/bake.h"
#include "lightsim/cpu_simulator.h"
#include "lightsim/test_scenes.h"
#include "viewer/loaded_scene.h"
#include "viewer/window.h"

namespace eik::test_scenes {

// The exact-optics scene (lightsim/exact_optics_test.cpp) at 32³: a sharp glass ball (R = 1,
// n = 1.5) whose lowest point is 0.5 above the floor (y = 0, the receiver, half extent 1.6).
constexpr int kBallRes = 32;

inline SimulationOptions lightsimOptions(const GridSpec& grid) {
  SimulationOptions options;
  const VolumeDefaults defaults = volumeDefaults(true, grid);  // lightsim's, with sharp interfaces
  options.max_depth = defaults.max_depth;
  options.patch_voxels = defaults.patch_voxels;
  options.split_voxels = defaults.split_voxels;
  options.free_flight = true;  // lightsim's default
  ReceiverSpec floor;
  floor.half_extent = 1.6;
  options.receiver = floor;
  return options;
}

inline LightSpec directional(glm::dvec3 direction) {
  LightSpec light;
  light.direction = glm::normalize(direction);
  light.power = glm::dvec3(1.0);
  return light;
}

// A light from azimuth `azimuth_deg` at 60° elevation (the window's sliders).
inline glm::dvec3 sunAt(double azimuth_deg) { return lightDirectionFromAngles(azimuth_deg, 60.0, {0, 1, 0}); }

// The ball baked with `light` as `lightsim --scene` writes it (fields, "light", "bake_options"),
// as a one-object scene with the floor as its ground.
inline LoadedScene bakedScene(const LightSpec& light, int res = kBallRes) {
  Volume volume = test_scenes::sharpVolume("procedural:sphere,r=1,center=0:1.5:0,ior=1.5", res, std::nullopt, 2.0);
  const SimulationOptions options = lightsimOptions(volume.grid);
  CpuSimulator simulator(volume);
  applyBake(volume, simulator.run(light, options), light);
  volume.metadata["bake_options"] = bakeOptionsToJson(options);
  Scene scene;
  scene.objects.push_back({});
  SceneGroundSpec ground;
  ground.half_extent = 1.6;
  scene.ground = ground;
  SceneLightSpec sun;
  sun.direction = light.direction;
  sun.irradiance = light.power;
  scene.lights.push_back(sun);
  return sceneFromVolumes(scene, {std::move(volume)});
}

}  // namespace eik::test_scenes
