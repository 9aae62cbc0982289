// The implicit voxeliser: coverage of signed-distance solids against exact volumes, exact face
// fractions, convergence with the supersampling rate, per-voxel n, determinism.
#include "voxelize/implicit_voxelizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <stdexcept>

#include "voxelize/distance_functions.h"
#include "voxelize/procedural.h"
#include "voxelize/procedural_shapes.h"
#include "voxelize/test_meshes.h"

namespace eik {
namespace {

double coverageSum(const Region& r) {
  double s = 0.0;
  for (float c : r.coverage) s += c;
  return s;
}

// n³ voxels on [−half, half]³.
GridSpec centredGrid(int n, double half) { return cubeGrid(glm::dvec3(0.0), 2.0 * half, n); }

ImplicitSolid sphere(double r, const glm::dvec3& c = glm::dvec3(0.0)) {
  ImplicitSolid s;
  s.name = "sphere";
  s.sdf = [=](const glm::dvec3& x) { return glm::length(x - c) - r; };
  s.bounds.min = c - r;
  s.bounds.max = c + r;
  return s;
}

ImplicitSolid box(const glm::dvec3& size, const glm::dvec3& c) {
  const glm::dvec3 half = 0.5 * size;
  ImplicitSolid s;
  s.name = "box";
  s.sdf = [=](const glm::dvec3& x) { return sdBox(x - c, half); };
  s.bounds.min = c - half;
  s.bounds.max = c + half;
  return s;
}

TEST(ImplicitVoxelizer, SphereVolumeAt128) {
  const double R = 0.5;
  const GridSpec grid = centredGrid(128, 0.53);
  const double exact = 4.0 / 3.0 * std::numbers::pi * R * R * R;
  for (bool antialias : {true, false}) {
    ProceduralOptions options;
    options.antialias = antialias;
    const Region region = voxelizeImplicit(sphere(R), grid, options);
    const double volume = coverageSum(region) * grid.voxelVolume();
    EXPECT_NEAR(volume, exact, 5e-4 * exact) << "antialias " << antialias;  // 10x tighter than required
    EXPECT_DOUBLE_EQ(region.enclosed_volume, volume);
  }
}

TEST(ImplicitVoxelizer, BoxVolumeIsExactForOffGridFaces) {
  const GridSpec grid = centredGrid(50, 0.5);
  const Region region = voxelizeImplicit(box({0.71, 0.453, 0.333}, {0.013, -0.02, 0.031}), grid);
  const double exact = 0.71 * 0.453 * 0.333;
  EXPECT_NEAR(region.enclosed_volume, exact, 1e-3 * exact);
  // Away from edges a face voxel holds exactly the fraction the face leaves it.
  const glm::dvec3 h = grid.voxelSize();
  const int i = static_cast<int>(std::floor((0.013 + 0.355 + 0.5) / h.x));  // voxel holding the +x face
  const double x0 = grid.center(i, 25, 25).x - 0.5 * h.x;
  const double expected = (0.013 + 0.355 - x0) / h.x;
  EXPECT_NEAR(region.coverage[grid.index(i, 25, 25)], expected, 1e-5);
}

TEST(ImplicitVoxelizer, SupersamplingConvergesToTheExactVolume) {
  const GridSpec grid = centredGrid(32, 0.55);
  const double exact = 4.0 / 3.0 * std::numbers::pi * 0.125;
  double previous_error = 1.0;
  for (int s : {1, 4, 12}) {
    ProceduralOptions options;
    options.supersample = s;
    options.antialias = false;
    const double v = voxelizeImplicit(sphere(0.5), grid, options).enclosed_volume;
    const double error = std::abs(v - exact) / exact;
    EXPECT_LT(error, std::max(previous_error, 2e-3)) << "S = " << s;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-3);
  ProceduralOptions bad;
  bad.supersample = 0;
  EXPECT_THROW(voxelizeImplicit(sphere(0.5), grid, bad), std::invalid_argument);
  bad.supersample = 17;
  EXPECT_THROW(voxelizeImplicit(sphere(0.5), grid, bad), std::invalid_argument);
  EXPECT_THROW(voxelizeImplicit(ImplicitSolid{}, grid), std::invalid_argument) << "no distance function";
}

TEST(ImplicitVoxelizer, NothingOutsideTheBoundsAndOpenSurfacesEncloseNothing) {
  const GridSpec grid = centredGrid(24, 0.6);
  ImplicitSolid s = sphere(0.3, {0.2, 0.0, 0.0});
  s.material.name = "ball";
  const Region ball = voxelizeImplicit(s, grid);
  EXPECT_EQ(ball.name, "sphere");
  EXPECT_EQ(ball.material.name, "ball");
  EXPECT_TRUE(ball.ior.empty()) << "no per-voxel n without an ior function";
  for (int k = 0; k < grid.dims.z; ++k)
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        if (glm::length(grid.center(i, j, k) - glm::dvec3(0.2, 0.0, 0.0)) > 0.3 + grid.voxelSize().x) {
          ASSERT_EQ(ball.coverage[grid.index(i, j, k)], 0.0f);
        }
      }
  s.open_surface = true;
  const Region sheet = voxelizeImplicit(s, grid);
  EXPECT_EQ(sheet.coverage, ball.coverage);
  EXPECT_EQ(sheet.enclosed_volume, 0.0);
  s.bounds = Bounds{};  // empty bounds: nothing to voxelise
  double reported = 0.0;
  const Region none = voxelizeImplicit(s, grid, {}, [&](double f) { reported = f; });
  EXPECT_EQ(coverageSum(none), 0.0);
  EXPECT_EQ(reported, 1.0);
}

TEST(ImplicitVoxelizer, IorIsTheMeanOverTheCoveredPart) {
  const GridSpec grid = centredGrid(16, 0.55);
  ImplicitSolid s = sphere(0.5);
  s.material.ior = 1.25f;
  s.ior = [](const glm::dvec3& x) { return 1.5 + 0.1 * x.x; };
  const Region region = voxelizeImplicit(s, grid);
  ASSERT_EQ(region.ior.size(), grid.count());
  for (std::size_t v = 0; v < grid.count(); ++v) {
    if (region.coverage[v] == 0.0f) {
      ASSERT_EQ(region.ior[v], 1.25f) << "outside: the material's n";
    } else {
      ASSERT_GE(region.ior[v], 1.5f - 0.0551f);
      ASSERT_LE(region.ior[v], 1.5f + 0.0551f);
    }
  }
  const std::size_t centre = grid.index(8, 8, 8);  // wholly inside: n at the voxel centre
  EXPECT_FLOAT_EQ(region.ior[centre], static_cast<float>(1.5 + 0.1 * grid.center(8, 8, 8).x));
}

TEST(ImplicitVoxelizer, DeterministicWhateverTheThreadCount) {
  const GridSpec grid = centredGrid(40, 0.6);
  const auto solids = proceduralSolids(parseProceduralSpec("procedural:wine_glass"), grid);
  ::setenv("EIKONAL_THREADS", "1", 1);
  const Region one = voxelizeImplicit(solids[0], grid);
  ::setenv("EIKONAL_THREADS", "3", 1);
  const Region three = voxelizeImplicit(solids[0], grid);
  ::unsetenv("EIKONAL_THREADS");
  EXPECT_EQ(one.coverage, three.coverage);
  EXPECT_EQ(one.enclosed_volume, three.enclosed_volume);
}

// Coverage and n as the definition has them: every voxel's S³ sub-samples, each weighed, summed in
// order. The voxelizer skips whole voxels and octants of sub-samples that the distance settles; its
// results must be these to the bit, for every shape (plain, and scaled unevenly and turned, whose
// distance is only a bound), with and without antialiasing, at S = 4 (octants of 2³) and, for the
// plain shapes, 6 (3³).
TEST(ImplicitVoxelizer, SkippedSubSamplesChangeNothing) {
  const GridSpec grid = centredGrid(14, 0.62);
  int shapes = 0;
  for (const ShapeDef& def : shapeDefs()) {
    for (const std::string extra : {"", ",scale=0.8:1.1:0.6,euler_deg=20:35:10"}) {
      if (def.name == "floor" && !extra.empty()) continue;  // the floor takes no scale
      const auto solids = proceduralSolids(parseProceduralSpec("procedural:" + def.name + extra), grid);
      for (const ImplicitSolid& solid : solids) {
        if (solid.open_surface) continue;  // a receiver: no coverage of its own to check
        for (const int S : {4, 6})
          for (const bool antialias : {true, false}) {
            if (S == 6 && !extra.empty()) continue;
            ProceduralOptions options;
            options.supersample = S;
            options.antialias = antialias;
            const Region region = voxelizeImplicit(solid, grid, options);
            const double sub_width = std::min({grid.voxelSize().x, grid.voxelSize().y, grid.voxelSize().z}) / S;
            int partial = 0;
            for (int k = 0; k < grid.dims.z; ++k)
              for (int j = 0; j < grid.dims.y; ++j)
                for (int i = 0; i < grid.dims.x; ++i) {
                  const glm::dvec3 c = grid.center(i, j, k);
                  double inside = 0.0, n_sum = 0.0;
                  for (int sz = 0; sz < S; ++sz)
                    for (int sy = 0; sy < S; ++sy)
                      for (int sx = 0; sx < S; ++sx) {
                        const glm::dvec3 offset = (glm::dvec3(sx, sy, sz) + 0.5) / static_cast<double>(S) - 0.5;
                        const glm::dvec3 p = c + glm::dvec3(offset.x * grid.voxelSize().x, offset.y * grid.voxelSize().y,
                                                            offset.z * grid.voxelSize().z);
                        const double ds = solid.sdf(p);
                        const double w = antialias ? std::clamp(0.5 - ds / sub_width, 0.0, 1.0) : (ds < 0.0 ? 1.0 : 0.0);
                        if (w > 0.0) {
                          inside += w;
                          if (solid.ior) n_sum += w * solid.ior(p);
                        }
                      }
                  const std::size_t at = grid.index(i, j, k);
                  const float want = static_cast<float>(inside) * (1.0f / static_cast<float>(S * S * S));
                  if (want > 0.0f && want < 1.0f) ++partial;
                  ASSERT_EQ(region.coverage[at], want) << def.name << extra << ", S " << S << ", antialias " << antialias
                                                       << ", voxel " << i << " " << j << " " << k;
                  if (solid.ior && inside > 0.0 && want < 1.0f) {
                    ASSERT_EQ(region.ior[at], static_cast<float>(n_sum / inside));
                  }
                }
            EXPECT_GT(partial, 0) << def.name << extra;  // the surface is there
          }
        ++shapes;
      }
    }
  }
  EXPECT_GT(shapes, 10);
}

}  // namespace
}  // namespace eik
