// Solid meshes → coverage: volumes against closed-form and polyhedral answers, leaky meshes, seams,
// orientation, overlaps, exact edge/vertex hits, determinism.
#include "voxelize/solid_voxelizer.h"

#include <gtest/gtest.h>

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

double relativeError(double value, double reference) { return std::abs(value - reference) / std::abs(reference); }

TEST(MeshVoxelizer, ClosedSphereMatchesPolyhedronAndBall) {
  const double R = 1.0;
  const TriangleMesh sphere = makeUvSphere(glm::dvec3(0.0), R, 64, 32);
  ASSERT_GE(sphere.triangleCount(), 2000u);
  ASSERT_TRUE(sphere.isClosed());
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.4 * R, 128);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(sphere, grid, {}, {}, &stats);
  EXPECT_FALSE(stats.open_surface) << stats.decision;
  EXPECT_EQ(region.name, "mesh:sphere");
  EXPECT_EQ(stats.rays_through_holes, 0u);
  const double polyhedron = sphere.signedVolume();
  EXPECT_LT(relativeError(region.enclosed_volume, polyhedron), 0.005)
      << region.enclosed_volume << " vs polyhedron " << polyhedron;
  EXPECT_LT(relativeError(region.enclosed_volume, 4.0 / 3.0 * kPi * R * R * R), 0.01);
  // A closed mesh should need the winding number for (almost) no voxel.
  EXPECT_LT(stats.winding_voxels, grid.count() / 10000) << stats.winding_voxels;
}

TEST(MeshVoxelizer, AnisotropicVoxels) {
  const TriangleMesh sphere = makeUvSphere(glm::dvec3(0.05, -0.02, 0.01), 0.9, 64, 32);
  GridSpec grid;
  grid.dims = {48, 80, 33};
  grid.bounds_min = glm::dvec3(-1.0, -1.1, -0.95);
  grid.bounds_max = glm::dvec3(1.05, 1.0, 1.0);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(sphere, grid, {}, {}, &stats);
  EXPECT_EQ(stats.rays_through_holes, 0u);
  EXPECT_LT(relativeError(region.enclosed_volume, sphere.signedVolume()), 0.005);
}

TEST(MeshVoxelizer, SphereWithHolesKeepsItsVolume) {
  const double R = 1.0;
  const TriangleMesh closed = makeUvSphere(glm::dvec3(0.0), R, 64, 32);
  // Opposite holes on all three axes (so some rays of every axis enter and leave through holes),
  // at both poles, the equator and in between.
  const std::vector<glm::dvec3> where = {{1, 0, 0},   {-1, 0, 0},  {0, 1, 0},    {0, -1, 0},  {0, 0, 1},
                                         {0, 0, -1},  {1, 1, 1},   {-1, -1, -1}, {1, -1, 0.3}, {-0.5, 0.7, -0.2}};
  const TriangleMesh leaky = punchHoles(closed, glm::dvec3(0.0), where);
  ASSERT_EQ(leaky.triangleCount(), closed.triangleCount() - where.size());
  ASSERT_GT(leaky.topology().boundary_edges, 0u);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.4 * R, 128);
  MeshVoxelizeStats closed_stats, leaky_stats;
  const Region a = voxelizeMesh(closed, grid, {}, {}, &closed_stats);
  const Region b = voxelizeMesh(leaky, grid, {}, {}, &leaky_stats);
  EXPECT_FALSE(leaky_stats.open_surface) << leaky_stats.decision;
  EXPECT_GT(leaky_stats.rays_through_holes, 0u);
  EXPECT_LT(relativeError(b.enclosed_volume, a.enclosed_volume), 0.01)
      << b.enclosed_volume << " vs closed " << a.enclosed_volume;
  // Not just the total: voxel by voxel the leaky sphere looks like the closed one.
  double differing = 0.0;
  for (std::size_t i = 0; i < a.coverage.size(); ++i) differing += std::abs(a.coverage[i] - b.coverage[i]);
  EXPECT_LT(differing * grid.voxelVolume(), 0.005 * a.enclosed_volume);
}

