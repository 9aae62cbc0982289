// The quiet map (quiet_map.h): a box it calls quiet must give one material with constant optics at
// every point, checked by sampling the volume itself at random points of random boxes; boxes across
// an interface, a gradient or an absorption edge are never quiet; space well away from them is.
#include "lightsim/quiet_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>

#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

using namespace test_scenes;

// Samples `samples` random points of each of `boxes` random boxes (edges up to 8 voxels, centres
// anywhere in the grid grown by 4 voxels); for every box the map calls quiet, every sample must see
// the material, n, ∇n and σa of the box's centre. Returns how many boxes were quiet.
int checkQuietBoxesAreUniform(const VolumeSampler& sampler, const QuietMap& map, int boxes, int samples) {
  std::mt19937 rng(12345);
  const GridSpec& g = sampler.grid();
  const double h = sampler.h();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int quiet = 0;
  for (int b = 0; b < boxes; ++b) {
    glm::dvec3 centre, half;
    for (int a = 0; a < 3; ++a) {
      centre[a] = g.bounds_min[a] - 4.0 * h + unit(rng) * (g.extent()[a] + 8.0 * h);
      half[a] = unit(rng) * 4.0 * h;
    }
    if (!map.quiet(centre - half, centre + half)) continue;
    ++quiet;
    const int material = sampler.materialAt(centre);
    const glm::dvec4 optics = sampler.iorAndGradient(centre);
    const glm::dvec3 sigma = sampler.hasAbsorption() ? sampler.sigmaA(centre) : glm::dvec3(0.0);
    EXPECT_EQ(optics.y, 0.0);
    EXPECT_EQ(optics.z, 0.0);
    EXPECT_EQ(optics.w, 0.0);
    for (int s = 0; s < samples; ++s) {
      glm::dvec3 p;
      for (int a = 0; a < 3; ++a) p[a] = centre[a] + (2.0 * unit(rng) - 1.0) * half[a];
      // Trilinear weights of equal values sum to the value within a few ulps.
      const glm::dvec4 o = sampler.iorAndGradient(p);
      const bool same = sampler.materialAt(p) == material && std::fabs(o.x - optics.x) < 1e-12 &&
                        glm::dvec3(o.y, o.z, o.w) == glm::dvec3(0.0) &&
                        (!sampler.hasAbsorption() || glm::length(sampler.sigmaA(p) - sigma) < 1e-12);
      EXPECT_TRUE(same) << "box " << b << " sample " << s;
      if (!same) return quiet;
    }
  }
  return quiet;
}

TEST(QuietMap, SharpSphereQuietBoxesAreUniformAndTheSurfaceIsNot) {
  const Volume volume = sharpVolume("procedural:sphere,r=0.5,ior=1.5", 32, cube(0.8));
  const VolumeSampler sampler(volume);
  const QuietMap map = sampler.quietMap();
  ASSERT_FALSE(map.empty());
  EXPECT_GT(map.noisyBricks(), 0u);
  const int quiet = checkQuietBoxesAreUniform(sampler, map, 4000, 40);
  // Most of the grid is air or the sphere's inside, away from its surface (a band of noisy bricks
  // about one brick thick): well over a tenth of random boxes must be quiet, or the map is useless.
  EXPECT_GT(quiet, 400);
  const double h = sampler.h();
  // A box astride the surface, anywhere on it, and a tiny one on it.
  for (const glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::normalize(glm::dvec3(1, 1, -1))}) {
    const glm::dvec3 on = 0.5 * dir;
    EXPECT_FALSE(map.quiet(on - 2.0 * h, on + 2.0 * h));
    EXPECT_FALSE(map.quiet(on - 0.01 * h, on + 0.01 * h));
  }
  // A segment from the air through the sphere is not quiet; the sphere's core and the grid's
  // corner (more than two bricks from the surface) are.
  EXPECT_FALSE(map.quiet(glm::dvec3(-0.05, -0.75, -0.05), glm::dvec3(0.05, 0.75, 0.05)));
  EXPECT_TRUE(map.quiet(glm::dvec3(-0.1), glm::dvec3(0.1)));
  EXPECT_TRUE(map.quiet(glm::dvec3(0.65), glm::dvec3(0.78)));
  // Beyond the grid, samples clamp to its edge voxels: air there, so quiet however far.
  EXPECT_TRUE(map.quiet(glm::dvec3(0.9, -3.0, 0.9), glm::dvec3(5.0, 3.0, 5.0)));
  EXPECT_FALSE(map.quiet(glm::dvec3(-0.1, -9.0, -0.1), glm::dvec3(0.1, 9.0, 0.1)));  // clamps across the sphere
  EXPECT_FALSE(map.quiet(glm::dvec3(0.0), glm::dvec3(std::numeric_limits<double>::infinity())));
}

