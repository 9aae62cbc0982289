#include "viewer/camera.h"

#include <cmath>
#include <sstream>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"

namespace eik {

glm::dmat4 Camera::view() const { return glm::lookAt(eye, target, up); }

glm::dmat4 Camera::projection(double aspect) const {
  return glm::perspective(glm::radians(fov_y_deg), aspect, 0.01, 1000.0);
}

glm::dmat4 Camera::inverseViewProjection(double aspect) const { return glm::inverse(projection(aspect) * view()); }

Camera parseCamera(const std::string& text, const std::string& source) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string part; std::getline(ss, part, ':');) parts.push_back(part);
  if (parts.size() != 3) throw InputError(source, text, "expected EX,EY,EZ:TX,TY,TZ:FOVY_DEG");
  auto triple = [&](const std::string& p, const char* what) {
    glm::dvec3 v;
    char c1 = 0, c2 = 0;
    std::istringstream in(p);
    if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() ||
        !std::isfinite(v.x + v.y + v.z))
      throw InputError(source, what, "'" + p + "' is not three comma-separated numbers");
    return v;
  };
  Camera c;
  c.eye = triple(parts[0], "eye");
  c.target = triple(parts[1], "target");
  std::istringstream in(parts[2]);
  if (!(in >> c.fov_y_deg) || !(in >> std::ws).eof() || !(c.fov_y_deg > 0 && c.fov_y_deg < 180))
    throw InputError(source, "fov", "'" + parts[2] + "' is not an angle in (0, 180) degrees");
  if (glm::length(c.target - c.eye) < 1e-12) throw InputError(source, "target", "equals the eye");
  return c;
}

}  // namespace eik
