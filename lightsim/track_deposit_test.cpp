// Track deposits (track_deposit.h): the hat weights along a path are exact and sum to one.
#include "lightsim/track_deposit.h"

#include <gtest/gtest.h>

#include <map>

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
}

}  // namespace
}  // namespace eik
