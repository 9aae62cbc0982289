// The directions over a light's disc (sun_disc.h): all within the disc, spread evenly over it (their
// mean is the light's direction, their mean squared angle the disc's, ρ²/2), the power shared.
// The penumbra they cast is checked against geometry in exact_optics_test.cpp
// (ExactOpticsSoftSun.TheSunsDiscCastsThePenumbraOfGeometry).
#include "lightsim/sun_disc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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

// A ball light (a point light with a radius) as points in the ball that look like a uniform disc
// of its radius from every side: seen along x, y, z or a diagonal, their projections have the
// mean square distance of a uniform disc, ρ²/2 (a uniform ball would give 2ρ²/5, its surface
// 2ρ²/3), and half of them fall within ρ/√2 (half the disc's area); the intensity is shared.
TEST(SunDisc, ABallLightLooksLikeAUniformDiscFromEverySide) {
  constexpr int kSamples = 256;
  constexpr double kRadius = 0.3;
  const std::vector<glm::dvec3> points = ballLightPoints(kRadius, kSamples);
  ASSERT_EQ(points.size(), static_cast<std::size_t>(kSamples));
  for (const glm::dvec3& p : points) EXPECT_LE(glm::length(p), kRadius + 1e-12);
  for (const glm::dvec3 axis : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1), glm::dvec3(1, 1, 1)}) {
    const glm::dvec3 a = glm::normalize(axis);
    double mean_square = 0.0, within = 0.0;
    glm::dvec3 centroid(0.0);
    for (const glm::dvec3& p : points) {
      const double s2 = glm::dot(p, p) - glm::dot(p, a) * glm::dot(p, a);  // squared distance from the axis
      mean_square += s2 / kSamples;
      within += s2 < 0.5 * kRadius * kRadius ? 1.0 / kSamples : 0.0;
      centroid += p / static_cast<double>(kSamples);
    }
    std::printf("seen along (%.2f, %.2f, %.2f): E[s²]/ρ² = %.4f, within ρ/√2 %.4f\n", a.x, a.y, a.z,
                mean_square / (kRadius * kRadius), within);
    // Tolerances: 256 stratified points (a random set's standard error would be 0.02 and 0.03).
    EXPECT_NEAR(mean_square / (kRadius * kRadius), 0.5, 0.03);
    EXPECT_NEAR(within, 0.5, 0.06);
    EXPECT_LT(glm::length(centroid), 0.05 * kRadius);
  }
  LightSpec lamp;
  lamp.type = LightSpec::Type::Point;
  lamp.position = {1.0, 2.0, 3.0};
  lamp.power = glm::dvec3(8.0);
  lamp.radius = kRadius;
  const std::vector<LightSpec> samples = sunDiscSamples(lamp, 16);
  ASSERT_EQ(samples.size(), 16u);
  glm::dvec3 power(0.0);
  for (const LightSpec& s : samples) {
    EXPECT_EQ(s.radius, 0.0);
    EXPECT_LE(glm::length(s.position - lamp.position), kRadius + 1e-12);
    power += s.power;
  }
  EXPECT_NEAR(glm::length(power - lamp.power), 0.0, 1e-12);
}

}  // namespace
}  // namespace eik
