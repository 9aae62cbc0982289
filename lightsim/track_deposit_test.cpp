// Track deposits (track_deposit.h): the hat weights along a path are exact and sum to one.
#include "lightsim/track_deposit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

namespace eik {
namespace {

// ∫ K_v ds / L along a→b by brute force (10⁵ midpoint samples).
std::map<long long, double> bruteForce(glm::dvec3 a, glm::dvec3 b, glm::ivec3 dims) {
  std::map<long long, double> w;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const HatWeights hw = hatWeights(a + (b - a) * ((i + 0.5) / n), dims);
    for (std::size_t k = 0; k < 8; ++k)
      if (hw.index[k] >= 0) w[hw.index[k]] += hw.weight[k] / n;
  }
  return w;
}

TEST(TrackDeposit, WeightsAreTheExactIntegralOfTheHats) {
  const glm::ivec3 dims(8);
  for (const auto& [a, b] : {std::pair{glm::dvec3(2.2, 3.7, 4.1), glm::dvec3(3.9, 4.05, 2.6)},
                             std::pair{glm::dvec3(1.5, 1.5, 1.5), glm::dvec3(1.5, 1.5, 4.5)},
                             std::pair{glm::dvec3(5.01, 2.3, 6.6), glm::dvec3(5.02, 2.31, 6.61)}}) {
    std::map<long long, double> exact;
    forEachTrackWeight(a, b, dims, [&](long long v, double w) { exact[v] += w; });
    const std::map<long long, double> brute = bruteForce(a, b, dims);
    double sum = 0.0;
    for (const auto& [v, w] : brute) {
      EXPECT_NEAR(exact[v], w, 1e-6) << "voxel " << v;  // brute force: O(1/n²) midpoint error
      sum += exact[v];
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);  // the hats are a partition of unity inside the grid
  }
}

TEST(TrackDeposit, OutsideTheGridTheWeightIsLostNotMoved) {
  double sum = 0.0;
  forEachTrackWeight(glm::dvec3(-0.4, 2.5, 2.5), glm::dvec3(0.2, 2.5, 2.5), glm::ivec3(5), [&](long long v, double w) {
    EXPECT_GE(v, 0);
    sum += w;
  });
  // Hats of voxel 0 reach x = −0.5 … 1.5 with weight 1 − |x − 0.5| on [−0.5, 0.5]: mean over
  // [−0.4, 0.2] is 1 − mean |x − 0.5| = 1 − 0.6 = 0.4.
  EXPECT_NEAR(sum, 0.4, 1e-12);
}

// A free flight: a segment of ~150 voxels, oblique, leaving the grid and crossing it again. Only
// its part within the hats' reach is integrated, in pieces of at most 48 voxels; the weights must
// still be the exact integral (against brute force over the whole segment) — before the cut,
// a segment crossing more than 64 planes lost the rest of its length.
TEST(TrackDeposit, LongSegmentsLeavingTheGridKeepTheExactIntegral) {
  const glm::ivec3 dims(40, 24, 32);
  for (const auto& [a, b] : {std::pair{glm::dvec3(-30.2, 3.7, 4.1), glm::dvec3(70.9, 20.05, 28.6)},
                             std::pair{glm::dvec3(20.3, -60.0, 16.2), glm::dvec3(20.3, 90.0, 16.2)},
                             std::pair{glm::dvec3(1.1, 2.2, 3.3), glm::dvec3(38.7, 21.9, 30.1)}}) {
    std::map<long long, double> exact;
    forEachTrackWeight(a, b, dims, [&](long long v, double w) { exact[v] += w; });
    const std::map<long long, double> brute = bruteForce(a, b, dims);
    double worst = 0.0, sum = 0.0, brute_sum = 0.0;
    for (const auto& [v, w] : brute) {
      worst = std::max(worst, std::abs(exact[v] - w));
      brute_sum += w;
    }
    for (const auto& [v, w] : exact) sum += w;
    // Brute force: 10⁵ samples over ~150 voxels, ~700 per voxel: the midpoint rule's error per hat
    // is O(1/700²) of its ~1/150 share, well under 10⁻⁷.
    EXPECT_LT(worst, 1e-7);
    EXPECT_NEAR(sum, brute_sum, 1e-7);  // the share of the length within the grid's hats
    EXPECT_GT(sum, 0.1);
  }
}

TEST(TrackDeposit, TheLatticeIsAtMostHalfAVoxel) {
  EXPECT_EQ(trackLattice(0.3), 1);
  EXPECT_EQ(trackLattice(0.5), 1);
  EXPECT_EQ(trackLattice(1.0), 2);
  EXPECT_EQ(trackLattice(1.01), 3);
  EXPECT_EQ(trackLattice(100.0), kMaxTrackLattice);
  // The dim light's lattice: at most one voxel.
  EXPECT_EQ(trackLattice(1.0, kDimTrackSpacing), 1);
  EXPECT_EQ(trackLattice(1.01, kDimTrackSpacing), 2);
  EXPECT_EQ(trackLattice(3.5, kDimTrackSpacing), 4);
  EXPECT_EQ(trackLattice(100.0, kDimTrackSpacing), kMaxTrackLattice);
}

TEST(TrackDeposit, DimLightTakesTheCoarserLattice) {
  // Irradiance = flux / area against the bound; 0 turns the rule off; a degenerate area (a focus)
  // is never dim.
  EXPECT_EQ(trackSpacing(1.0, 1.0, 2.0), kDimTrackSpacing);
  EXPECT_EQ(trackSpacing(1.0, 0.4, 2.0), kTrackSpacing);
  EXPECT_EQ(trackSpacing(1.0, 100.0, 0.0), kTrackSpacing);
  EXPECT_EQ(trackSpacing(1.0, 0.0, 2.0), kTrackSpacing);
}

// A plane wave of unit irradiance as sub-paths on a square lattice of `spacing` voxels (a patch's
// sub-paths, far from its edges), crossing a 24³ grid at polar angle θ from +y and azimuth φ:
// the largest deviation from 1 of a voxel's deposit, over the voxels 4 or more from the faces
// (the hats of every voxel there are crossed by the whole beam).
double planeWaveRipple(double spacing, double theta_deg, double phi_deg) {
  const int n = 24;
  const glm::ivec3 dims(n);
  const double theta = glm::radians(theta_deg), phi = glm::radians(phi_deg);
  const glm::dvec3 d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  const glm::dvec3 side = std::fabs(d.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(d, side)), v = glm::cross(d, u);
  std::vector<double> sum(static_cast<std::size_t>(n * n * n), 0.0);
  const glm::dvec3 centre(0.5 * n);
  const double reach = 40.0;  // beyond the grid's half diagonal (20.8) in every direction
  const int m = static_cast<int>(reach / spacing);
  for (int i = -m; i < m; ++i)
    for (int j = -m; j < m; ++j) {
      const glm::dvec3 o = centre + ((i + 0.5) * spacing) * u + ((j + 0.5) * spacing) * v;
      // Each sub-path carries flux E·spacing² over a length 2·reach: weight w → E·spacing²·2·reach·w
      // per voxel volume (1 here), which is the irradiance in a uniform beam.
      forEachTrackWeight(o - reach * d, o + reach * d, dims, [&](long long at, double w) {
        sum[static_cast<std::size_t>(at)] += w * spacing * spacing * 2.0 * reach;
      });
    }
  double worst = 0.0;
  for (int z = 4; z < n - 4; ++z)
    for (int y = 4; y < n - 4; ++y)
      for (int x = 4; x < n - 4; ++x)
        worst = std::max(worst, std::fabs(sum[static_cast<std::size_t>(x + n * (y + n * z))] - 1.0));
  return worst;
}

TEST(TrackDeposit, APlaneWavesRippleIsBoundedAtBothLatticeSpacings) {
  // The figures trackSpacing rests on: ½ voxel leaves at most 0.54 %, 1 voxel at most 7.5 %
  // (measured over these directions; bounds 0.6 % and 8 % leave room for rounding only), so dim
  // light under 1/16 of the brightest keeps its ripple under 0.5 % of that light. Along the axes
  // both lattices are exact: the replicas of the lattice fall on the zeros of the hat's spectrum.
  double fine = 0.0, coarse = 0.0;
  for (double theta = 0.0; theta <= 90.0; theta += 15.0)
    for (double phi = 0.0; phi <= 45.0; phi += 15.0) {
      fine = std::max(fine, planeWaveRipple(kTrackSpacing, theta, phi));
      coarse = std::max(coarse, planeWaveRipple(kDimTrackSpacing, theta, phi));
    }
  EXPECT_LT(fine, 0.006);
  EXPECT_LT(coarse, 0.08);
  EXPECT_GT(coarse, 0.01);  // the coarse lattice does ripple off the axes: the test sees it
  EXPECT_LT(coarse * kDimTrackFraction, 0.005);
  EXPECT_LT(planeWaveRipple(kDimTrackSpacing, 0.0, 0.0), 1e-9);
  EXPECT_LT(planeWaveRipple(kTrackSpacing, 90.0, 0.0), 1e-9);
}

}  // namespace
}  // namespace eik