TEST(MeshVoxelizer, OpenSeamIsBridged) {
  // A teapot-like seam: the upper hemisphere lifted by one voxel, leaving a ring-shaped gap. Rays of
  // two axes slip through the gap in its plane (consistently: no crossing at all), so voting alone
  // would cut the ball in two; the winding number bridges the gap.
  const double R = 1.0;
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.4 * R, 96);
  const double gap = grid.voxelSize().x;
  const TriangleMesh ball = makeUvSphere(glm::dvec3(0.0), R, 64, 32);
  TriangleMesh seam = ball;
  seam.triangles.clear();
  std::vector<int> lifted(ball.positions.size(), -1);
  for (glm::uvec3 t : ball.triangles) {
    const double cz = (ball.positions[t[0]].z + ball.positions[t[1]].z + ball.positions[t[2]].z) / 3.0;
    for (int c = 0; c < 3 && cz > 0.0; ++c) {
      if (std::abs(ball.positions[t[c]].z) > 1e-12) continue;  // equator vertex of an upper triangle
      if (lifted[t[c]] < 0) {
        lifted[t[c]] = static_cast<int>(seam.positions.size());
        seam.positions.push_back(ball.positions[t[c]]);
      }
      t[c] = static_cast<unsigned>(lifted[t[c]]);
    }
    seam.triangles.push_back(t);
  }
  for (std::size_t v = 0; v < seam.positions.size(); ++v) {
    const bool equator_copy = v >= ball.positions.size();
    if (equator_copy || seam.positions[v].z > 1e-12) seam.positions[v].z += gap;
  }
  ASSERT_EQ(seam.topology().boundary_edges, 128u);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(seam, grid, {}, {}, &stats);
  EXPECT_FALSE(stats.open_surface) << stats.decision;
  EXPECT_GT(stats.winding_voxels, 0u);
  const double equator_polygon = 32.0 * std::sin(2.0 * kPi / 64.0) * R * R;
  const double filled = ball.signedVolume() + equator_polygon * gap;
  EXPECT_LT(relativeError(region.enclosed_volume, filled), 0.005)
      << region.enclosed_volume << " vs " << filled << " (two separate halves: " << ball.signedVolume() << ")";
  // The equatorial plane inside the ball is inside.
  const int k = static_cast<int>((gap / 2 + 1.2 * R) / grid.voxelSize().z);
  EXPECT_EQ(region.coverage[grid.index(48, 48, k)], 1.0f);
}

TEST(MeshVoxelizer, TorusMatchesPappus) {
  const double R = 1.0, r = 0.4;
  const int major = 96, minor = 48;
  const TriangleMesh torus = makeTorus(glm::dvec3(0.0), R, r, major, minor);
  const GridSpec grid = [&] {
    GridSpec g;
    g.dims = {128, 128, 40};
    g.bounds_min = {-1.5, -1.5, -0.46875};
    g.bounds_max = {1.5, 1.5, 0.46875};
    return g;
  }();
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(torus, grid, {}, {}, &stats);
  EXPECT_EQ(stats.rays_through_holes, 0u);
  const double polyhedron = torus.signedVolume();
  EXPECT_LT(relativeError(region.enclosed_volume, polyhedron), 0.005);
  // Pappus: 2π²Rr², with the inscribed polygons' area factors n·sin(2π/n)/(2π) for the tube
  // cross-section and (to first order) for the sweep.
  auto polygon = [](int n) { return n * std::sin(2.0 * kPi / n) / (2.0 * kPi); };
  const double corrected = 2.0 * kPi * kPi * R * r * r * polygon(minor) * polygon(major);
  EXPECT_LT(relativeError(region.enclosed_volume, corrected), 0.005)
      << region.enclosed_volume << " vs " << corrected << " (uncorrected " << 2 * kPi * kPi * R * r * r << ")";
}

