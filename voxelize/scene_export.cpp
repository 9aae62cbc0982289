#include "voxelize/scene_export.h"

#include <algorithm>
#include <cmath>

namespace eik {

glm::dvec3 irradianceFromLux(const glm::dvec3& color, double lux) { return color * (lux / kLumensPerWatt); }

glm::dvec3 radiantIntensityFromCandela(const glm::dvec3& color, double candela) {
  return color * (candela / kLumensPerWatt);
}

SceneExport exportScene(const std::vector<MeshScene>& inputs, const std::filesystem::path& manifest,
                        const GridSpec& grid) {
  SceneExport out;
  Scene& scene = out.scene;
  const glm::dvec3 center = 0.5 * (grid.bounds_min + grid.bounds_max);
  const double radius = 0.5 * glm::length(grid.extent());

  // Default camera: looks at the volume from the front and a little above, the whole box in view.
  scene.camera.target = center;
  scene.camera.fov_y_deg = 40.0;
  const double distance = radius / std::sin(glm::radians(scene.camera.fov_y_deg) * 0.5) * 1.05;
  scene.camera.eye = center + distance * glm::normalize(glm::dvec3(0.0, 0.45, 1.0));
  scene.camera.up = {0.0, 1.0, 0.0};

  bool have_camera = false;
  for (const MeshScene& in : inputs) {
    for (const auto& cam : in.cameras) {
      out.from_gltf = true;
      if (have_camera) {
        out.warnings.push_back("camera '" + cam.name + "' ignored: a scene has one camera");
        continue;
      }
      scene.camera.eye = cam.eye;
      scene.camera.target = cam.target;
      scene.camera.up = cam.up;
      scene.camera.fov_y_deg = cam.fov_y_deg;
      have_camera = true;
    }
    for (const auto& light : in.lights) {
      out.from_gltf = true;
      SceneLightSpec l;
      if (light.type == SceneLight::Type::Directional) {
        l.type = SceneLightSpec::Type::Directional;
        l.direction = glm::normalize(light.direction);
        l.irradiance = irradianceFromLux(light.color, light.intensity);
      } else {
        l.type = light.type == SceneLight::Type::Spot ? SceneLightSpec::Type::Spot : SceneLightSpec::Type::Point;
        l.position = light.position;
        l.intensity = radiantIntensityFromCandela(light.color, light.intensity);
        if (light.type == SceneLight::Type::Spot) {
          // The cone as glTF gives it (radians), kept valid for the scene file: 0 ≤ inner < outer ≤ 90°.
          l.direction = glm::normalize(light.direction);
          l.outer_cone_deg = std::clamp(glm::degrees(light.outer_cone_rad), 1e-3, 90.0);
          l.inner_cone_deg = std::clamp(glm::degrees(light.inner_cone_rad), 0.0, 0.999 * l.outer_cone_deg);
        }
      }
      scene.lights.push_back(l);
    }
  }
  if (scene.lights.empty()) {
    SceneLightSpec l;
    l.type = SceneLightSpec::Type::Directional;
    l.direction = {0.0, -1.0, 0.0};
    l.irradiance = glm::dvec3(1.0);
    scene.lights.push_back(l);
  }
  SceneObjectSpec object;
  object.volume = manifest.filename().string();
  scene.objects.push_back(object);
  return out;
}

}  // namespace eik
