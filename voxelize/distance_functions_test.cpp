// The signed distance primitives: exact values at known points, and 1-Lipschitz (the implicit
// voxeliser's classification relies on |sdf| never overestimating the distance).
#include "voxelize/distance_functions.h"

#include <gtest/gtest.h>

#include <random>

namespace eik {
namespace {

TEST(DistanceFunctions, BoxIsExactInsideAndOutside) {
  const glm::dvec3 half(1.0, 2.0, 3.0);
  EXPECT_DOUBLE_EQ(sdBox(glm::dvec3(0.0), half), -1.0);                  // nearest face: x
  EXPECT_DOUBLE_EQ(sdBox(glm::dvec3(0.0, 1.5, 0.0), half), -0.5);        // nearer the y face
  EXPECT_DOUBLE_EQ(sdBox(glm::dvec3(3.0, 0.0, 0.0), half), 2.0);         // off a face
  EXPECT_DOUBLE_EQ(sdBox(glm::dvec3(4.0, 6.0, 0.0), half), 5.0);         // off an edge: (3, 4)
  EXPECT_DOUBLE_EQ(sdBox(glm::dvec3(-1.0, 2.0, -3.0), half), 0.0);       // a corner
  EXPECT_DOUBLE_EQ(sdBox2(glm::dvec2(4.0, 6.0), glm::dvec2(1.0, 2.0)), 5.0);
  EXPECT_DOUBLE_EQ(sdBox2(glm::dvec2(0.0, 0.0), glm::dvec2(1.0, 2.0)), -1.0);
}

TEST(DistanceFunctions, RoundingKeepsTheOuterExtent) {
  const glm::dvec3 half(1.0);
  EXPECT_DOUBLE_EQ(sdRoundBox(glm::dvec3(2.0, 0.0, 0.0), half, 0.25), 1.0);  // faces stay where they were
  // A corner is cut to a sphere of the rounding radius around (0.75, 0.75, 0.75).
  const glm::dvec3 corner(1.0);
  EXPECT_NEAR(sdRoundBox(corner, half, 0.25), glm::length(glm::dvec3(0.25)) - 0.25, 1e-15);
  EXPECT_DOUBLE_EQ(sdRoundCylinderY(glm::dvec3(0.0), 0.5, 1.0, 0.0), -0.5);
  EXPECT_DOUBLE_EQ(sdRoundCylinderY(glm::dvec3(0.0, 3.0, 0.0), 0.5, 1.0, 0.1), 2.0);
  EXPECT_DOUBLE_EQ(sdRoundCylinderY(glm::dvec3(3.0, 0.0, 4.0), 0.5, 1.0, 0.0), 4.5);
  EXPECT_DOUBLE_EQ(combine2(3.0, 4.0), 5.0);   // outside both: the Euclidean combination
  EXPECT_DOUBLE_EQ(combine2(-1.0, -2.0), -1.0);  // inside both: the nearer boundary
  EXPECT_DOUBLE_EQ(combine2(-1.0, 2.0), 2.0);
}

TEST(DistanceFunctions, AreOneLipschitz) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  auto point = [&] { return glm::dvec3(u(random), u(random), u(random)); };
  const glm::dvec3 half(0.7, 0.4, 0.9);
  for (int n = 0; n < 2000; ++n) {
    const glm::dvec3 p = point(), q = point();
    const double d = glm::length(p - q) * (1.0 + 1e-12) + 1e-15;
    ASSERT_LE(std::abs(sdBox(p, half) - sdBox(q, half)), d);
    ASSERT_LE(std::abs(sdRoundBox(p, half, 0.3) - sdRoundBox(q, half, 0.3)), d);
    ASSERT_LE(std::abs(sdRoundCylinderY(p, 0.6, 0.8, 0.2) - sdRoundCylinderY(q, 0.6, 0.8, 0.2)), d);
    ASSERT_LE(std::abs(sdBox2(glm::dvec2(p), glm::dvec2(half)) - sdBox2(glm::dvec2(q), glm::dvec2(half))), d);
  }
}

}  // namespace
}  // namespace eik
