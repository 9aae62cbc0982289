#include "lightsim/sun_disc.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lightsim/wavefront.h"

namespace eik {

std::vector<glm::dvec3> ballLightPoints(double radius, int samples) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<glm::dvec3> points;
  for (int i = 0; i < samples; ++i) {
    // The radius: F(u) = (u − sin u cos u)/(π/2) = (i + ½)/K by bisection (F rises on [0, π/2]).
    const double q = (i + 0.5) / samples;
    double lo = 0.0, hi = 0.5 * std::numbers::pi;
    for (int k = 0; k < 60; ++k) {
      const double u = 0.5 * (lo + hi);
      ((u - std::sin(u) * std::cos(u)) / (0.5 * std::numbers::pi) < q ? lo : hi) = u;
    }
    const double r = radius * std::sin(0.5 * (lo + hi));
    // The direction: the base-2 radical inverse of i for the height, the golden angle for the azimuth.
    double inverse = 0.0, digit = 0.5;
    for (unsigned n = static_cast<unsigned>(i); n > 0; n >>= 1, digit *= 0.5)
      if (n & 1u) inverse += digit;
    const double z = 1.0 - 2.0 * (inverse + 0.5 / samples), ring = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = i * golden;
    points.push_back(r * glm::dvec3(ring * std::cos(phi), z, ring * std::sin(phi)));
  }
  return points;
}

std::vector<LightSpec> sunDiscSamples(const LightSpec& light, int samples) {
  if (light.type != LightSpec::Type::Directional && light.radius > 0.0 && samples > 1) {
    std::vector<LightSpec> out;
    for (const glm::dvec3& offset : ballLightPoints(light.radius, samples)) {
      LightSpec s = light;
      s.radius = 0.0;
      s.position = light.position + offset;
      s.power = light.power / static_cast<double>(samples);
      out.push_back(s);
    }
    return out;
  }
  if (light.type != LightSpec::Type::Directional || !(light.angular_diameter_deg > 0.0) || samples <= 1) {
    LightSpec one = light;
    one.angular_diameter_deg = 0.0;
    one.radius = 0.0;
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