TEST(MeshVoxelizer, FlippedNormalsGiveTheSameVolume) {
  TriangleMesh sphere = makeUvSphere(glm::dvec3(0.1, -0.05, 0.02), 0.8, 48, 24);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 64);
  const Region outward = voxelizeMesh(sphere, grid);
  sphere.flipWinding();
  ASSERT_LT(sphere.signedVolume(), 0.0);
  const Region inward = voxelizeMesh(sphere, grid);
  EXPECT_NEAR(inward.enclosed_volume, outward.enclosed_volume, 1e-9);
  EXPECT_EQ(inward.coverage, outward.coverage);
  // Also with holes, where the winding-number fallback has to respect the orientation.
  const TriangleMesh leaky = punchHoles(sphere, glm::dvec3(0.1, -0.05, 0.02), {{1, 0, 0}, {-1, 0, 0}, {0, 0, 1}});
  MeshVoxelizeStats stats;
  const Region leaky_inward = voxelizeMesh(leaky, grid, {}, {}, &stats);
  EXPECT_LT(relativeError(leaky_inward.enclosed_volume, outward.enclosed_volume), 0.01);
}

TEST(MeshVoxelizer, OverlappingAndDuplicatedPartsAreTheirUnion) {
  // Two overlapping balls in one mesh: inside = winding ≠ 0, so the overlap counts once.
  const double R = 0.6, d = 0.6;
  TriangleMesh mesh = makeUvSphere(glm::dvec3(-d / 2, 0, 0), R, 96, 48);
  const TriangleMesh right = makeUvSphere(glm::dvec3(d / 2, 0, 0), R, 96, 48);
  mesh.append(right);
  // ... and a duplicated copy of one of them (coincident faces, winding 2 inside).
  mesh.append(right);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 96);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(mesh, grid, {}, {}, &stats);
  EXPECT_FALSE(stats.open_surface) << stats.decision;
  const double ball = makeUvSphere(glm::dvec3(0.0), R, 96, 48).signedVolume();
  const double lens = kPi * (4 * R + d) * (2 * R - d) * (2 * R - d) / 12.0;  // two-sphere intersection
  const double exact_ball = 4.0 / 3.0 * kPi * R * R * R;
  const double expected = (2.0 * exact_ball - lens) * (ball / exact_ball);
  EXPECT_LT(relativeError(region.enclosed_volume, expected), 0.01) << region.enclosed_volume << " vs " << expected;
  for (float c : region.coverage) ASSERT_TRUE(c >= 0.0f && c <= 1.0f);
}

TEST(MeshVoxelizer, CoverageIsFractionalOnlyOnTheBoundary) {
  const double R = 0.7;
  const glm::dvec3 center(0.013, -0.021, 0.007);
  const TriangleMesh sphere = makeUvSphere(center, R, 96, 48);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 64);
  const Region region = voxelizeMesh(sphere, grid);
  const double h = grid.voxelSize().x;
  const double slack = 0.5 * std::sqrt(3.0) * h + R * (1 - std::cos(kPi / 48)) + 1e-9;
  std::size_t fractional = 0;
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        const float c = region.coverage[grid.index(i, j, k)];
        ASSERT_GE(c, 0.0f);
        ASSERT_LE(c, 1.0f);
        const double distance = glm::length(grid.center(i, j, k) - center) - R;
        if (c > 0.0f && c < 1.0f) {
          ++fractional;
          EXPECT_LE(std::abs(distance), slack) << i << " " << j << " " << k << " c=" << c;
        }
        if (distance > slack) {
          EXPECT_EQ(c, 0.0f);
        }
        if (distance < -slack) {
          EXPECT_EQ(c, 1.0f);
        }
      }
  EXPECT_GT(fractional, 1000u);  // anti-aliased, not binary
}