TEST(QuietMap, SmoothedSphereQuietBoxesHaveNoGradient) {
  const Volume volume = glassSphere(32, cube(0.8));
  const VolumeSampler sampler(volume);
  const QuietMap map = sampler.quietMap();
  const int quiet = checkQuietBoxesAreUniform(sampler, map, 4000, 40);
  EXPECT_GT(quiet, 200);
  // The smoothed boundary layer (∇n ≠ 0 over a few voxels) is never quiet.
  const double h = sampler.h();
  EXPECT_FALSE(map.quiet(glm::dvec3(0.5 - h, 0.0, 0.0), glm::dvec3(0.5 + h, 0.01, 0.01)));
  EXPECT_TRUE(map.quiet(glm::dvec3(0.66), glm::dvec3(0.78)));
}

TEST(QuietMap, AbsorptionEdgesAreNotQuietAndUniformAbsorptionIs) {
  const Bounds bounds = cube(0.5);
  const Volume absorbing = slab(32, bounds, -0.1, 0.2, 1.0, glm::dvec3(2.0, 1.0, 0.5));
  const VolumeSampler sampler(absorbing);
  ASSERT_TRUE(sampler.hasAbsorption());
  const QuietMap map = sampler.quietMap();
  checkQuietBoxesAreUniform(sampler, map, 2000, 20);
  EXPECT_FALSE(map.quiet(glm::dvec3(-0.1, 0.05, -0.1), glm::dvec3(0.1, 0.15, 0.1)));  // the slab's top
  const Volume uniform = uniformVolume(cubicGrid(16, 0.5), 1.33, glm::dvec3(0.5));
  const VolumeSampler uniform_sampler(uniform);
  const QuietMap all = uniform_sampler.quietMap();
  EXPECT_EQ(all.noisyBricks(), 0u);
  EXPECT_TRUE(all.quiet(glm::dvec3(-0.5), glm::dvec3(0.5)));
}

