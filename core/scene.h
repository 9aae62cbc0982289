// SCENE.json: volumes placed in a world, with lights, camera, environment, ground and render
// settings (docs/scene-format.md). Read strictly: wrong types and unknown keys are InputErrors (exit 2).
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace eik {

struct SceneCameraSpec {
  glm::dvec3 eye{0.0, 4.0, 6.0};
  glm::dvec3 target{0.0, 0.8, 0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fov_y_deg = 40.0;
};

struct SceneLightSpec {
  enum class Type { Directional, Point, Spot };
  Type type = Type::Directional;
  glm::dvec3 direction{0.0, -1.0, 0.0};   // directional: direction the light travels; spot: its axis (unit)
  glm::dvec3 irradiance{1.0};             // directional: W/m² on a plane facing the light, RGB
  glm::dvec3 position{0.0};               // point, spot
  glm::dvec3 intensity{1.0};              // point, spot (on its axis): radiant intensity W/sr, RGB
  double inner_cone_deg = 0.0;            // spot: full intensity within this angle of the axis
  double outer_cone_deg = 45.0;           // spot: none beyond it (glTF KHR_lights_punctual's defaults)
  // directional: the angle the light's disc spans (the sun's 0.53°; 0: a point at infinity, sharp
  // shadows). Its irradiance comes evenly from the disc: soft shadows (lightsim/sun_disc.h).
  double angular_diameter_deg = 0.0;
  // point, spot: the radius of the ball that shines (0: a point, sharp shadows). Its light comes
  // evenly from the disc it shows every receiver: soft shadows (lightsim/sun_disc.h).
  double radius = 0.0;
};
// The largest angular diameter a directional light may have (degrees).
constexpr double kMaxAngularDiameterDeg = 20.0;
// The largest radius a point or spot light may have (world units).
constexpr double kMaxLightRadius = 1e3;

// A spot light's intensity off its axis, as a fraction of the axis' (glTF KHR_lights_punctual):
// ((cos θ − cos θ_outer)/(cos θ_inner − cos θ_outer))² clamped to [0, 1], θ the angle between the
// axis and the direction the light leaves in (the difference of the cosines at least 10⁻³).
inline double spotAttenuation(double cos_theta, double cos_inner, double cos_outer) {
  const double t = (cos_theta - cos_outer) / std::max(1e-3, cos_inner - cos_outer);
  const double c = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  return c * c;
}

// The same cone as the viewer's shaders take it: (axis, cos θ_outer) and 1/(cos θ_inner − cos θ_outer)
// (at most 10³), the attenuation then clamp((axis·d − cos θ_outer)·scale, 0, 1)².
struct SpotCone {
  glm::dvec4 axis_cos_outer{0.0};
  double scale = 0.0;
};
inline SpotCone spotCone(const glm::dvec3& axis, double inner_cone_deg, double outer_cone_deg) {
  const double cos_inner = std::cos(inner_cone_deg * 3.14159265358979323846 / 180.0);
  const double cos_outer = std::cos(outer_cone_deg * 3.14159265358979323846 / 180.0);
  const double len = std::sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
  return {glm::dvec4(len > 0.0 ? axis / len : axis, cos_outer), 1.0 / std::max(1e-3, cos_inner - cos_outer)};
}

struct SceneEnvironmentSpec {
  std::optional<glm::dvec3> uniform = glm::dvec3(0.1);   // uniform radiance, or
  std::string file;                                      // an equirectangular map (path as written)
  double intensity = 1.0;
  double rotate_deg = 0.0;
  std::string procedural;                                // e.g. "sky" (viewer issue)
};

struct SceneGroundSpec {
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0, 1.0, 0.0};
  glm::dvec3 albedo{0.8};
  double half_extent = 4.0;
};

struct SceneObjectSpec {
  std::string volume;                  // path as written in the file (relative to the scene file)
  glm::dvec3 translate{0.0};
  glm::dvec3 rotate_deg{0.0};          // XYZ Euler angles in degrees, applied X then Y then Z
  glm::dvec3 scale{1.0};               // along the volume's own x, y, z (one number in the file when equal)

  bool uniformScale() const { return scale.x == scale.y && scale.y == scale.z; }
};

struct SceneRenderSpec {
  glm::ivec2 size{256, 256};
  double step_voxels = 0.5;
  double exposure = 0.0;               // EV
  std::string tonemap = "aces";        // aces | reinhard | linear
};

struct Scene {
  SceneCameraSpec camera;
  SceneEnvironmentSpec environment;
  std::vector<SceneLightSpec> lights;
  std::optional<SceneGroundSpec> ground;
  std::vector<SceneObjectSpec> objects;
  SceneRenderSpec render;
  std::filesystem::path base_dir;      // directory the scene was read from (for relative paths)
  std::filesystem::path file;          // the SCENE.json it was read from (empty when built in memory)

  // The path of an object's volume or the environment file, `named` as the scene's `key` names it.
  // For a scene read from a file it must lie inside that file's folder (core/paths.h): otherwise
  // InputError naming the key.
  std::filesystem::path resolve(const std::string& key, const std::string& named) const;
};

// Where an object's volume lies in the world: translate · Rz · Ry · Rx · scale (docs/scene-format.md
// "Placement of an object").
glm::dmat4 objectToWorld(const SceneObjectSpec& object);

// Parses and validates; `source` names the file in messages ("scene.json: lights[0].direction: ...").
Scene sceneFromJson(const nlohmann::json& j, const std::string& source);
Scene readScene(const std::filesystem::path& file);
nlohmann::json sceneToJson(const Scene& scene);
void writeScene(const Scene& scene, const std::filesystem::path& file);

// Photometric to radiometric conversion used for glTF lights (KHR_lights_punctual): directional
// intensity is in lux and point intensity in candela; 683 lm/W (Blender writes 683 lux for 1 W/m²).
constexpr double kLumensPerWatt = 683.0;

}  // namespace eik
