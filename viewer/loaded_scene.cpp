#include "viewer/loaded_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "core/interfaces.h"
#include "lightsim/scene_bake.h"

namespace eik {
namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A receiver map a volume was baked with that cannot follow the scene's uneven scale (its plane
// would need a rectangular lattice): the ground under that object shows the direct light only.
void warnMapLeftOut(const std::string& source, const std::string& map) {
  std::fprintf(stderr,
               "viewer: %s: its receiver map '%s' cannot follow a scale that differs along its plane: left out "
               "(bake the scene with lightsim SCENE.json to light the ground)\n",
               source.c_str(), map.c_str());
}

// The viewer needs n and ∇n (Eq. 5.11/5.12) — in a volume of sharp constant-n materials either may
// have been left unread (SceneLoadOptions) and ∇n left out as 0 throughout (core/interfaces.h
// refractiveIndex, iorGradient); every other field is optional.
void requireOptics(const Volume& volume, const std::string& source) {
  const InterfaceTable table = interfaceTable(volume, source);
  refractiveIndex(volume, table, source);
  iorGradient(volume, table, source);
}

// How to read a volume: with SceneLoadOptions::leave_constant_optics_unread, a volume of sharp
// constant-n materials (its manifest's interface table says so) without n and ∇n.
Volume readOptics(const std::filesystem::path& path, const SceneLoadOptions& options) {
  VolumeReadOptions read;
  if (options.leave_constant_optics_unread) {
    const Volume header = readVolumeHeader(path);
    if (constantSlots(interfaceTable(header, path.string())))
      for (const char* field : {"ior", "ior_grad"})
        if (header.has(field)) read.leave_unread.push_back(field);
  }
  return readVolume(path, read);
}

// The lights a bare volume was baked with (lightsim's "lights" manifest entry when it summed
// several, else its "light"), those that parse.
std::vector<SceneLightSpec> bakedLights(const Volume& volume) {
  std::vector<SceneLightSpec> lights;
  std::vector<nlohmann::json> entries;
  if (const auto all = volume.metadata.find("lights"); all != volume.metadata.end() && all->is_array())
    entries.assign(all->begin(), all->end());
  else if (const auto one = volume.metadata.find("light"); one != volume.metadata.end())
    entries.push_back(*one);
  for (const nlohmann::json& j : entries) {
    if (!j.is_object()) continue;
    try {
      const std::string type = j.value("type", std::string());
      auto vec = [&](const char* key, glm::dvec3 fallback) {
        if (!j.contains(key) || !j.at(key).is_array() || j.at(key).size() != 3) return fallback;
        return glm::dvec3(j.at(key)[0].get<double>(), j.at(key)[1].get<double>(), j.at(key)[2].get<double>());
      };
      SceneLightSpec light;
      if (type == "directional") {
        light.type = SceneLightSpec::Type::Directional;
        light.direction = vec("direction", light.direction);
        if (glm::length(light.direction) > 0) light.direction = glm::normalize(light.direction);
        light.irradiance = vec("irradiance", light.irradiance);
        lights.push_back(light);
      } else if (type == "point" || type == "spot") {
        light.type = type == "spot" ? SceneLightSpec::Type::Spot : SceneLightSpec::Type::Point;
        light.position = vec("position", light.position);
        light.intensity = vec("intensity", light.intensity);
        if (type == "spot") {
          light.direction = vec("direction", light.direction);
          if (glm::length(light.direction) > 0) light.direction = glm::normalize(light.direction);
          light.inner_cone_deg = j.value("inner_cone_deg", light.inner_cone_deg);
          light.outer_cone_deg = j.value("outer_cone_deg", light.outer_cone_deg);
        }
        lights.push_back(light);
      }
    } catch (const nlohmann::json::exception&) {
      // metadata is informative here; a malformed entry only loses that light on the ground
    }
  }
  return lights;
}

}  // namespace