// The brick size: with sharp interfaces a flag per voxel up to 100 voxels an axis, bricks of 2³
// beyond (the 128³ sphere's 132³ grid: a cheaper map whose tables stay in cache); without them
// (a smoothed n, whose band of ∇n ≠ 0 is wide) per voxel up to 160.
TEST(QuietMap, SharpVolumesTakeBricksFromAHundredVoxels) {
  for (const int n : {100, 101}) {
    const GridSpec grid = boxGrid({n, 4, 4}, 0.01);
    const std::vector<glm::vec4> ior_grad(grid.count(), glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
    const std::vector<glm::vec4> distances(grid.count(), glm::vec4(1.0f));
    InterfaceTable table;
    table.slots.resize(1);
    table.band = 0.04;
    const QuietMap sharp(grid, ior_grad, distances, table, {});
    const QuietMap smooth(grid, ior_grad, {}, InterfaceTable{}, {});
    EXPECT_EQ(sharp.brickVoxels(), n <= 100 ? 1 : 2) << n;
    EXPECT_EQ(smooth.brickVoxels(), 1) << n;
    EXPECT_EQ(sharp.noisyBricks(), 0u);
    EXPECT_TRUE(sharp.quiet(grid.bounds_min, grid.bounds_max));
  }
}

// From flagged voxels (VolumeSampler::absorberMap): a box is quiet exactly when no trilinear sample
// in it takes a flagged voxel as one of its eight taps (taps floor(q − ½) and the next, at voxel
// coordinate q; 8³ voxels of 1/8, so brick = voxel); an absorbing sphere's map is not quiet at it.
// The noisy bricks of a sharp volume, made by layers of bricks in parallel, are exactly those a
// plain scan finds: a brick is noisy when a voxel in it is noisy itself (a distance exactly 0 here)
// or differs from a face neighbour (the other side of a sign change of a slot's distance, or of a
// σa edge). 170 voxels on x make bricks of 2, so pairs of voxels that differ across two layers of
// bricks (z) are met on both sides; the answer is read from the summed-area table, brick by brick.
TEST(QuietMap, TheNoisyBricksAreThoseANoisyVoxelOrADifferingFaceNeighbourMakes) {
  const GridSpec grid = boxGrid({170, 9, 23}, 0.01);
  const std::size_t n = grid.count();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Two slots: slot 0 negative inside a few random balls, slot 1 below a tilted plane; σa changes on
  // one random voxel in 500; one distance in 300 is exactly 0.
  struct Ball { glm::dvec3 c; double r; };
  std::vector<Ball> balls;
  for (int b = 0; b < 6; ++b) balls.push_back({{unit(rng) * 170, unit(rng) * 9, unit(rng) * 23}, 2.0 + 4.0 * unit(rng)});
  std::vector<glm::vec4> ior_grad(n, glm::vec4(1.0f, 0.0f, 0.0f, 0.0f)), distances(n);
  std::vector<glm::vec3> sigma(n, glm::vec3(0.0f));
  for (int z = 0; z < 23; ++z)
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 170; ++x) {
        const std::size_t i = grid.index(x, y, z);
        double d0 = 1.0;
        for (const Ball& b : balls) d0 = std::min(d0, glm::length(glm::dvec3(x, y, z) - b.c) - b.r);
        const double d1 = 0.3 * x + 0.5 * y - 1.7 * z + 5.0;
        distances[i] = glm::vec4(static_cast<float>(d0), static_cast<float>(d1), 1.0f, 1.0f);
        if (unit(rng) < 1.0 / 300.0) distances[i].x = 0.0f;
        if (unit(rng) < 1.0 / 500.0) sigma[i] = glm::vec3(0.5f);
      }
  InterfaceTable table;
  table.slots.resize(2);
  table.band = 0.04;
  // The distances' signs a voxel, as VolumeSampler passes them (bit k: < 0, bit 4 + k: = 0).
  std::vector<std::uint8_t> signs(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 2; ++k)
      signs[i] |= static_cast<std::uint8_t>((distances[i][k] < 0.0f ? 1 : 0) << k | (distances[i][k] == 0.0f ? 1 : 0) << (4 + k));
  // From the vectors, from views with the signs, and from the signs without σa (the constant-n
  // materials' own scan): each against the plain scan below.
  for (int form = 0; form < 3; ++form) {
    const bool with_sigma = form < 2;
    QuietMap::FieldViews views;
    views.ior = &ior_grad[0].x;
    views.ior_stride = 4;
    views.grad = &ior_grad[0].y;
    views.grad_stride = 4;
    views.distances = &distances[0].x;
    views.slot_signs = signs.data();
    if (with_sigma) views.sigma_a = &sigma[0].x;
    const QuietMap map = form == 0 ? QuietMap(grid, ior_grad, distances, table, sigma) : QuietMap(grid, views, table);
    ASSERT_EQ(map.brickVoxels(), 2);
    // The plain scan.
    auto signature = [&](std::size_t i) {
      return std::tuple<bool, bool, float>(distances[i].x < 0.0f, distances[i].y < 0.0f, with_sigma ? sigma[i].x : 0.0f);
    };
    const glm::ivec3 bricks = map.bricks();
    std::vector<std::uint8_t> noisy(static_cast<std::size_t>(bricks.x) * bricks.y * bricks.z, 0);
    auto flag = [&](int x, int y, int z) { noisy[static_cast<std::size_t>(x / 2 + bricks.x * (y / 2 + bricks.y * (z / 2)))] = 1; };
    for (int z = 0; z < 23; ++z)
      for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 170; ++x) {
          const std::size_t i = grid.index(x, y, z);
          if (distances[i].x == 0.0f || distances[i].y == 0.0f) flag(x, y, z);
          const int nx[6] = {x - 1, x + 1, x, x, x, x}, ny[6] = {y, y, y - 1, y + 1, y, y}, nz[6] = {z, z, z, z, z - 1, z + 1};
          for (int a = 0; a < 6; ++a) {
            if (nx[a] < 0 || ny[a] < 0 || nz[a] < 0 || nx[a] >= 170 || ny[a] >= 9 || nz[a] >= 23) continue;
            if (signature(grid.index(nx[a], ny[a], nz[a])) != signature(i)) flag(x, y, z);
          }
        }
    // The table's count in each single brick.
    const std::vector<std::uint32_t>& sat = map.table();
    auto at = [&](int i, int j, int k) {
      return static_cast<std::int64_t>(sat[static_cast<std::size_t>(i) + static_cast<std::size_t>(bricks.x + 1) *
                                            (static_cast<std::size_t>(j) + static_cast<std::size_t>(bricks.y + 1) * static_cast<std::size_t>(k))]);
    };
    int checked_noisy = 0;
    for (int k = 0; k < bricks.z; ++k)
      for (int j = 0; j < bricks.y; ++j)
        for (int i = 0; i < bricks.x; ++i) {
          const std::int64_t count = at(i + 1, j + 1, k + 1) - at(i, j + 1, k + 1) - at(i + 1, j, k + 1) - at(i + 1, j + 1, k) +
                                     at(i, j, k + 1) + at(i, j + 1, k) + at(i + 1, j, k) - at(i, j, k);
          const bool expected = noisy[static_cast<std::size_t>(i + bricks.x * (j + bricks.y * k))] != 0;
          ASSERT_EQ(count, expected ? 1 : 0) << "brick " << i << " " << j << " " << k;
          checked_noisy += expected ? 1 : 0;
        }
    EXPECT_EQ(static_cast<std::size_t>(checked_noisy), map.noisyBricks());
    EXPECT_GT(checked_noisy, 100);
    EXPECT_LT(static_cast<std::size_t>(checked_noisy), noisy.size() / 2);
  }
}

