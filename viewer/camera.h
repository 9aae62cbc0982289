// A pinhole camera (docs/scene-format.md "camera"): eye, target, up, vertical field of view.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "core/scene.h"

namespace eik {

struct Camera {
  glm::dvec3 eye{0.0, 0.0, 3.0};
  glm::dvec3 target{0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fov_y_deg = 40.0;

  static Camera fromSpec(const SceneCameraSpec& spec) { return {spec.eye, spec.target, spec.up, spec.fov_y_deg}; }
  glm::dmat4 view() const;
  glm::dmat4 projection(double aspect) const;
  // Clip space → world, for generating one ray per pixel.
  glm::dmat4 inverseViewProjection(double aspect) const;
};

// "EX,EY,EZ:TX,TY,TZ:FOVY_DEG" (the --camera flag, docs/programs.md); InputError naming `source`.
Camera parseCamera(const std::string& text, const std::string& source = "--camera");

}  // namespace eik
