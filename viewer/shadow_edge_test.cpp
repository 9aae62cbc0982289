// Tests of viewer/shadow_edge: the shadow clearance of a sharp sphere against the exact distance
// of the light's ray from it, at two resolutions, and the receiver texture against a map of
// known light and shadow (the lit fraction of the texels the edge crosses, the change the ground
// shows on either side of the edge).
#include "viewer/shadow_edge.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/half_float.h"
#include "lightsim/test_scenes.h"

namespace eik {
namespace {

// A dark map on the plane y = 0, facing +y (ReceiverMap's point and normal as they start).
ReceiverMap floorMap(glm::dvec2 origin, double pitch, glm::ivec2 texels) {
  ReceiverMap map;
  receiverAxes(map.normal, map.u, map.v);
  map.origin = origin;
  map.pitch = pitch;
  map.texels = texels;
  map.irradiance.assign(3 * map.texelCount(), 0.0f);
  return map;
}

// A sphere R = 0.3 at height 0.5 under a light straight down: the ray up from (x, 0, z) passes
// the centre at ρ = |(x, z)|, so its least signed distance from the sphere is ρ − R, on both
// sides of the edge (inside, the deepest point of the chord is ρ − R below the surface). Its value
// is checked within a quarter voxel of the edge (the texels the lookup reads there; farther away
// only its sign matters, and blocks of texels get their corners' interpolation), its sign
// everywhere.
TEST(ShadowEdge, TheClearanceOfASphereIsTheLightRaysDistanceFromIt) {
  const double R = 0.3;
  double worst[2] = {0.0, 0.0};
  const int resolutions[2] = {32, 64};
  for (int r = 0; r < 2; ++r) {
    const Volume volume = test_scenes::sharpVolume("procedural:sphere,r=0.3,center=0:0.5:0,ior=1.5", resolutions[r],
                                                   test_scenes::box({-0.4, 0.1, -0.4}, {0.4, 0.9, 0.4}));
    const double h = volume.grid.voxelSize().x;
    const ReceiverMap map = floorMap({-0.45, -0.45}, 0.005, {180, 180});
    const std::vector<float> c = shadowClearance(volume, map, {0.0, -1.0, 0.0});
    ASSERT_EQ(c.size(), map.texelCount());
    int checked = 0;
    for (int j = 0; j < map.texels.y; ++j) {
      for (int i = 0; i < map.texels.x; ++i) {
        const glm::dvec3 p = map.texelCenter(i, j);
        const double exact = std::hypot(p.x, p.z) - R;
        const double got = c[static_cast<std::size_t>(j) * 180 + static_cast<std::size_t>(i)];
        if (std::abs(exact) < 0.25 * h) {  // the edge's texels: marched one by one
          worst[r] = std::max(worst[r], std::abs(got - exact) / h);
          ++checked;
        }
        if (std::abs(exact) < 0.02 * h) continue;  // the sign is right to within the error below
        if (exact > 0.0) {
          ASSERT_GT(got, 0.0) << p.x << ", " << p.z;  // lit, however far
        } else {
          ASSERT_LT(got, 0.0) << p.x << ", " << p.z;  // in the shadow
        }
      }
    }
    std::printf("%d³: clearance within %.4f voxel of ρ − R over the %d texels of the edge\n", resolutions[r], worst[r],
                checked);
    EXPECT_GT(checked, 400);  // a ring of 2·0.25h around R = 0.3 in texels of 0.005
  }
  // The voxelizer's distances and their trilinear interpolation near a surface of radius
  // R = 12–24 voxels: second order in h/R, a few hundredths of a voxel; the march finds the least distance of a grazing ray within h²/(32R). 0.06
  // voxel is a quarter of a texel of the bake's default pitch (a quarter voxel); in voxels the
  // error falls with the resolution (first order in h/R).
  EXPECT_LT(worst[0], 0.06);
  EXPECT_LT(worst[1], 0.6 * worst[0]);
  // The sun's ray missing the grid's box altogether: lit.
  const Volume volume = test_scenes::sharpVolume("procedural:sphere,r=0.3,center=0:0.5:0,ior=1.5", 32,
                                                 test_scenes::box({-0.4, 0.1, -0.4}, {0.4, 0.9, 0.4}));
  const ReceiverMap far = floorMap({2.0, 2.0}, 0.1, {4, 4});
  for (float v : shadowClearance(volume, far, {0.0, -1.0, 0.0})) EXPECT_GT(v, 0.0f);
  // No interfaces: no clearance.
  Volume smooth = volume;
  smooth.fields.erase("interfaces");
  smooth.metadata.erase("interfaces");
  EXPECT_TRUE(shadowClearance(smooth, far, {0.0, -1.0, 0.0}).empty());
}

// Two small spheres far apart, one low, one high and to the side, under an oblique sun: the rays
// toward the high one cross bricks far from every surface first, which the march skips. The least
// distance of the ray p + t·u from a sphere (centre c, radius R) is |c − p − t*·u| − R at t* the
// centre's projection (both centres lie ahead of every ray from the floor), the union's the least
// of the two. Skipped space must not hide the high sphere: its shadow's sign everywhere, its edge's
// clearance as close as the lone sphere's above.
TEST(ShadowEdge, TheMarchSkipsSpaceFarFromSurfacesButNotASurfaceBeyondIt) {
  const double R = 0.09;
  const glm::dvec3 centres[2] = {{-0.22, 0.22, -0.05}, {0.2, 0.74, 0.1}};
  const glm::dvec3 toLight = glm::normalize(glm::dvec3(-0.25, 1.0, -0.15));
  auto exact = [&](const glm::dvec3& p) {
    double best = 1e30;
    for (const glm::dvec3& c : centres) best = std::min(best, glm::length(c - p - glm::dot(c - p, toLight) * toLight) - R);
    return best;
  };
  const int resolutions[2] = {32, 48};
  for (int res : resolutions) {
    const Volume volume = test_scenes::sharpVolume(std::vector<std::string>{"procedural:sphere,r=0.09,center=-0.22:0.22:-0.05,ior=1.5",
                                                    "procedural:sphere,r=0.09,center=0.2:0.74:0.1,ior=1.5"},
                                                   res, test_scenes::box({-0.4, 0.1, -0.4}, {0.4, 0.9, 0.4}));
    const double h = volume.grid.voxelSize().x;
    const ReceiverMap map = floorMap({-0.3, -0.4}, 0.004, {220, 200});
    const std::vector<float> c = shadowClearance(volume, map, -toLight);
    ASSERT_EQ(c.size(), map.texelCount());
    int high_shadow = 0, edge = 0;
    double worst = 0.0;
    for (int j = 0; j < map.texels.y; ++j) {
      for (int i = 0; i < map.texels.x; ++i) {
        const glm::dvec3 p = map.texelCenter(i, j);
        const double want = exact(p);
        const double got = c[static_cast<std::size_t>(j) * static_cast<std::size_t>(map.texels.x) + static_cast<std::size_t>(i)];
        if (std::abs(want) < 0.25 * h) {
          worst = std::max(worst, std::abs(got - want) / h);
          ++edge;
        }
        if (std::abs(want) < 0.1 * h) continue;  // the sign is right to within the error below
        if (want > 0.0) {
          ASSERT_GT(got, 0.0) << res << "³ at " << p.x << ", " << p.z << " want " << want;
        } else {
          ASSERT_LT(got, 0.0) << res << "³ at " << p.x << ", " << p.z << " got " << got << " want " << want;
          high_shadow += glm::length(centres[1] - p - glm::dot(centres[1] - p, toLight) * toLight) < R;
        }
      }
    }
    std::printf("%d³, two spheres: clearance within %.4f voxel over the %d texels of the edges; %d texels in the high one's shadow\n",
                res, worst, edge, high_shadow);
    EXPECT_GT(high_shadow, 500);  // the high sphere's shadow is on the map (π·R² in texels of 0.004: ~1600)
    EXPECT_GT(edge, 100);
    // Spheres of R = 3.6–5.4 voxels: the trilinear distance's own error is larger than the big
    // sphere's above (0.02 voxel at 12 voxels), measured 0.074 / 0.049 voxel. Steps of a voxel
    // alone would add up to h²/(8R) = 0.035 voxel where a grazing ray's minimum falls between two
    // samples (measured without the parabola's vertex: 0.097 / 0.070); 0.085 leaves room for the
    // field's error only. Under a third of a texel of the bake's default pitch.
    EXPECT_LT(worst, 0.085);
  }
}

// A map of a straight shadow edge at u = e (lit for u ≥ e) under D = 2 W/m², plus light C(u, v)
// that is linear (a caustic's slope): each texel holds its mean, D·s_true + C(centre), s_true the
// part of the texel at u ≥ e. With the clearance c = u − e, the texture adds back D·(1 − s) and
// the change the ground shows, rgb − D·(2 − lit) at lit = [bilinear c ≥ 0], is C − D·[u < e] at
// any point: the edge where it is, not spread over two texels.
TEST(ShadowEdge, TheGroundShowsTheEdgeWhereTheClearanceChangesSign) {
  const double pitch = 0.1, e = 0.33, D = 2.0;
  ReceiverMap map = floorMap({0.0, 0.0}, pitch, {10, 6});
  auto C = [](glm::dvec2 uv) { return 0.5 + 0.8 * uv.x - 0.3 * uv.y; };
  std::vector<float> clearance(map.texelCount());
  for (int j = 0; j < map.texels.y; ++j) {
    for (int i = 0; i < map.texels.x; ++i) {
      const glm::dvec2 centre((i + 0.5) * pitch, (j + 0.5) * pitch);
      const double s = std::clamp((centre.x + 0.5 * pitch - e) / pitch, 0.0, 1.0);
      const std::size_t t = static_cast<std::size_t>(j) * 10 + static_cast<std::size_t>(i);
      for (int k = 0; k < 3; ++k) map.irradiance[3 * t + static_cast<std::size_t>(k)] = static_cast<float>(D * s + C(centre));
      clearance[t] = static_cast<float>(centre.x - e);
    }
  }
  ReceiverLayer layer;
  layer.map = &map;
  layer.light_pos = glm::dvec4(0.0, -1.0, 0.0, 0.0);
  layer.light_power = glm::dvec3(D);
  const std::vector<float> texels = receiverTexels(layer, clearance);
  ASSERT_EQ(texels.size(), 4 * map.texelCount());
  // What the viewer uploads: the same texels as halves (row by row through the span conversion).
  const std::vector<std::uint16_t> halves = receiverTexelsHalf(layer, clearance);
  ASSERT_EQ(halves.size(), texels.size());
  for (std::size_t k = 0; k < texels.size(); ++k) ASSERT_EQ(halves[k], toHalf(texels[k])) << k;
  // The map is grey (R = G = B) and so is the light: kept grey (ReceiverMap::makeGrey), its texture
  // is R and A alone, the same halves; a coloured light (its direct light added back under the
  // shadow) or an RGB map keep all four.
  EXPECT_FALSE(greyReceiverTexels(layer));  // the map is still RGB
  ReceiverMap grey_map = map;
  ASSERT_TRUE(grey_map.makeGrey());
  ReceiverLayer grey_layer = layer;
  grey_layer.map = &grey_map;
  ASSERT_TRUE(greyReceiverTexels(grey_layer));
  const std::vector<std::uint16_t> grey_halves = receiverTexelsHalf(grey_layer, clearance);
  ASSERT_EQ(grey_halves.size(), 2 * map.texelCount());
  for (std::size_t t = 0; t < map.texelCount(); ++t) {
    ASSERT_EQ(grey_halves[2 * t], halves[4 * t]) << t;
    ASSERT_EQ(grey_halves[2 * t + 1], halves[4 * t + 3]) << t;
  }
  grey_layer.light_power = glm::dvec3(D, D, 0.5 * D);
  EXPECT_FALSE(greyReceiverTexels(grey_layer));
  EXPECT_EQ(receiverTexelsHalf(grey_layer, clearance).size(), 4 * map.texelCount());
  // Texel 3 (u in [0.3, 0.4)) is the one the edge crosses: lit 7/10 of it; the 8×8 points find
  // 6/8 (those at u ≥ 0.33), so it gets D·(1 − 0.75) back. The others: nothing in the light, D
  // in the shadow.
  for (int i = 0; i < 10; ++i) {
    const std::size_t t = static_cast<std::size_t>(2 * 10 + i);
    const double s_true = std::clamp(((i + 1) * pitch - e) / pitch, 0.0, 1.0);
    const double s = i == 3 ? 0.75 : s_true;
    EXPECT_NEAR(texels[4 * t], map.irradiance[3 * t] + D * (1.0 - s), 1e-5) << i;
    EXPECT_FLOAT_EQ(texels[4 * t + 3], clearance[t]);
  }
  // The change at points across the edge, a tenth of a texel apart, away from the map's border.
  layer.texels = &texels;
  double worst = 0.0, worst_old = 0.0;
  for (double u = 0.16; u <= 0.5; u += 0.01) {
    const glm::dvec3 x = map.point + u * map.u + 0.27 * map.v;
    glm::dvec3 change;
    ASSERT_TRUE(receiverChangeAt(layer, x, change));
    const double want = C({u, 0.27}) - (u < e ? D : 0.0);
    worst = std::max(worst, std::abs(change.x - want));
    ReceiverLayer plain = layer;
    plain.texels = nullptr;
    glm::dvec3 old;
    ASSERT_TRUE(receiverChangeAt(plain, x, old));
    worst_old = std::max(worst_old, std::abs(old.x - want));
  }
  std::printf("change across the edge: worst %.4f W/m² (the map alone: %.4f) of D = %.1f\n", worst, worst_old, D);
  // What is left is the 8×8 points' estimate of the crossed texel's lit part (0.75 for 0.7), which
  // its bilinear neighbourhood weighs by at most 1: D·0.05.
  EXPECT_LE(worst, D * 0.05 + 1e-5);
  EXPECT_GT(worst_old, 0.3 * D);  // the map alone smears the edge over a texel
}

}  // namespace
}  // namespace eik