TEST(QuietMap, FlaggedVoxelsMakeTheBoxesWhoseSamplesTouchThemNoisy) {
  const GridSpec grid = cubicGrid(8, 0.5);  // [−0.5, 0.5]³, voxel edge 1/8
  std::vector<std::uint8_t> flags(grid.count(), 0);
  flags[grid.index(3, 4, 5)] = 1;
  const QuietMap map(grid, flags);
  ASSERT_FALSE(map.empty());
  EXPECT_EQ(map.noisyBricks(), 1u);
  auto world = [&](double qx, double qy, double qz) { return grid.bounds_min + glm::dvec3(qx, qy, qz) / 8.0; };
  // At voxel x-coordinate 4.4 the x-taps are 3 and 4: it touches voxel 3; at 4.6 they are 4 and 5.
  EXPECT_FALSE(map.quiet(world(4.4, 4.5, 5.5), world(4.4, 4.5, 5.5)));
  EXPECT_TRUE(map.quiet(world(4.6, 4.5, 5.5), world(4.6, 4.5, 5.5)));
  EXPECT_TRUE(map.quiet(world(4.6, 0.0, 0.0), world(8.0, 8.0, 8.0)));
  EXPECT_FALSE(map.quiet(world(4.4, 0.0, 0.0), world(8.0, 8.0, 8.0)));
  EXPECT_TRUE(map.quiet(world(0.0, 0.0, 0.0), world(2.4, 8.0, 8.0)));  // x-taps up to 2: clear of 3
  EXPECT_FALSE(map.quiet(world(0.0, 0.0, 0.0), world(2.6, 8.0, 8.0)));
  const VolumeSampler absorbing(absorbingSphere(16, cube(0.5), 0.3, 2.0));
  const QuietMap absorbers = absorbing.absorberMap();
  EXPECT_FALSE(absorbers.quiet(glm::dvec3(-0.05), glm::dvec3(0.05)));
  EXPECT_TRUE(absorbers.quiet(glm::dvec3(0.42), glm::dvec3(0.5)));  // a corner of the grid, clear of it
}

