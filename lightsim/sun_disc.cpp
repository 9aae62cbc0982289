#include "lightsim/sun_disc.h"

#include <cmath>
#include <numbers>

#include "lightsim/wavefront.h"

namespace eik {

std::vector<LightSpec> sunDiscSamples(const LightSpec& light, int samples) {
  if (light.type != LightSpec::Type::Directional || !(light.angular_diameter_deg > 0.0) || samples <= 1) {
    LightSpec one = light;
    one.angular_diameter_deg = 0.0;
    return {one};
  }
  const glm::dvec3 L = glm::normalize(light.direction);
  glm::dvec3 u, v;
  orthonormalBasis(L, u, v);
  const double radius = 0.5 * glm::radians(light.angular_diameter_deg);  // the disc's angular radius
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));       // 137.5°
  std::vector<LightSpec> out;
  for (int i = 0; i < samples; ++i) {
    // Equal areas of the disc (small angles: the tangent plane is the sphere to O(ρ²)).
    const double r = radius * std::sqrt((i + 0.5) / samples), phi = i * golden;
    LightSpec s = light;
    s.angular_diameter_deg = 0.0;
    s.direction = glm::normalize(L + std::tan(r) * (std::cos(phi) * u + std::sin(phi) * v));
    s.power = light.power / static_cast<double>(samples);
    out.push_back(s);
  }
  return out;
}

}  // namespace eik
