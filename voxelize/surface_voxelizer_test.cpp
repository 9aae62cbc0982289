// Open surfaces → a thin opaque receiver layer: one voxel's worth per column, the rounded rim,
// the layer's thickness.
#include "voxelize/surface_voxelizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "voxelize/mesh_voxelizer.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(MeshVoxelizer, FloorQuadBecomesOneVoxelThickOpaqueLayer) {
  TriangleMesh floor = makeRectangle({-0.8, 0.03, 0.7}, {1.6, 0.0, 0.0}, {0.0, 0.0, -1.4});
  floor.name = "floor";
  floor.material.albedo = glm::vec3(0.5f, 0.6f, 0.7f);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 64);
  const double h = grid.voxelSize().x;
  std::string reason;
  EXPECT_TRUE(isOpenSurface(floor, grid, {}, &reason)) << reason;
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(floor, grid, {}, {}, &stats);
  EXPECT_TRUE(stats.open_surface);
  EXPECT_EQ(region.name, "mesh:floor (open surface)");
  EXPECT_TRUE(region.material.opaque);
  EXPECT_EQ(region.material.albedo, glm::vec3(0.5f, 0.6f, 0.7f));
  EXPECT_EQ(region.enclosed_volume, 0.0);
  double sum = 0.0;
  for (float c : region.coverage) {
    ASSERT_GE(c, 0.0f);
    ASSERT_LE(c, 1.0f);
    sum += c;
  }
  // Coverage volume / h = area (a layer one voxel thick), plus the rounded rim: beyond the edge the
  // layer falls off with the distance d as 1 − d/h over a half disc, ∫(1 − r/h)πr dr / h = πh/6 per
  // unit length of boundary.
  const double rim = 2.0 * (1.6 + 1.4) * kPi * h / 6.0;
  EXPECT_NEAR(sum * grid.voxelVolume() / h, 1.6 * 1.4 + rim, 0.005 * 1.6 * 1.4);
  // Each column well inside the quad holds exactly one voxel's worth, within two voxels of y = 0.03.
  for (int k = 12; k < 52; k += 7)
    for (int i = 12; i < 52; i += 7) {
      double column = 0.0;
      for (int j = 0; j < 64; ++j) {
        const float c = region.coverage[grid.index(i, j, k)];
        column += c;
        if (c > 0.0f) {
          EXPECT_LT(std::abs(grid.center(i, j, k).y - 0.03), 1.01 * h);
        }
      }
      EXPECT_NEAR(column, 1.0, 1e-6);
    }
  // Forcing Solid on a sheet gives (almost) nothing; forcing Surface on a sphere gives a shell.
  MeshVoxelizeOptions solid;
  solid.surface_mode = SurfaceMode::Solid;
  EXPECT_LT(voxelizeMesh(floor, grid, solid).enclosed_volume, 0.01);
  MeshVoxelizeOptions surface;
  surface.surface_mode = SurfaceMode::Surface;
  const Region shell = voxelizeMesh(makeUvSphere(glm::dvec3(0.0), 0.5, 32, 16), grid, surface);
  EXPECT_EQ(shell.enclosed_volume, 0.0);
}

TEST(SurfaceVoxelizer, LayerThicknessScalesTheCoverage) {
  const TriangleMesh floor = makeRectangle({-0.8, 0.03, 0.7}, {1.6, 0.0, 0.0}, {0.0, 0.0, -1.4});
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 64);
  auto columnAt = [&](const std::vector<float>& coverage, int i, int k) {
    double column = 0.0;
    for (int j = 0; j < grid.dims.y; ++j) column += coverage[grid.index(i, j, k)];
    return column;
  };
  for (double thickness : {1.0, 2.0, 3.5}) {
    MeshVoxelizeOptions options;
    options.surface_thickness_voxels = thickness;
    std::vector<float> coverage(grid.count(), 0.0f);
    double last = 0.0;
    voxelizeSurfaceLayer(floor, grid, options, [&](double f) { last = std::max(last, f); }, coverage);
    EXPECT_DOUBLE_EQ(last, 1.0);
    for (int k = 12; k < 52; k += 13)
      for (int i = 12; i < 52; i += 13) EXPECT_NEAR(columnAt(coverage, i, k), thickness, 1e-6) << thickness;
  }
}

TEST(SurfaceVoxelizer, DeterministicWhateverTheThreadCount) {
  const TriangleMesh sphere = makeUvSphere(glm::dvec3(0.05, 0.0, -0.03), 0.6, 32, 16);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 1.6, 32);
  std::vector<float> one(grid.count(), 0.0f), three(grid.count(), 0.0f);
  ::setenv("EIKONAL_THREADS", "1", 1);
  voxelizeSurfaceLayer(sphere, grid, {}, {}, one);
  ::setenv("EIKONAL_THREADS", "3", 1);
  voxelizeSurfaceLayer(sphere, grid, {}, {}, three);
  ::unsetenv("EIKONAL_THREADS");
  EXPECT_EQ(one, three);
}

}  // namespace
}  // namespace eik
