// Mesh → coverage: solid or open surface (the Auto decision and forcing it), region names, loaded
// meshes, degenerate and broken input, progress. The two voxelisers are tested in
// solid_voxelizer_test.cpp and surface_voxelizer_test.cpp.
#include "voxelize/mesh_voxelizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "voxelize/mesh_scene.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

double relativeError(double value, double reference) { return std::abs(value - reference) / std::abs(reference); }

TEST(MeshVoxelizer, NestedMeshesGiveTwoRegions) {
  // Written as one OBJ with two objects, loaded, voxelised one region per mesh.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "eikonal_mesh_voxelizer_test";
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "nested.obj";
  {
    std::ofstream out(file);
    int base = 0;
    for (auto [name, radius] : {std::pair<const char*, double>{"outer", 1.0}, {"inner", 0.5}}) {
      const TriangleMesh s = makeUvSphere(glm::dvec3(0.0), radius, 48, 24);
      out << "o " << name << "\n";
      for (const glm::dvec3& p : s.positions) out << "v " << p.x << " " << p.y << " " << p.z << "\n";
      for (const glm::uvec3& t : s.triangles)
        out << "f " << t[0] + 1 + base << " " << t[1] + 1 + base << " " << t[2] + 1 + base << "\n";
      base += static_cast<int>(s.positions.size());
    }
  }
  const MeshScene scene = loadMeshFile(file);
  ASSERT_EQ(scene.meshes.size(), 2u);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.4, 96);
  const Region outer = voxelizeMesh(scene.meshes[0], grid);
  const Region inner = voxelizeMesh(scene.meshes[1], grid);
  EXPECT_EQ(outer.name, "mesh:outer");
  EXPECT_EQ(inner.name, "mesh:inner");
  EXPECT_LT(relativeError(outer.enclosed_volume, scene.meshes[0].signedVolume()), 0.005);
  EXPECT_LT(relativeError(inner.enclosed_volume, scene.meshes[1].signedVolume()), 0.005);
  EXPECT_LT(inner.enclosed_volume, outer.enclosed_volume);  // innermost-wins order in compositing
  std::filesystem::remove_all(dir);
}

TEST(MeshVoxelizer, TiltedSheetAndThinClosedSlabAreSurfaces) {
  // A sheet made of many triangles: few boundary edges, yet open.
  TriangleMesh sheet;
  sheet.name = "terrain";
  const int n = 40;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -0.9 + 1.8 * i / n, z = -0.9 + 1.8 * j / n;
      sheet.positions.emplace_back(x, 0.1 * std::sin(3 * x) + 0.3 * z, z);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const unsigned a = static_cast<unsigned>(j * (n + 1) + i), b = a + 1, c = a + n + 1, d = c + 1;
      sheet.triangles.emplace_back(a, c, d);
      sheet.triangles.emplace_back(a, d, b);
    }
  EXPECT_LT(sheet.topology().boundaryFraction(), 0.05);
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 64);
  MeshVoxelizeStats stats;
  const Region region = voxelizeMesh(sheet, grid, {}, {}, &stats);
  EXPECT_TRUE(stats.open_surface) << stats.decision;
  double sum = 0.0;
  for (float c : region.coverage) sum += c;
  const double h = grid.voxelSize().x;
  EXPECT_NEAR(sum * grid.voxelVolume() / h, sheet.area(), 0.05 * sheet.area());

  // Two sheets facing opposite ways (a floor and a ceiling in one mesh) are still sheets: the
  // decision is made per connected component, so their area vectors do not cancel.
  TriangleMesh floors = makeRectangle({-0.8, -0.5, 0.8}, {1.6, 0, 0}, {0, 0, -1.6});
  floors.append(makeRectangle({-0.8, 0.5, -0.8}, {1.6, 0, 0}, {0, 0, 1.6}));
  ASSERT_LT(floors.openness(), 1e-12);
  std::string why;
  EXPECT_TRUE(isOpenSurface(floors, grid, {}, &why)) << why;
  // A ball with an inverted twin beside it is two solids, not a zero-volume sheet.
  TriangleMesh twins = makeUvSphere({-0.5, 0, 0}, 0.4, 32, 16);
  TriangleMesh inverted = makeUvSphere({0.5, 0, 0}, 0.4, 32, 16);
  inverted.flipWinding();
  twins.append(inverted);
  ASSERT_LT(std::abs(twins.signedVolume()), 1e-9);
  EXPECT_FALSE(isOpenSurface(twins, grid, {}, &why)) << why;
  EXPECT_LT(relativeError(voxelizeMesh(twins, grid).enclosed_volume, 2.0 * std::abs(inverted.signedVolume())), 0.01);

  // A closed box a tenth of a voxel thick is a sheet too.
  const TriangleMesh slab = makeBox({-0.5, 0.0, -0.5}, {0.5, 0.1 * h, 0.5});
  std::string reason;
  EXPECT_TRUE(isOpenSurface(slab, grid, {}, &reason)) << reason;
  EXPECT_FALSE(isOpenSurface(makeBox({-0.5, 0.0, -0.5}, {0.5, 0.5 * h, 0.5}), grid, {}, &reason)) << reason;
}

