// Narrow-band signed distance of meshes (mesh_distance.h) against the exact distance of the
// shape the mesh approximates.
#include "voxelize/mesh_distance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "voxelize/mesh_voxelizer.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

TEST(MeshDistance, ClosestPointOnATriangleInEveryRegion) {
  const glm::dvec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Barycentric arithmetic rounds in the last bit: 1e-12 is a million ulps of margin and still far
  // below any wrong region (the nearest wrong answer is 0.1 away).
  auto expectPoint = [](const glm::dvec3& got, const glm::dvec3& want, const char* where) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], 1e-12) << where << " axis " << i;
  };
  expectPoint(closestPointOnTriangle({0.2, 0.2, 1.0}, a, b, c), {0.2, 0.2, 0.0}, "face");
  expectPoint(closestPointOnTriangle({-1, -1, 0.5}, a, b, c), a, "vertex a");
  expectPoint(closestPointOnTriangle({2, -0.5, 0}, a, b, c), b, "vertex b");
  expectPoint(closestPointOnTriangle({0.5, -2, 0}, a, b, c), {0.5, 0, 0}, "edge ab");
  expectPoint(closestPointOnTriangle({1, 1, 0}, a, b, c), {0.5, 0.5, 0}, "edge bc");
}

TEST(MeshDistance, ABoxMeshHasTheBoxsDistanceInTheBand) {
  const TriangleMesh box = makeBox(glm::dvec3(-0.3), glm::dvec3(0.3));
  GridSpec g;
  g.dims = glm::ivec3(20);
  g.bounds_min = glm::dvec3(-0.5);
  g.bounds_max = glm::dvec3(0.5);
  MeshVoxelizeOptions options;
  options.distance_band = 0.2;
  const Region r = voxelizeMesh(box, g, options);
  ASSERT_EQ(r.distance.size(), g.count());
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 20; ++i) {
        const glm::dvec3 p = g.center(i, j, k);
        const glm::dvec3 q = glm::abs(p) - glm::dvec3(0.3);
        const double exact = glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
        ASSERT_NEAR(r.distance[g.index(i, j, k)], std::clamp(exact, -0.2, 0.2), 1e-6) << i << " " << j << " " << k;
      }
}

}  // namespace
}  // namespace eik
