// The scene's ground map (viewer/ground_map.h) against the maps it sums: each map's change read as
// the shader reads it (bilinear, less the direct light), the union of the footprints, the finest
// map's lattice kept, and fields that bilinear filtering reproduces exactly (linear ones) coming
// back exactly at any point.
#include "viewer/ground_map.h"
#include "viewer/shadow_edge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

namespace eik {
namespace {

// A map on the plane y = 0 (volume space) whose irradiance is E(u, v) = a + b·u + c·v at texel
// centres (linear: bilinear filtering reproduces it between them).
ReceiverMap linearMap(glm::dvec2 origin, double pitch, glm::ivec2 texels, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  ReceiverMap map;
  map.point = glm::dvec3(0.0);
  map.normal = glm::dvec3(0.0, 1.0, 0.0);
  receiverAxes(map.normal, map.u, map.v);
  map.origin = origin;
  map.pitch = pitch;
  map.texels = texels;
  map.irradiance.resize(map.texelCount() * 3);
  for (int j = 0; j < texels.y; ++j)
    for (int i = 0; i < texels.x; ++i) {
      const glm::dvec2 uv = origin + (glm::dvec2(i, j) + 0.5) * pitch;
      const glm::dvec3 e = a + b * uv.x + c * uv.y;
      for (int k = 0; k < 3; ++k) map.irradiance[3 * (static_cast<std::size_t>(j) * texels.x + i) + k] = static_cast<float>(e[k]);
    }
  return map;
}

ReceiverLayer layerAt(const ReceiverMap& map, const glm::dmat4& to_world, glm::dvec3 sun = glm::dvec3(2.0)) {
  ReceiverLayer layer;
  layer.map = &map;
  layer.to_world = to_world;
  layer.to_volume = glm::inverse(to_world);
  layer.light_pos = glm::dvec4(0.0, -1.0, 0.0, 0.0);  // straight down: direct light = sun on the plane
  layer.light_power = sun;
  return layer;
}

// The ground map filtered as its texture is (bilinear between texel centres, clamped).
glm::dvec4 sample(const GroundMap& g, const glm::dvec3& xw) {
  const glm::dvec2 at = (glm::dvec2(glm::dot(xw - g.point, g.u), glm::dot(xw - g.point, g.v)) - g.origin) / g.pitch - 0.5;
  const int i0 = static_cast<int>(std::floor(at.x)), j0 = static_cast<int>(std::floor(at.y));
  const double fx = at.x - i0, fy = at.y - j0;
  auto texel = [&](int i, int j) {
    i = std::clamp(i, 0, g.texels.x - 1);
    j = std::clamp(j, 0, g.texels.y - 1);
    const float* t = &g.rgba[4 * (static_cast<std::size_t>(j) * g.texels.x + i)];
    return glm::dvec4(t[0], t[1], t[2], t[3]);
  };
  return (1 - fx) * (1 - fy) * texel(i0, j0) + fx * (1 - fy) * texel(i0 + 1, j0) + (1 - fx) * fy * texel(i0, j0 + 1) +
         fx * fy * texel(i0 + 1, j0 + 1);
}

const glm::dvec3 kUp(0.0, 1.0, 0.0);

TEST(ReceiverChange, IsTheMapFilteredBilinearlyLessTheDirectLightAndNothingBeyondIt) {
  const ReceiverMap map = linearMap({-1.0, -1.0}, 0.1, {20, 20}, {1.0, 2.0, 3.0}, {0.5, 0.0, -0.5}, {0.0, 0.25, 0.0});
  const ReceiverLayer layer = layerAt(map, glm::translate(glm::dmat4(1.0), {0.3, 0.0, 0.0}));
  glm::dvec3 change;
  // World (0.3 + 0.37, 0, 0.21) is (u, v) = (0.37, −0.21) in the map (v = −z for this plane).
  ASSERT_TRUE(receiverChangeAt(layer, {0.67, 0.0, 0.21}, change));
  const glm::dvec3 expected = glm::dvec3(1.0, 2.0, 3.0) + glm::dvec3(0.5, 0.0, -0.5) * 0.37 +
                              glm::dvec3(0.0, 0.25, 0.0) * -0.21 - glm::dvec3(2.0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(change[c], expected[c], 1e-6) << c;
  EXPECT_FALSE(receiverChangeAt(layer, {1.31 + 0.3, 0.0, 0.0}, change));  // past the map's edge
  EXPECT_EQ(change, glm::dvec3(0.0));
}

// A map baked with a scene's lights summed (the manifest's "lights"): the change is the map less
// every light's direct light, read from the map itself or from the receiver texture the viewer
// makes of it (receiverTexels: the other lights taken off each texel, the first left to the
// shader). Here a sun straight down (2) and a point light 1.5 over the map's (0.4, 0, 0) (I = 3):
// its direct light 3·cos θ/r² varies across the map, so a texture that took it off at the wrong
// place, or not at all, would be off by up to 1.33.
TEST(ReceiverChange, TakesOffEveryLightTheMapWasBakedWith) {
  const ReceiverMap map = linearMap({-1.0, -1.0}, 0.05, {40, 40}, {4.0, 4.0, 4.0}, {0.5, 0.0, -0.5}, {0.0, 0.25, 0.0});
  ReceiverLayer layer = layerAt(map, glm::dmat4(1.0));
  ReceiverLayer::Light lamp;
  lamp.pos = glm::dvec4(0.4, 1.5, 0.0, 1.0);
  lamp.power = glm::dvec3(3.0);
  layer.other_lights = {lamp};
  const std::vector<float> texels = receiverTexels(layer, {});
  ReceiverLayer textured = layer;
  textured.texels = &texels;
  for (const glm::dvec3 x : {glm::dvec3(0.4, 0.0, 0.0), glm::dvec3(-0.6, 0.0, 0.3), glm::dvec3(0.8, 0.0, -0.7)}) {
    const glm::dvec3 to_lamp = glm::dvec3(lamp.pos) - x;
    const double r2 = glm::dot(to_lamp, to_lamp);
    const double lamp_light = 3.0 * (to_lamp.y / std::sqrt(r2)) / r2;
    glm::dvec3 plain, from_texture;
    ASSERT_TRUE(receiverChangeAt(layer, x, plain));
    ASSERT_TRUE(receiverChangeAt(textured, x, from_texture));
    const glm::dvec3 expected = glm::dvec3(4.0) + glm::dvec3(0.5, 0.0, -0.5) * x.x + glm::dvec3(0.0, 0.25, 0.0) * -x.z -
                                glm::dvec3(2.0) - glm::dvec3(lamp_light);
    // The map is linear, so bilinear filtering reproduces it; the lamp's light is curved, and the
    // texture holds it at texel centres: within the bilinear error of I·cos θ/r² over 0.05 (its
    // second derivative is under 10 here: 10·0.05²/8 ≈ 3·10⁻³).
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(plain[c], expected[c], 1e-5) << c;
      EXPECT_NEAR(from_texture[c], expected[c], 5e-3) << c;
    }
  }
}

TEST(GroundMap, SumsTheChangesOfTwoMapsAtAnyPointAndCoversTheirUnion) {
  // Two objects side by side, maps of different pitches and lattices, overlapping in the middle.
  const ReceiverMap left = linearMap({-1.0, -1.0}, 0.05, {40, 40}, {1.0, 1.5, 2.0}, {0.2, 0.0, 0.1}, {0.0, -0.3, 0.05});
  const ReceiverMap right = linearMap({-0.8, -0.9}, 0.07, {24, 26}, {3.0, 2.5, 2.0}, {-0.1, 0.4, 0.0}, {0.3, 0.0, 0.2});
  const std::vector<ReceiverLayer> layers = {layerAt(left, glm::translate(glm::dmat4(1.0), {-0.6, 0.0, 0.013})),
                                             layerAt(right, glm::translate(glm::dmat4(1.0), {0.55, 0.0, -0.031}))};
  const GroundMap g = combineReceiverMaps(layers, glm::dvec3(0.0), {1.0, 0.0, 0.0}, {0.0, 0.0, -1.0});
  EXPECT_DOUBLE_EQ(g.pitch, 0.05);  // the finer map's
  // The union: u from −1.6 (left's corner) to 0.55 − 0.8 + 1.68 = 1.43; v from −1.0 − 0.013 to
  // 0.9 + 0.031 + 0.92 ... within a texel.
  EXPECT_LE(g.origin.x, -1.6 + 1e-9);
  EXPECT_GT(g.origin.x, -1.6 - g.pitch);
  EXPECT_GE(g.origin.x + g.size().x, 1.43 - 1e-9);
  EXPECT_LT(g.origin.x + g.size().x, 1.43 + g.pitch);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-1.55, 1.38), z(-0.8, 0.8);
  int both = 0;
  for (int n = 0; n < 400; ++n) {
    const glm::dvec3 p(x(rng), 0.0, z(rng));
    glm::dvec3 sum(0.0), change;
    int covering = 0, near_edge = 0;
    for (const ReceiverLayer& layer : layers) {
      if (receiverChangeAt(layer, p, change)) {
        sum += change;
        ++covering;
      }
      // Within two texels of a map's edge the clamp and the coverage step are not linear.
      const glm::dvec3 q = glm::dvec3(layer.to_volume * glm::dvec4(p, 1.0));
      const glm::dvec2 st = (layer.map->planeCoordinates(q) - layer.map->origin) / layer.map->pitch;
      if (glm::any(glm::lessThan(glm::abs(st), glm::dvec2(2.0))) ||
          glm::any(glm::lessThan(glm::abs(st - glm::dvec2(layer.map->texels)), glm::dvec2(2.0))))
        ++near_edge;
    }
    if (near_edge) continue;
    both += covering == 2;
    const glm::dvec4 got = sample(g, p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], sum[c], 1e-5) << "at " << p.x << ", " << p.z << " channel " << c;
    EXPECT_NEAR(got.w, covering ? 1.0 : 0.0, 1e-9);
  }
  EXPECT_GT(both, 20) << "the points must include the maps' overlap";
}