TEST(MeshVoxelizer, EmptyAndDegenerateMeshesGiveNothing) {
  const GridSpec grid = cubeGrid(glm::dvec3(0.0), 2.0, 8);
  TriangleMesh empty;
  empty.name = "empty";
  EXPECT_EQ(voxelizeMesh(empty, grid).enclosed_volume, 0.0);
  TriangleMesh degenerate = makeRectangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0});  // zero area
  const Region region = voxelizeMesh(degenerate, grid);
  EXPECT_EQ(region.coverage, std::vector<float>(grid.count(), 0.0f));
  TriangleMesh broken = makeBox({0, 0, 0}, {1, 1, 1});
  broken.triangles[3][1] = 99;
  EXPECT_THROW(voxelizeMesh(broken, grid), InputError);
}

TEST(MeshVoxelizer, EmptyAndRepeatedTrianglesAreDroppedOrientationKept) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // 3..5 copy 0..2
  mesh.triangles = {{0, 1, 2},   // kept
                    {1, 2, 0},   // the same, rotated: a repeat
                    {0, 2, 1},   // reversed: the other side, kept
                    {3, 4, 5},   // the same positions through other vertices: a repeat
                    {0, 0, 1},   // two equal corners
                    {0, 3, 1}};  // equal corner positions through different vertices
  std::size_t dropped = 0;
  const TriangleMesh clean = withoutEmptyOrRepeatedTriangles(mesh, &dropped);
  EXPECT_EQ(dropped, 4u);
  EXPECT_EQ(clean.triangles, (std::vector<glm::uvec3>{{0, 1, 2}, {0, 2, 1}}));
  EXPECT_EQ(clean.positions, mesh.positions);
}

// The hostile fan of the issue "Reliability" (one OBJ face repeating three vertices 50 000 times,
// which took 44 s at --res 16): it voxelises to exactly what its one distinct triangle gives.
TEST(MeshVoxelizer, AFanRepeatingOneFaceCostsOneFace) {
  TriangleMesh fan;
  fan.name = "fan";
  fan.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  // The OBJ loader triangulates "f 1 2 3 1 2 3 ..." as a fan from vertex 1: (1,2,3), (1,3,1), (1,1,2), ...
  const std::vector<unsigned> ring = {0, 1, 2};
  for (unsigned i = 1; i + 1 < 150000; ++i) fan.triangles.push_back({0, ring[i % 3], ring[(i + 1) % 3]});
  TriangleMesh one = fan;
  one.triangles = {{0, 1, 2}};
  const GridSpec grid = cubeGrid(glm::dvec3(0.5, 0.5, 0.0), 1.4, 16);
  MeshVoxelizeOptions options;
  options.distance_band = 0.2;
  MeshVoxelizeStats stats;
  const Region a = voxelizeMesh(fan, grid, options, {}, &stats);
  const Region b = voxelizeMesh(one, grid, options);
  EXPECT_EQ(stats.dropped_triangles, fan.triangles.size() - 1);
  EXPECT_EQ(a.coverage, b.coverage);
  EXPECT_EQ(a.distance, b.distance);
  EXPECT_GT(*std::max_element(a.coverage.begin(), a.coverage.end()), 0.0f) << "the triangle is voxelised";
}

TEST(MeshVoxelizer, ProgressReachesOne) {
  const TriangleMesh sphere = makeUvSphere(glm::dvec3(0.0), 0.5, 16, 8);
  std::atomic<double> last{0.0};
  voxelizeMesh(sphere, cubeGrid(glm::dvec3(0.0), 1.2, 16), {}, [&](double f) {
    double seen = last.load();
    while (f > seen && !last.compare_exchange_weak(seen, f)) {
    }
  });
  EXPECT_DOUBLE_EQ(last.load(), 1.0);
}

}  // namespace
}  // namespace eik