TEST(MeshVoxelizer, EdgeAndVertexHitsCountOnce) {
  // Voxels of size 1 on [0, 16]³, S = 4: sub-rays at 0.125 + 0.25·m. Box corners on that lattice,
  // so rays run exactly through the box's edges, the diagonals of its faces and its vertices.
  GridSpec grid;
  grid.dims = glm::ivec3(16);
  grid.bounds_min = glm::dvec3(0.0);
  grid.bounds_max = glm::dvec3(16.0);
  const glm::dvec3 lo(2.125, 3.375, 4.625), hi(10.875, 9.125, 12.375);
  const TriangleMesh box = makeBox(lo, hi);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(box, grid, {}, {}, &stats);
  EXPECT_EQ(stats.rays_through_holes, 0u);
  EXPECT_EQ(stats.winding_voxels, 0u);
  const glm::dvec3 size = hi - lo;
  EXPECT_NEAR(region.enclosed_volume, size.x * size.y * size.z, 1e-5 * size.x * size.y * size.z);

  // An octahedron whose apexes and edges lie on sub-rays: rays through a vertex shared by four
  // faces, and along edges shared by two, are each counted exactly once.
  TriangleMesh octahedron;
  octahedron.name = "octahedron";
  const glm::dvec3 c(8.125, 7.875, 8.375);
  const double a = 5.0;
  octahedron.positions = {c + glm::dvec3(a, 0, 0), c - glm::dvec3(a, 0, 0), c + glm::dvec3(0, a, 0),
                          c - glm::dvec3(0, a, 0), c + glm::dvec3(0, 0, a), c - glm::dvec3(0, 0, a)};
  octahedron.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  ASSERT_NEAR(octahedron.signedVolume(), 4.0 / 3.0 * a * a * a, 1e-9);
  const Region oct = voxelizeMesh(octahedron, grid, {}, {}, &stats);
  EXPECT_EQ(stats.rays_through_holes, 0u);
  EXPECT_LT(relativeError(oct.enclosed_volume, 4.0 / 3.0 * a * a * a), 0.002);
}

TEST(MeshVoxelizer, LeakyScanFallsBackToWindingNumber) {
  // Every 9th face missing: most rays pass through a hole, so large parts are decided by the
  // generalized winding number.
  const TriangleMesh closed = makeUvSphere(glm::dvec3(0.0), 0.8, 32, 16);
  TriangleMesh leaky = closed;
  leaky.triangles.clear();
  for (std::size_t t = 0; t < closed.triangles.size(); ++t)
    if (t % 9 != 4) leaky.triangles.push_back(closed.triangles[t]);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 48);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(leaky, grid, {}, {}, &stats);
  EXPECT_FALSE(stats.open_surface) << stats.decision;
  EXPECT_GT(stats.winding_voxels, 100u);
  EXPECT_LT(relativeError(region.enclosed_volume, closed.signedVolume()), 0.02)
      << region.enclosed_volume << " vs " << closed.signedVolume();
}

TEST(MeshVoxelizer, DeterministicWhateverTheThreadCount) {
  const TriangleMesh torus = punchHoles(makeTorus(glm::dvec3(0.0), 0.6, 0.25, 48, 24), glm::dvec3(0.0),
                                        {{1, 0, 0}, {0, 1, 0.2}});
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 40);
  const char* previous = std::getenv("EIKONAL_THREADS");
  const std::string saved = previous ? previous : "";
  setenv("EIKONAL_THREADS", "1", 1);
  const Region one = voxelizeMesh(torus, grid);
  setenv("EIKONAL_THREADS", "3", 1);
  const Region three = voxelizeMesh(torus, grid);
  if (previous) setenv("EIKONAL_THREADS", saved.c_str(), 1);
  else unsetenv("EIKONAL_THREADS");
  EXPECT_EQ(one.coverage, three.coverage);
  EXPECT_EQ(one.enclosed_volume, three.enclosed_volume);
}

TEST(SolidVoxelizer, IsWhatVoxelizeMeshUsesForSolids) {
  const TriangleMesh sphere = punchHoles(makeUvSphere(glm::dvec3(0.0), 0.6, 32, 16), glm::dvec3(0.0), {{1, 0, 0}});
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 1.5, 24);
  MeshVoxelizeStats direct;
  const Region region = voxelizeSolid(sphere, grid, {}, {}, direct);
  MeshVoxelizeStats via_mesh;
  const Region mesh_region = voxelizeMesh(sphere, grid, {}, {}, &via_mesh);
  EXPECT_EQ(region.coverage, mesh_region.coverage);
  EXPECT_EQ(direct.rays, via_mesh.rays);
  EXPECT_EQ(direct.rays_through_holes, via_mesh.rays_through_holes);
  EXPECT_GT(direct.rays_through_holes, 0u);
  EXPECT_EQ(direct.winding_voxels, via_mesh.winding_voxels);
  EXPECT_EQ(direct.winding_evaluations, via_mesh.winding_evaluations);
  // 3 axes × 24² columns × S² sub-rays.
  EXPECT_EQ(direct.rays, 3u * 24u * 24u * 16u);
}

}  // namespace
}  // namespace eik
