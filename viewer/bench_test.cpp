// The --bench machinery: the median, the bare march's exact step count (against the count worked
// out by hand for a straight ray through a homogeneous cube), its curved rays (the deflection of
// a linear index gradient), and that the report's figures are consistent. No time is asserted.
#include "viewer/bench.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "gl/context.h"
#include "lightsim/test_scenes.h"

#include <glm/gtc/matrix_transform.hpp>

namespace eik {
namespace {

// A 16³ cube [-0.5, 0.5]³ with n = n0 + g·x.
Volume cube(float n0, float g) { return test_scenes::linearIorVolume(test_scenes::cubicGrid(16, 0.5), n0, g); }

TEST(Bench, MedianOfOddAndEvenCounts) {
  EXPECT_EQ(medianOf({}), 0.0);
  EXPECT_EQ(medianOf({5.0}), 5.0);
  EXPECT_EQ(medianOf({9.0, 1.0, 5.0}), 5.0);
  EXPECT_EQ(medianOf({4.0, 1.0, 100.0, 2.0}), 3.0);
}

TEST(Bench, BareMarchCountsTheStepsOfAStraightRay) {
  gl::GlContext context;
  gl::ShaderLibrary shaders;
  BareMarch bare(shaders, cube(1.5f, 0.0f), glm::dmat4(1.0), 0.5);
  EXPECT_DOUBLE_EQ(bare.stepLength(), 1.0 / 32.0);  // half a voxel of 1/16
  const Camera camera{{0.0, 0.0, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 30.0};
  Image image = bare.render(camera, glm::ivec2(33, 33));
  // The centre ray crosses 1 unit of material from 1e-4·|extent| inside the front face: samples at
  // s0 + k/32 ≤ 1, i.e. 32 of them; constant n: it leaves along -z unbent.
  const float* centre = image.at(16, 16);
  EXPECT_NEAR(centre[3], 32.0f, 0.5f);
  EXPECT_NEAR(centre[0], 0.5f, 1e-5f);
  EXPECT_NEAR(centre[1], 0.5f, 1e-5f);
  EXPECT_NEAR(centre[2], 0.0f, 1e-5f);
  EXPECT_EQ(image.at(0, 0)[3], 0.0f);  // a corner ray misses the cube: no steps
  double sum = 0.0;
  for (std::size_t p = 3; p < image.pixels.size(); p += 4) sum += image.pixels[p];
  EXPECT_EQ(bare.countSteps(camera, glm::ivec2(33, 33)), sum);
  EXPECT_GT(sum, 32.0 * 50);  // many rays cross the cube
}

TEST(Bench, BareMarchBendsRaysTowardsHigherIndex) {
  gl::GlContext context;
  gl::ShaderLibrary shaders;
  // n = 1.5 + 0.2·x: over a path of length 1 along -z, w gains ∇n·L = (0.2, 0, 0), so the exit
  // direction is tilted by about 0.2 / 1.5 towards +x (first order).
  BareMarch bare(shaders, cube(1.5f, 0.2f), glm::dmat4(1.0), 0.25);
  const Camera camera{{0.0, 0.0, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 30.0};
  Image image = bare.render(camera, glm::ivec2(33, 33));
  const float dx = 2.0f * image.at(16, 16)[0] - 1.0f;
  EXPECT_NEAR(dx, 0.2f / 1.5f, 0.015f);
  EXPECT_NEAR(2.0f * image.at(16, 16)[1] - 1.0f, 0.0f, 1e-4f);
}

TEST(Bench, TheBareMarchOfASceneCrossesEveryObjectInTheOrderTheRayMeetsThem) {
  gl::GlContext context;
  gl::ShaderLibrary shaders;
  // Two cubes of constant n one behind the other on the camera's axis, and a third beside them
  // that the centre ray misses: straight rays, so each ray's steps are the sum of the boxes' own.
  const Volume a = cube(1.5f, 0.0f), b = cube(1.3f, 0.0f), c = cube(1.2f, 0.0f);
  const glm::dmat4 front(1.0), behind = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -2.0)),
                   aside = glm::translate(glm::dmat4(1.0), glm::dvec3(3.0, 0.0, -1.0));
  const Camera camera{{0.0, 0.0, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 30.0};
  const glm::ivec2 size(33, 33);
  const double alone = BareMarch(shaders, a, front, 0.5).countSteps(camera, size) +
                       BareMarch(shaders, b, behind, 0.5).countSteps(camera, size) +
                       BareMarch(shaders, c, aside, 0.5).countSteps(camera, size);
  for (const bool reversed : {false, true}) {
    std::vector<BareObject> objects = {{&a, front, "a"}, {&b, behind, "b"}, {&c, aside, "c"}};
    if (reversed) std::swap(objects.front(), objects.back());
    const BareMarch scene(shaders, objects, 0.5);
    EXPECT_EQ(scene.objectCount(), 3);
    const Image image = scene.render(camera, size);
    // The centre ray: 32 steps in each of the two cubes on the axis (as the one-cube test).
    EXPECT_NEAR(image.at(16, 16)[3], 64.0f, 1.0f) << "reversed " << reversed;
    // Every ray: the sum of the three boxes' steps, to a step where a ray grazes a box's edge.
    EXPECT_NEAR(scene.countSteps(camera, size), alone, 0.002 * alone) << "reversed " << reversed;
  }
  // The ground: a ray going down towards it leaves reflected (its hit test).
  SceneGroundSpec ground;
  ground.point = {0.0, -1.0, 0.0};
  const Camera above{{0.0, 2.0, 3.0}, {0.0, -1.0, 0.0}, {0.0, 1.0, 0.0}, 30.0};
  const Image with_ground = BareMarch(shaders, {{&a, front, "a"}}, 0.5, ground).render(above, size);
  const Image without = BareMarch(shaders, {{&a, front, "a"}}, 0.5).render(above, size);
  EXPECT_GT(2.0f * with_ground.at(16, 32)[1] - 1.0f, 0.0f);  // bottom row, up after the ground
  EXPECT_LT(2.0f * without.at(16, 32)[1] - 1.0f, 0.0f);      // still going down without it
  // No objects, or more than the samplers it has.
  EXPECT_THROW(BareMarch(shaders, std::vector<BareObject>{}, 0.5), InputError);
  EXPECT_THROW(BareMarch(shaders, std::vector<BareObject>(9, BareObject{&a, front, "a"}), 0.5), InputError);
}

TEST(Bench, ReportFiguresAreConsistent) {
  gl::GlContext context;
  gl::ShaderLibrary shaders;
  BareMarch bare(shaders, cube(1.5f, 0.1f), glm::dmat4(1.0), 0.5);
  const Camera camera{{0.0, 0.0, 3.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 30.0};
  const glm::ivec2 size(24, 16);
  int full_calls = 0;
  BenchReport r = runBench([&] { ++full_calls; bare.draw(camera, size); }, bare, camera, size, 5);
  EXPECT_EQ(full_calls, 6);  // 5 timed + 1 warm-up
  int calls = 0;
  EXPECT_EQ(timeFrames([&] { ++calls; }, 3, false).size(), 3u);
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(timeFrames([&] { ++calls; }, 2).size(), 2u);
  EXPECT_EQ(calls, 6);  // and one warm-up
  ASSERT_EQ(r.full.frame_ms.size(), 5u);
  ASSERT_EQ(r.bare.frame_ms.size(), 5u);
  EXPECT_EQ(r.full.median_ms, medianOf(r.full.frame_ms));
  EXPECT_EQ(r.bare.steps_per_frame, bare.countSteps(camera, size));
  EXPECT_EQ(r.full.steps_per_frame, r.bare.steps_per_frame);
  EXPECT_GT(r.bare.steps_per_frame, 0.0);
  EXPECT_NEAR(r.bare.samples_per_s, r.bare.steps_per_frame / (r.bare.median_ms / 1000.0), 1e-6 * r.bare.samples_per_s);
  EXPECT_NEAR(r.ratio_full_over_bare, r.full.median_ms / r.bare.median_ms, 1e-12);
  nlohmann::json j = benchReportJson(r);
  EXPECT_EQ(j["size"][0], 24);
  EXPECT_EQ(j["full"]["frame_ms"].size(), 5u);
  EXPECT_TRUE(j.contains("ratio_full_over_bare"));
  EXPECT_NE(formatBenchReport(r).find("full/bare"), std::string::npos);
}

}  // namespace
}  // namespace eik
