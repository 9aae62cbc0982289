// The directions over a light's disc (sun_disc.h): all within the disc, spread evenly over it (their
// mean is the light's direction, their mean squared angle the disc's, ρ²/2), the power shared.
// The penumbra they cast is checked against geometry in exact_optics_test.cpp
// (ExactOpticsSoftSun.TheSunsDiscCastsThePenumbraOfGeometry).
#include "lightsim/sun_disc.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eik {
namespace {

TEST(SunDisc, DirectionsSpreadEvenlyOverTheDisc) {
  LightSpec sun;
  sun.direction = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  sun.power = {2.0, 3.0, 4.0};
  sun.angular_diameter_deg = 4.0;
  const double rho = glm::radians(2.0);
  const std::vector<LightSpec> directions = sunDiscSamples(sun, 64);
  ASSERT_EQ(directions.size(), 64u);
  glm::dvec3 power(0.0), mean(0.0);
  double mean_square = 0.0;
  for (const LightSpec& d : directions) {
    const double angle = std::acos(std::min(1.0, glm::dot(d.direction, sun.direction)));
    EXPECT_LT(angle, rho);
    EXPECT_EQ(d.angular_diameter_deg, 0.0);
    power += d.power;
    mean += d.direction;
    mean_square += angle * angle / 64.0;
  }
  EXPECT_NEAR(glm::length(power - sun.power), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(glm::normalize(mean) - sun.direction), 0.0, 0.02 * rho);  // the sunflower's centroid
  EXPECT_NEAR(mean_square / (0.5 * rho * rho), 1.0, 0.02);  // a uniform disc: E[r²] = ρ²/2
  // No angular size (or a point light): the light itself, once.
  LightSpec point_like = sun;
  point_like.angular_diameter_deg = 0.0;
  EXPECT_EQ(sunDiscSamples(point_like, 16).size(), 1u);
  EXPECT_EQ(sunDiscSamples(sun, 1).at(0).direction, sun.direction);
}

}  // namespace
}  // namespace eik
