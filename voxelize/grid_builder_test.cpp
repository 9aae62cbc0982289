#include "voxelize/grid_builder.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace eik {
namespace {

Bounds box(glm::dvec3 lo, glm::dvec3 hi) {
  Bounds b;
  b.min = lo;
  b.max = hi;
  return b;
}

void expectCubicVoxels(const GridSpec& g, double h) {
  const glm::dvec3 v = g.voxelSize();
  EXPECT_NEAR(v.x, h, 1e-12);
  EXPECT_NEAR(v.y, h, 1e-12);
  EXPECT_NEAR(v.z, h, 1e-12);
}

TEST(GridBuilder, LongestAxisGetsResVoxelsPlusPadding) {
  const GridSpec g = makeGrid(box(glm::dvec3(-0.5), glm::dvec3(0.5)), 128, 3.0);
  EXPECT_EQ(g.dims, glm::ivec3(134));
  expectCubicVoxels(g, 1.0 / 128.0);
  // Centred on the objects, with exactly 3 voxels of air on every side.
  EXPECT_NEAR(g.bounds_min.x, -0.5 - 3.0 / 128.0, 1e-12);
  EXPECT_NEAR(g.bounds_max.z, 0.5 + 3.0 / 128.0, 1e-12);
}

TEST(GridBuilder, OtherAxesAreRoundedUp) {
  const Bounds objects = box({0, 0, 0}, {2.0, 1.0, 0.33});
  const GridSpec g = makeGrid(objects, 100, 2.0);
  // h = 0.02: x 100, y 50, z ceil(16.5) = 17, each plus 2·2.
  EXPECT_EQ(g.dims, glm::ivec3(104, 54, 21));
  expectCubicVoxels(g, 0.02);
  EXPECT_NEAR(0.5 * (g.bounds_min.z + g.bounds_max.z), 0.165, 1e-12);
  // The objects fit with at least the padding on every side.
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(g.bounds_min[a], objects.min[a] - 2.0 * 0.02 + 1e-12);
    EXPECT_GE(g.bounds_max[a], objects.max[a] + 2.0 * 0.02 - 1e-12);
  }
}

TEST(GridBuilder, FractionalPadRoundsUpToWholeVoxels) {
  const GridSpec g = makeGrid(box(glm::dvec3(0), glm::dvec3(1)), 10, 0.5);
  EXPECT_EQ(g.dims, glm::ivec3(12));
  EXPECT_EQ(makeGrid(box(glm::dvec3(0), glm::dvec3(1)), 10, 0.0).dims, glm::ivec3(10));
}

TEST(GridBuilder, FlatObjectsGetAtLeastOneVoxel) {
  // A floor plane alone: zero height.
  const GridSpec g = makeGrid(box({-1, -0.5, -1}, {1, -0.5, 1}), 64, 2.0);
  EXPECT_EQ(g.dims, glm::ivec3(68, 5, 68));
  expectCubicVoxels(g, 2.0 / 64.0);
}

TEST(GridBuilder, ExplicitBoundsAreUsedAsGiven) {
  const Bounds b = box({-1, 0, 0}, {1, 0.5, 0.26});
  const GridSpec g = makeGrid(box(glm::dvec3(0), glm::dvec3(0.1)), 100, 3.0, b);
  EXPECT_EQ(g.bounds_min, b.min);
  EXPECT_EQ(g.bounds_max, b.max);
  EXPECT_EQ(g.dims, glm::ivec3(100, 25, 13));  // h = 0.02; 0.26/0.02 = 13
  expectCubicVoxels(g, 0.02);
}

TEST(GridBuilder, Errors) {
  const Bounds unit = box(glm::dvec3(0), glm::dvec3(1));
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message([&] { makeGrid(unit, 0, 2); }).rfind("--res:", 0), 0u);
  EXPECT_EQ(message([&] { makeGrid(unit, 100000, 2); }).rfind("--res:", 0), 0u);
  EXPECT_EQ(message([&] { makeGrid(unit, 64, -1); }).rfind("--pad:", 0), 0u);
  EXPECT_NE(message([&] { makeGrid(Bounds{}, 64, 2); }), "");
  EXPECT_NE(message([&] { makeGrid(box(glm::dvec3(1), glm::dvec3(1)), 64, 2); }), "");
  EXPECT_EQ(message([&] { makeGrid(unit, 64, 2, box({0, 0, 0}, {1, -1, 1})); }).rfind("--bounds: y:", 0), 0u);
  // A thin, long object at a high resolution would need more than kMaxGridDim voxels across.
  EXPECT_NE(message([&] { makeGrid(box(glm::dvec3(0), glm::dvec3(1)), 4096, 100); }), "");
  // The limit is the writer's (1024, core/limits.h), checked before any work; the padding that
  // pushes a grid over it is named, and a huge --pad neither overflows nor blames --res.
  EXPECT_EQ(message([&] { makeGrid(unit, 1025, 0); }).rfind("--res:", 0), 0u);
  EXPECT_EQ(message([&] { makeGrid(unit, 1020, 3); }).rfind("--pad:", 0), 0u);
  EXPECT_EQ(message([&] { makeGrid(unit, 64, 1e9); }).rfind("--pad:", 0), 0u);
  EXPECT_NO_THROW(makeGrid(unit, 1018, 3));
}

TEST(GridBuilder, ParseBounds) {
  const Bounds b = parseBounds("-1,-2,-3,1,2,3");
  EXPECT_EQ(b.min, glm::dvec3(-1, -2, -3));
  EXPECT_EQ(b.max, glm::dvec3(1, 2, 3));
  EXPECT_THROW(parseBounds("0,0,0,1,1"), InputError);
  EXPECT_THROW(parseBounds("0,0,0,1,1,x"), InputError);
  EXPECT_THROW(parseBounds("0,0,0,1,0,1"), InputError);
}

TEST(Bounds, ExtendAndEmpty) {
  Bounds b;
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(b.extent(), glm::dvec3(0));
  b.extend(glm::dvec3(1, 2, 3));
  EXPECT_FALSE(b.empty());
  b.extend(box({-1, 0, 0}, {0, 5, 0}));
  EXPECT_EQ(b.min, glm::dvec3(-1, 0, 0));
  EXPECT_EQ(b.max, glm::dvec3(1, 5, 3));
  EXPECT_TRUE(b.contains(box({0, 1, 1}, {1, 2, 2})));
  EXPECT_FALSE(b.contains(box({0, 1, 1}, {1, 6, 2})));
}

}  // namespace
}  // namespace eik
