#include "voxelize/gltf_lights_cameras.h"

#include <cmath>
#include <cstdio>

#include <tiny_gltf.h>

#include <cstddef>
#include <string>

namespace eik {

namespace {
// A JSON number as written: integers without a fraction, others with %g.
std::string numberText(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}
}  // namespace

std::optional<SceneLight> gltfLight(const tinygltf::Model& model, const tinygltf::Node& node, const tinygltf::Value& ext,
                                    const std::string& field, const glm::dmat4& world, const GltfDiagnostics& diag) {
  const std::string lfield = field + ".extensions.KHR_lights_punctual.light";
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
    diag.fail(lfield, "missing or not a number");
  // Range-checked as a double first: GetNumberAsInt converts a real such as 1e20 to int, which is
  // undefined behaviour.
  const double number = ext.Get("light").GetNumberAsDouble();
  if (!(number >= 0.0 && number < static_cast<double>(model.lights.size())) || number != std::floor(number))
    diag.fail(lfield, "light " + numberText(number) + " is not an index of the file's " + str(model.lights.size()) + " lights");
  const int index = static_cast<int>(number);
  const tinygltf::Light& l = model.lights[static_cast<std::size_t>(index)];
  SceneLight light;
  if (l.type == "directional") light.type = SceneLight::Type::Directional;
  else if (l.type == "point") light.type = SceneLight::Type::Point;
  else if (l.type == "spot") light.type = SceneLight::Type::Spot;
  else {
    diag.warn(indexed("KHR_lights_punctual.lights", static_cast<std::size_t>(index)) + ": type '" + l.type +
              "' skipped");
    return std::nullopt;
  }
  light.name = !l.name.empty() ? l.name : !node.name.empty() ? node.name : indexed("light", static_cast<std::size_t>(index));
  light.position = glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
  glm::dvec3 dir = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
  light.direction = glm::length(dir) > 0.0 ? glm::normalize(dir) : glm::dvec3(0.0, 0.0, -1.0);
  if (l.color.size() == 3) light.color = {l.color[0], l.color[1], l.color[2]};
  light.intensity = l.intensity;
  light.range = l.range;
  light.inner_cone_rad = l.spot.innerConeAngle;
  light.outer_cone_rad = l.spot.outerConeAngle;
  return light;
}

std::optional<SceneCamera> gltfCamera(const tinygltf::Model& model, const tinygltf::Node& node, const std::string& field,
                                      const glm::dmat4& world, const GltfDiagnostics& diag) {
  if (static_cast<std::size_t>(node.camera) >= model.cameras.size())
    diag.fail(field + ".camera", "camera " + str(node.camera) + " out of range (the file has " +
                                       str(model.cameras.size()) + " cameras)");
  const tinygltf::Camera& c = model.cameras[static_cast<std::size_t>(node.camera)];
  if (c.type != "perspective") {
    diag.warn(indexed("cameras", static_cast<std::size_t>(node.camera)) + ": " + c.type + " camera skipped");
    return std::nullopt;
  }
  SceneCamera cam;
  cam.name = !c.name.empty() ? c.name : !node.name.empty() ? node.name : indexed("camera", static_cast<std::size_t>(node.camera));
  cam.eye = glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
  glm::dvec3 forward = glm::dmat3(world) * glm::dvec3(0.0, 0.0, -1.0);
  glm::dvec3 up = glm::dmat3(world) * glm::dvec3(0.0, 1.0, 0.0);
  if (!(glm::length(forward) > 0.0)) diag.fail(field, "camera transform is singular");
  forward = glm::normalize(forward);
  up -= glm::dot(up, forward) * forward;  // orthonormalise (non-uniform scale)
  if (!(glm::length(up) > 0.0)) diag.fail(field, "camera transform is singular");
  cam.up = glm::normalize(up);
  cam.target = cam.eye + forward;
  cam.fov_y_deg = glm::degrees(c.perspective.yfov);
  cam.aspect_ratio = c.perspective.aspectRatio;
  cam.znear = c.perspective.znear;
  cam.zfar = c.perspective.zfar;
  return cam;
}

}  // namespace eik
