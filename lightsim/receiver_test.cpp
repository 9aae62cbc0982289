// Receiver maps (receiver.h): the exact clipping of footprints against texels, the footprint of a
// patch on the plane, and the map's layout.
#include "lightsim/receiver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "core/error.h"
#include "lightsim/test_scenes.h"
#include "lightsim/wavefront.h"

namespace eik {
namespace {

TEST(Receiver, TriangleSquareOverlapIsExact) {
  // The whole triangle inside, the square inside the triangle, and a half cut.
  EXPECT_NEAR(triangleSquareOverlap({0.2, 0.2}, {0.8, 0.2}, {0.2, 0.8}, {0, 0}, {1, 1}), 0.18, 1e-15);
  EXPECT_NEAR(triangleSquareOverlap({-5, -5}, {10, -5}, {-5, 10}, {0, 0}, {1, 1}), 1.0, 1e-15);
  EXPECT_NEAR(triangleSquareOverlap({0, 0}, {2, 0}, {0, 2}, {0, 0}, {1, 1}), 1.0, 1e-15);
  EXPECT_NEAR(triangleSquareOverlap({0, 0}, {1, 0}, {0, 1}, {0, 0}, {1, 1}), 0.5, 1e-15);
  EXPECT_NEAR(triangleSquareOverlap({2, 2}, {3, 2}, {2, 3}, {0, 0}, {1, 1}), 0.0, 1e-15);
  // Winding does not matter.
  EXPECT_NEAR(triangleSquareOverlap({0, 0}, {0, 1}, {1, 0}, {0, 0}, {1, 1}), 0.5, 1e-15);
}

ReceiverMap unitMap(int texels, double pitch) {
  ReceiverMap map;
  map.origin = glm::dvec2(-0.5 * texels * pitch);
  map.pitch = pitch;
  map.texels = glm::ivec2(texels);
  return map;
}

// An axis-aligned rectangle takes depositFootprint's separable path; every texel must get the
// flux its two triangles' exact overlaps give (triangleSquareOverlap), in either corner order and
// orientation, and a rectangle reaching off the map loses only what lies off it.
TEST(Receiver, AxisAlignedFootprintsGetTheirTrianglesExactShares) {
  const ReceiverMap map = unitMap(12, 0.1);
  for (const std::array<glm::dvec2, 4>& quad :
       {std::array<glm::dvec2, 4>{{{0.05, -0.21}, {0.37, -0.21}, {0.37, 0.13}, {0.05, 0.13}}},
        std::array<glm::dvec2, 4>{{{0.05, -0.21}, {0.05, 0.13}, {0.37, 0.13}, {0.37, -0.21}}},
        std::array<glm::dvec2, 4>{{{0.37, 0.13}, {0.05, 0.13}, {0.05, -0.21}, {0.37, -0.21}}},
        std::array<glm::dvec2, 4>{{{0.41, 0.31}, {0.93, 0.31}, {0.93, 0.77}, {0.41, 0.77}}}}) {
    std::vector<glm::dvec3> flux(map.texelCount(), glm::dvec3(0.0));
    const glm::dvec3 phi(2.0, 1.0, 0.5);
    depositFootprint(map, quad, phi, flux);
    const double area = std::abs((quad[2].x - quad[0].x) * (quad[2].y - quad[0].y));
    double total = 0.0, expected_total = 0.0;
    for (int j = 0; j < map.texels.y; ++j)
      for (int i = 0; i < map.texels.x; ++i) {
        const glm::dvec2 lo = map.origin + glm::dvec2(i, j) * map.pitch, hi = lo + glm::dvec2(map.pitch);
        const double overlap = triangleSquareOverlap(quad[0], quad[1], quad[2], lo, hi) +
                               triangleSquareOverlap(quad[0], quad[2], quad[3], lo, hi);
        const glm::dvec3 got = flux[static_cast<std::size_t>(j * map.texels.x + i)];
        EXPECT_NEAR(got.x, phi.x * overlap / area, 1e-12) << i << "," << j;
        EXPECT_NEAR(got.z, phi.z * overlap / area, 1e-12) << i << "," << j;
        total += got.x;
        expected_total += phi.x * overlap / area;
      }
    EXPECT_NEAR(total, expected_total, 1e-12);
    EXPECT_GT(total, 0.4);  // the last one lies 46 % on the map
  }
}

// Footprints of every shape (random quads: slivers, large, tiny, straddling the map's edge, convex
// or not) against the texel-by-texel clipping of their two triangles (triangleSquareOverlap, exact
// by construction): each texel's flux to 1e-12 of the footprint's flux.
TEST(Receiver, EveryTexelGetsItsExactOverlapForFootprintsOfAnyShape) {
  const ReceiverMap map = unitMap(24, 0.05);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> centre(-0.7, 0.7), log_size(-4.0, 0.0), unit(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const glm::dvec2 c(centre(rng), centre(rng));
    const double size = std::pow(10.0, log_size(rng)) * 0.6;
    std::array<glm::dvec2, 4> quad;
    for (glm::dvec2& q : quad) q = c + size * glm::dvec2(unit(rng), unit(rng));
    if (trial % 3 == 0) quad[3] = quad[0] + quad[2] - quad[1];  // a parallelogram, as most footprints are
    std::vector<glm::dvec3> flux(map.texelCount(), glm::dvec3(0.0));
    depositFootprint(map, quad, glm::dvec3(1.0), flux);
    auto cross = [](glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; };
    const double a1 = 0.5 * std::abs(cross(quad[1] - quad[0], quad[2] - quad[0]));
    const double a2 = 0.5 * std::abs(cross(quad[2] - quad[0], quad[3] - quad[0]));
    if (!(a1 + a2 > 0.0)) continue;
    for (int j = 0; j < map.texels.y; ++j)
      for (int i = 0; i < map.texels.x; ++i) {
        const glm::dvec2 lo = map.origin + glm::dvec2(i, j) * map.pitch, hi = lo + glm::dvec2(map.pitch);
        double want = 0.0;
        if (a1 > 0.0) want += a1 / (a1 + a2) * triangleSquareOverlap(quad[0], quad[1], quad[2], lo, hi) / a1;
        if (a2 > 0.0) want += a2 / (a1 + a2) * triangleSquareOverlap(quad[0], quad[2], quad[3], lo, hi) / a2;
        ASSERT_NEAR(flux[static_cast<std::size_t>(j * map.texels.x + i)].x, want, 1e-12 + 1e-9 * want)
            << "trial " << trial << " texel " << i << "," << j;
      }
  }
}

TEST(Receiver, FootprintFluxIsConservedAndSpreadByArea) {
  const ReceiverMap map = unitMap(16, 0.1);
  std::vector<glm::dvec3> flux(map.texelCount(), glm::dvec3(0.0));
  // A tilted quad inside the map.
  const std::array<glm::dvec2, 4> quad{{{-0.33, -0.21}, {0.41, -0.29}, {0.37, 0.52}, {-0.28, 0.44}}};
  depositFootprint(map, quad, glm::dvec3(2.0, 1.0, 0.5), flux);
  const glm::dvec3 total = std::accumulate(flux.begin(), flux.end(), glm::dvec3(0.0));
  EXPECT_NEAR(total.x, 2.0, 1e-12);
  EXPECT_NEAR(total.z, 0.5, 1e-12);
  // A texel wholly inside gets flux × texel area / quad area.
  const double area = 0.5 * std::abs((quad[2].x - quad[0].x) * (quad[3].y - quad[1].y) -
                                     (quad[3].x - quad[1].x) * (quad[2].y - quad[0].y));
  const std::size_t centre = 8 * 16 + 8;  // texel [0, 0.1]²
  EXPECT_NEAR(flux[centre].x, 2.0 * 0.01 / area, 1e-12);
  // Flux outside the map is dropped, the rest kept.
  std::vector<glm::dvec3> edge(map.texelCount(), glm::dvec3(0.0));
  depositFootprint(map, {{{0.7, 0.7}, {0.9, 0.7}, {0.9, 0.9}, {0.7, 0.9}}}, glm::dvec3(1.0), edge);
  EXPECT_NEAR(std::accumulate(edge.begin(), edge.end(), glm::dvec3(0.0)).x, 0.25, 1e-12);
}

TEST(Receiver, FootprintsThatTileThePlaneGiveEveryTexelItsShare) {
  const ReceiverMap map = unitMap(20, 0.05);
  std::vector<glm::dvec3> flux(map.texelCount(), glm::dvec3(0.0));
  // A lattice of parallelograms of 0.073 × 0.061, sheared, over the whole map, E = 3.
  const double a = 0.073, b = 0.061, shear = 0.02;
  for (int j = -20; j < 20; ++j)
    for (int i = -20; i < 20; ++i) {
      auto at = [&](int u, int v) { return glm::dvec2(u * a + v * shear, v * b); };
      depositFootprint(map, {{at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)}}, glm::dvec3(3.0 * a * b), flux);
    }
  for (std::size_t t = 0; t < map.texelCount(); ++t) ASSERT_NEAR(flux[t].x / (0.05 * 0.05), 3.0, 1e-9) << t;
}

TEST(Receiver, APatchsFootprintFollowsItsCornerRays) {
  ReceiverMap map = unitMap(8, 0.1);
  Patch p;
  p.x = {glm::dvec3(0, 1, 0), glm::dvec3(0.1, 1, 0), glm::dvec3(0.1, 1, 0.1), glm::dvec3(0, 1, 0.1)};
  const glm::dvec3 d = glm::normalize(glm::dvec3(1, -1, 0));
  for (auto& w : p.w) w = d;
  std::array<glm::dvec2, 4> f;
  ASSERT_TRUE(patchFootprint(p, map, f));
  // Each corner moves 1 along +x on its way down to y = 0: u = x + 1, v = z (the map's default axes).
  EXPECT_NEAR(f[0].x, 1.0, 1e-12);
  EXPECT_NEAR(f[1].x, 1.1, 1e-12);
  EXPECT_NEAR(f[2].y, 0.1, 1e-12);
  for (auto& w : p.w) w = glm::dvec3(1, 0, 0);
  EXPECT_FALSE(patchFootprint(p, map, f));  // parallel to the plane
  // One corner above the plane heading away from it: its ray never lands (back along it is where it
  // came from), so the patch is not received.
  for (auto& w : p.w) w = d;
  p.w[2] = glm::normalize(glm::dvec3(1, 0.01, 0));
  EXPECT_FALSE(patchFootprint(p, map, f));
  // Below the plane heading further down, it crossed it: the crossing is back along its ray.
  for (auto& x : p.x) x.y = -1.0;
  for (auto& w : p.w) w = d;
  ASSERT_TRUE(patchFootprint(p, map, f));
  EXPECT_NEAR(f[0].x, -1.0, 1e-12);
}

// FootprintSums: a footprint of up to 16×16 texels is deposited exactly as depositFootprint does,
// to float rounding (the fine level's sums are floats: 2⁻²⁴ of a texel's flux); a wide one goes to a coarse level whose flux, spread over its texels, keeps the
// footprint's flux (on the map) and its density inside, and reaches at most one coarse texel (16
// map texels at the coarsest level) beyond the footprint's box. Bands in any order: the same sums.
TEST(Receiver, WideFootprintsGoToCoarseLevelsAndKeepTheirFluxAndDensity) {
  const ReceiverMap map = unitMap(100, 0.01);  // [−0.5, 0.5]², 7 bands of 16 rows (the last short)
  const std::array<glm::dvec2, 4> small{{{-0.031, -0.052}, {0.071, -0.04}, {0.063, 0.061}, {-0.04, 0.05}}};
  const std::array<glm::dvec2, 4> wide{{{-0.43, -0.12}, {0.38, -0.25}, {0.41, -0.07}, {-0.45, 0.11}}};
  FootprintSums sums(map);
  EXPECT_EQ(sums.level(small), 0);
  EXPECT_EQ(sums.bands(), 7);
  const int k = sums.level(wide);
  EXPECT_GE(k, 1);
  EXPECT_LE(k, FootprintSums::kFootprintLevels);
  const glm::dvec3 phi_small(1.0, 2.0, 3.0), phi_wide(0.5);
  for (int band = sums.bands() - 1; band >= 0; --band) {  // any order
    sums.deposit(small, phi_small, band);
    sums.deposit(wide, phi_wide, band);
  }
  const std::vector<glm::dvec3> both = sums.resolve();
  FootprintSums small_only(map);
  for (int band = 0; band < small_only.bands(); ++band) small_only.deposit(small, phi_small, band);
  std::vector<glm::dvec3> exact(map.texelCount(), glm::dvec3(0.0));
  depositFootprint(map, small, phi_small, exact);
  const std::vector<glm::dvec3> small_sums = small_only.resolve();
  ASSERT_EQ(small_sums.size(), exact.size());
  for (std::size_t t = 0; t < exact.size(); ++t)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(small_sums[t][c], exact[t][c], 6e-8 * exact[t][c]) << t;
  // The wide footprint (both less the small one's sums, the same floats): its flux, its density in
  // a texel deep inside it, nothing far outside.
  glm::dvec3 total(0.0);
  for (std::size_t t = 0; t < both.size(); ++t) total += both[t] - small_sums[t];
  EXPECT_NEAR(total.x, phi_wide.x, 1e-12);
  auto cross = [](glm::dvec2 a, glm::dvec2 b) { return a.x * b.y - a.y * b.x; };
  const double area = 0.5 * std::abs(cross(wide[2] - wide[0], wide[3] - wide[1]));
  const std::size_t inside = 45 * 100 + 30;  // texel [−0.2, −0.19] × [−0.05, −0.04]: 1/10 of the way from any edge
  EXPECT_NEAR(both[inside].x - small_sums[inside].x, phi_wide.x * 1e-4 / area, 1e-12);
  const int reach = 1 << k;
  for (int j = 0; j < 100; ++j)
    for (int i = 0; i < 100; ++i) {
      const double u = -0.5 + 0.01 * i, v = -0.5 + 0.01 * j;  // the texel's low corner
      const bool far = u > 0.41 + 0.01 * reach || u + 0.01 < -0.45 - 0.01 * reach || v > 0.11 + 0.01 * reach ||
                       v + 0.01 < -0.25 - 0.01 * reach;
      if (far) {
        EXPECT_EQ(both[static_cast<std::size_t>(j * 100 + i)].x - small_sums[static_cast<std::size_t>(j * 100 + i)].x, 0.0)
            << i << "," << j;
      }
    }
}

// Grey sums (a grey light through a volume that colours nothing): one float a texel, the same
// values as the first channel of RGB sums of the same footprints, fine and coarse, to the bit.
TEST(Receiver, GreySumsAreTheFirstChannelOfRgbSums) {
  const ReceiverMap map = unitMap(100, 0.01);
  const std::array<glm::dvec2, 4> small{{{-0.031, -0.052}, {0.071, -0.04}, {0.063, 0.061}, {-0.04, 0.05}}};
  const std::array<glm::dvec2, 4> wide{{{-0.43, -0.12}, {0.38, -0.25}, {0.41, -0.07}, {-0.45, 0.11}}};
  FootprintSums rgb(map), grey(map, true);
  EXPECT_EQ(rgb.channels(), 3);
  EXPECT_EQ(grey.channels(), 1);
  for (int band = 0; band < rgb.bands(); ++band) {
    for (FootprintSums* sums : {&rgb, &grey}) {
      sums->deposit(small, glm::dvec3(0.7), band);
      sums->deposit(wide, glm::dvec3(0.3), band);
    }
  }
  std::vector<float> e_rgb, e_grey;
  rgb.irradiance(nullptr, 1e4, e_rgb);
  grey.irradiance(nullptr, 1e4, e_grey);
  ASSERT_EQ(e_rgb.size(), 3 * map.texelCount());
  ASSERT_EQ(e_grey.size(), map.texelCount());
  std::size_t lit = 0;
  for (std::size_t t = 0; t < map.texelCount(); ++t) {
    ASSERT_EQ(e_grey[t], e_rgb[3 * t]) << t;
    lit += e_grey[t] > 0.0f;
  }
  EXPECT_GT(lit, map.texelCount() / 10);  // the wide footprint covers a fifth of the map
}

// The direct light on the map (directMapLight) against the patches it stands for: a sun at 40°
// over a small glass sphere's box, its map on the floor below. Every cell of the light's lattice
// that meets the box or the map, each going straight to the floor as a patch (initialPatches
// without DirectCells) and deposited there exactly (depositFootprint), is the reference; the
// cells left out (with DirectCells) in closed form plus the followed patches' own footprints must
// give the same flux to every texel, to rounding (10⁻¹²: sums of ~20 exact overlaps in double),
// and the left-out cells must carry the flux the patches did (the ledger's in and received).
TEST(Receiver, TheDirectLightIsWhatTheLeftOutCellsWouldPutOnTheMap) {
  const Volume volume = test_scenes::sharpVolume("procedural:sphere,r=0.3,ior=1.5", 16, test_scenes::cube(0.5));
  const VolumeSampler sampler(volume);
  LightSpec light;
  light.direction = glm::normalize(glm::dvec3(0.6, -1.0, -0.25));
  light.power = {2.0, 1.0, 0.5};
  ReceiverSpec spec;
  spec.point = {0.0, -0.7, 0.0};
  spec.half_extent = 1.2;
  SimulationOptions options;
  options.receiver = spec;
  glm::dvec3 lo, hi;
  propagationBox(volume.grid, options, lo, hi);
  const ReceiverMap map = receiverGeometry(spec, light, volume.grid, lo, hi);

  auto straightToMap = [&](const std::vector<Patch>& patches, std::vector<glm::dvec3>& flux) {
    for (const Patch& p : patches) {
      std::array<glm::dvec2, 4> f;
      ASSERT_TRUE(patchFootprint(p, map, f));
      depositFootprint(map, f, p.flux, flux);
    }
  };
  const std::vector<Patch> all = initialPatches(light, volume.grid, sampler, options, nullptr, &map);
  std::vector<glm::dvec3> reference(map.texelCount(), glm::dvec3(0.0));
  straightToMap(all, reference);

  DirectCells direct;
  const std::vector<Patch> followed = initialPatches(light, volume.grid, sampler, options, nullptr, &map, &direct);
  ASSERT_GT(direct.cells, 0u);
  EXPECT_EQ(followed.size() + direct.cells, all.size());
  EXPECT_LT(followed.size(), all.size() / 2);  // most of the map is lit directly
  const DirectMapLight direct_light = directMapLight(map, light, followed);
  std::vector<glm::dvec3> flux = direct_light.texels();
  // The bands of rows the followed patches reach hold their light, the others nothing (most of the
  // map: the box's shadow is a small part of it).
  EXPECT_GT(direct_light.heldBands(), 0);
  EXPECT_LT(direct_light.heldBands(), (map.texels.y + 15) / 16);
  for (int j = 0; j < map.texels.y; j += 7)
    for (int i = 0; i < map.texels.x; i += 5)
      ASSERT_EQ(direct_light.flux(i, j), flux[static_cast<std::size_t>(j) * static_cast<std::size_t>(map.texels.x) + static_cast<std::size_t>(i)]);
  const glm::dvec3 texel_full = reference[0];  // a corner texel, far from the shadow: lit wholly
  int partial = 0, dark = 0;
  for (std::size_t t = 0; t < flux.size(); ++t) {
    const double direct_part = flux[t].x / texel_full.x;
    partial += direct_part > 1e-6 && direct_part < 1.0 - 1e-6 ? 1 : 0;
    dark += direct_part < 1e-9 ? 1 : 0;
  }
  EXPECT_GT(partial, 0);  // texels the shadow's edge crosses
  EXPECT_GT(dark, 0);     // texels wholly in the followed patches' shadow
  straightToMap(followed, flux);
  for (std::size_t t = 0; t < flux.size(); ++t)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(flux[t][c], reference[t][c], 1e-12 * texel_full[c]) << t;
  glm::dvec3 in_all(0.0), in_followed(0.0);
  for (const Patch& p : all) in_all += p.flux;
  for (const Patch& p : followed) in_followed += p.flux;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(in_followed[c] + direct.flux[c], in_all[c], 1e-12 * in_all[c]);

  // A point light leaves its cells that miss the box to the closed form as well (I·cos θ/d² a
  // texel: ExactOpticsFreeAir.APointLightFallsOffByTheInverseSquareLaw), and only a light that
  // reaches the plane's front has one.
  LightSpec point;
  point.type = LightSpec::Type::Point;
  point.position = {0.2, 1.5, 0.1};
  const ReceiverMap point_map = receiverGeometry(spec, point, volume.grid, lo, hi);
  DirectCells left;
  const std::vector<Patch> point_followed = initialPatches(point, volume.grid, sampler, options, nullptr, &point_map, &left);
  EXPECT_GT(left.cells, 0u);
  EXPECT_GT(point_followed.size(), 0u);
  EXPECT_EQ(directMapLight(point_map, point, point_followed).texels().size(), point_map.texelCount());
  LightSpec below = point;
  below.position.y = spec.point.y - 1.0;
  EXPECT_THROW(directMapLight(point_map, below, {}), InputError);
}

TEST(Receiver, TheMapCoversTheShadowAndOneShadowSizeAround) {
  const GridSpec g = test_scenes::cubicGrid(10, 0.5);
  ReceiverSpec spec;
  spec.point = {0, -1, 0};
  LightSpec light;  // straight down
  const ReceiverMap map = receiverGeometry(spec, light, g, g.bounds_min, g.bounds_max);
  // The shadow is [−0.5, 0.5]²; grown by 1 on every side: [−1.5, 1.5]², texels of h/4 = 0.025.
  EXPECT_NEAR(map.origin.x, -1.5, 1e-12);
  EXPECT_NEAR(map.pitch, 0.025, 1e-12);
  EXPECT_EQ(map.texels, glm::ivec2(120));
  spec.half_extent = 0.7;
  EXPECT_EQ(receiverGeometry(spec, light, g, g.bounds_min, g.bounds_max).texels, glm::ivec2(56));
  light.direction = {0, 1, 0};  // from below: the plane's back
  EXPECT_THROW(receiverGeometry(spec, light, g, g.bounds_min, g.bounds_max), InputError);
}

}  // namespace
}  // namespace eik