TEST(GroundMap, KeepsTheFinestMapsLatticeAndStaysWithinItsTexelBudget) {
  // An arbitrary (non-linear) map: on its own lattice the ground map holds its texels less the
  // direct light, exactly.
  ReceiverMap map = linearMap({-0.5, -0.5}, 0.01, {100, 100}, glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(0.0f, 5.0f);
  for (float& e : map.irradiance) e = value(rng);
  const ReceiverMap other = linearMap({-0.5, -0.5}, 0.02, {50, 50}, glm::dvec3(2.0), glm::dvec3(0.0), glm::dvec3(0.0));
  const ReceiverLayer fine = layerAt(map, glm::translate(glm::dmat4(1.0), {0.1234, 0.0, -0.0567}));
  // The other object turned 90° about the vertical: its footprint still counts, its lattice not.
  const ReceiverLayer turned = layerAt(other, glm::rotate(glm::translate(glm::dmat4(1.0), {2.0, 0.0, 0.0}), glm::radians(90.0), kUp));
  const GroundMap g = combineReceiverMaps({fine, turned}, glm::dvec3(0.0), {1.0, 0.0, 0.0}, {0.0, 0.0, -1.0});
  ASSERT_DOUBLE_EQ(g.pitch, 0.01);
  EXPECT_GE(g.origin.x + g.size().x, 2.5 - 1e-9);  // the turned map reaches u = 2.5
  int checked = 0;
  for (int j = 5; j < 95; j += 7)
    for (int i = 5; i < 95; i += 7) {
      const glm::dvec3 centre = glm::dvec3(fine.to_world * glm::dvec4(map.texelCenter(i, j), 1.0));
      const glm::dvec4 got = sample(g, centre);
      const float* e = &map.irradiance[3 * (static_cast<std::size_t>(j) * 100 + i)];
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], e[c] - 2.0, 2e-5) << i << ", " << j;
      ++checked;
    }
  EXPECT_EQ(checked, 169);
  // A budget of 10,000 texels: the pitch grows, the union stays covered.
  const GroundMap small = combineReceiverMaps({fine, turned}, glm::dvec3(0.0), {1.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, 10000);
  EXPECT_LE(static_cast<std::size_t>(small.texels.x) * small.texels.y, 10000u);
  EXPECT_GT(small.pitch, 0.01);
  EXPECT_GE(small.origin.x + small.size().x, 2.5 - 1e-9);
  EXPECT_TRUE(combineReceiverMaps({}, glm::dvec3(0.0), {1.0, 0.0, 0.0}, {0.0, 0.0, -1.0}).rgba.empty());
}

}  // namespace
}  // namespace eik