// Each brick's clearance is its chessboard distance to the nearest flagged brick (capped at 255),
// as a brute-force search over every flagged brick finds it: a few scattered flags, a grid with a
// single one in a corner (distances across the whole grid), and none at all.
TEST(QuietMap, ClearanceIsTheChessboardDistanceToTheNearestNoisyBrick) {
  for (const int case_index : {0, 1, 2}) {
    const int n = 23;
    const GridSpec grid = cubicGrid(n, 0.5);
    std::vector<std::uint8_t> flags(grid.count(), 0);
    std::vector<glm::ivec3> flagged;
    std::mt19937 rng(11);
    std::uniform_int_distribution<int> voxel(0, n - 1);
    if (case_index == 0)
      for (int i = 0; i < 12; ++i) flagged.emplace_back(voxel(rng), voxel(rng), voxel(rng));
    if (case_index == 1) flagged.emplace_back(n - 1, 0, n - 2);
    for (const glm::ivec3& v : flagged) flags[grid.index(v.x, v.y, v.z)] = 1;
    const QuietMap map(grid, flags);
    ASSERT_EQ(map.brickVoxels(), 1);
    const std::vector<std::uint8_t>& clearance = map.clearances();
    ASSERT_EQ(clearance.size(), grid.count());
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          int expected = 255;
          for (const glm::ivec3& v : flagged)
            expected = std::min(expected, std::max({std::abs(x - v.x), std::abs(y - v.y), std::abs(z - v.z)}));
          ASSERT_EQ(static_cast<int>(clearance[grid.index(x, y, z)]), expected)
              << "case " << case_index << " at " << x << "," << y << "," << z;
        }
  }
}

// The answer from a brick's clearance (one lookup) is the summed-area table's (eight): random
// boxes from a voxel to most of the grid, around scattered flagged voxels, against a brute-force
// scan of the voxels every sample in the box takes as taps. At 200 voxels an axis the bricks are
// 2³ voxels, so the scan is over bricks too.
TEST(QuietMap, EveryBoxIsQuietExactlyWhenNoFlaggedBrickIsInIt) {
  for (const int n : {24, 200}) {
    const GridSpec grid = cubicGrid(n, 0.5);
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> voxel(0, n - 1);
    std::vector<std::uint8_t> flags(grid.count(), 0);
    const int flagged = n == 24 ? 30 : 300;
    for (int i = 0; i < flagged; ++i) flags[grid.index(voxel(rng), voxel(rng), voxel(rng))] = 1;
    const QuietMap map(grid, flags);
    const int brick = map.brickVoxels();
    EXPECT_EQ(brick, n <= 160 ? 1 : 2);  // flags of the voxels (absorbers): per voxel up to 160
    std::vector<std::uint8_t> brick_flag(static_cast<std::size_t>(map.bricks().x) * map.bricks().y * map.bricks().z, 0);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          if (flags[grid.index(x, y, z)])
            brick_flag[static_cast<std::size_t>(x / brick + map.bricks().x * (y / brick + map.bricks().y * (z / brick)))] = 1;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    int quiet = 0, boxes = 3000;
    for (int b = 0; b < boxes; ++b) {
      // Voxel coordinates of the box's corners: an edge of up to a voxel, eight, or half the grid.
      const double scale = b % 3 == 0 ? 1.0 : b % 3 == 1 ? 8.0 : 0.5 * n;
      glm::dvec3 q0, q1;
      int v0[3], v1[3];
      for (int a = 0; a < 3; ++a) {
        q0[a] = -2.0 + unit(rng) * (n + 4.0);
        q1[a] = q0[a] + unit(rng) * scale;
        // The taps of the samples in [q0, q1] on this axis (quiet_map.cpp, trilinearTaps).
        v0[a] = static_cast<int>(std::floor(std::clamp(q0[a] - 0.5, 0.0, n - 1.0)));
        v1[a] = std::min(n - 1, static_cast<int>(std::floor(std::clamp(q1[a] - 0.5, 0.0, n - 1.0))) + 1);
      }
      bool any = false;
      for (int z = v0[2] / brick; z <= v1[2] / brick && !any; ++z)
        for (int y = v0[1] / brick; y <= v1[1] / brick && !any; ++y)
          for (int x = v0[0] / brick; x <= v1[0] / brick && !any; ++x)
            any = brick_flag[static_cast<std::size_t>(x + map.bricks().x * (y + map.bricks().y * z))] != 0;
      const bool answer = map.quiet(grid.bounds_min + q0 * (1.0 / n), grid.bounds_min + q1 * (1.0 / n));
      ASSERT_EQ(answer, !any) << "n " << n << " box " << b;
      quiet += answer ? 1 : 0;
    }
    // Both answers are common, or the comparison proves little.
    EXPECT_GT(quiet, boxes / 10) << n;
    EXPECT_LT(quiet, boxes * 9 / 10) << n;
  }
}

}  // namespace
}  // namespace eik