SceneCameraSpec framingCamera(const GridSpec& grid, double fov_y_deg) {
  SceneCameraSpec camera;
  const glm::dvec3 center = 0.5 * (grid.bounds_min + grid.bounds_max);
  const double radius = 0.5 * glm::length(grid.extent());
  camera.target = center;
  camera.eye = center + glm::dvec3(0.0, 0.35, 1.0) * (radius / std::sin(glm::radians(fov_y_deg / 2)));
  camera.fov_y_deg = fov_y_deg;
  return camera;
}

LoadedScene sceneFromVolume(Volume volume, const std::string& source) {
  requireOptics(volume, source);
  LoadedScene loaded;
  loaded.bare_volume = true;
  loaded.source = source;
  loaded.scene.camera = framingCamera(volume.grid);
  loaded.scene.environment.uniform = glm::dvec3(1.0);
  loaded.scene.lights = bakedLights(volume);
  loaded.scene.render.size = glm::ivec2(512, 512);
  loaded.scene.objects.push_back(SceneObjectSpec{source});
  LoadedObject object;
  object.source = source;
  object.volume = std::move(volume);
  loaded.objects.push_back(std::move(object));
  return loaded;
}

LoadedScene sceneFromVolumes(Scene scene, std::vector<Volume> volumes) {
  if (volumes.size() != scene.objects.size())
    throw InputError("scene", "objects", "expected one volume per object");
  if (scene.objects.empty()) throw InputError("scene", "objects", "the scene has no object");
  LoadedScene loaded;
  loaded.source = "scene";
  for (std::size_t i = 0; i < volumes.size(); ++i) {
    LoadedObject object;
    object.source = scene.objects[i].volume.empty() ? "objects[" + std::to_string(i) + "]" : scene.objects[i].volume;
    requireOptics(volumes[i], object.source);
    object.volume = std::move(volumes[i]);
    takeInAxisScale(object.volume, scene.objects[i], [&](const std::string& map) { warnMapLeftOut(object.source, map); });
    object.object_to_world = objectToWorld(scene.objects[i]);
    loaded.objects.push_back(std::move(object));
  }
  loaded.scene = std::move(scene);
  return loaded;
}

LoadedScene loadScene(const std::filesystem::path& input) { return loadScene(input, SceneLoadOptions{}); }

LoadedScene loadScene(const std::filesystem::path& input, const SceneLoadOptions& options) {
  const std::string text = input.string();
  if (endsWith(text, ".vol.json")) return sceneFromVolume(readOptics(input, options), text);
  LoadedScene loaded;
  loaded.source = text;
  loaded.scene = readScene(input);
  // Resolved paths are made absolute here, once: a relative one (a scene given as
  // sub/SCENE.json) would be taken relative to the scene's folder again by whoever opens it.
  SceneEnvironmentSpec& environment = loaded.scene.environment;
  if (!environment.file.empty())
    environment.file = std::filesystem::absolute(loaded.scene.resolve("environment.file", environment.file)).string();
  if (loaded.scene.objects.empty()) throw InputError(text, "objects", "the scene has no object");
  for (std::size_t i = 0; i < loaded.scene.objects.size(); ++i) {
    SceneObjectSpec& spec = loaded.scene.objects[i];
    LoadedObject object;
    object.source =
        std::filesystem::absolute(loaded.scene.resolve("objects[" + std::to_string(i) + "].volume", spec.volume)).string();
    object.volume = readOptics(object.source, options);
    requireOptics(object.volume, object.source);
    // Scaled differently along its axes: the volume at world scale along each axis, placed with
    // scale 1, as lightsim bakes it (lightsim/scene_bake.h).
    takeInAxisScale(object.volume, spec, [&](const std::string& map) { warnMapLeftOut(object.source, map); });
    object.object_to_world = objectToWorld(spec);
    loaded.objects.push_back(std::move(object));
  }
  return loaded;
}

}  // namespace eik
