#include "core/gaussian_filter.h"

#include <gtest/gtest.h>

#include <numeric>
#include <stdexcept>

namespace eik {
namespace {

GridSpec cube(int n) {
  GridSpec g;
  g.dims = glm::ivec3(n);
  g.bounds_min = glm::dvec3(0.0);
  g.bounds_max = glm::dvec3(1.0);
  return g;
}

// Each component of a 3-component field is filtered exactly as the same values alone would be,
// and, away from the borders, keeps its sum.
TEST(GaussianSmoothComponents, FiltersEachComponentLikeAScalar) {
  const GridSpec g = cube(16);
  const std::size_t n = g.count();
  Field rgb;
  rgb.components = 3;
  rgb.data.assign(n * 3, 0.0f);
  Field channel[3];
  for (int c = 0; c < 3; ++c) {
    channel[c].data.assign(n, 0.0f);
    const std::size_t voxel = (8 + 16 * (7 + c) + 256 * 8);  // a different spike per channel
    channel[c].data[voxel] = 1.0f + static_cast<float>(c);
    rgb.data[voxel * 3 + static_cast<std::size_t>(c)] = channel[c].data[voxel];
  }
  gaussianSmoothComponents(rgb, g, 1.0);
  for (int c = 0; c < 3; ++c) {
    gaussianSmooth(channel[c], g, 1.0);
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_FLOAT_EQ(rgb.data[i * 3 + static_cast<std::size_t>(c)], channel[c].data[i]) << "channel " << c;
      sum += rgb.data[i * 3 + static_cast<std::size_t>(c)];
    }
    EXPECT_NEAR(sum, 1.0 + c, 1e-5) << "channel " << c;
    EXPECT_LT(channel[c].data[8 + 16 * (7 + c) + 256 * 8], 0.1f * (1.0f + static_cast<float>(c)));  // spread out
  }
}

TEST(GaussianSmoothComponents, RejectsAFieldThatDoesNotFitTheGrid) {
  Field f;
  f.components = 3;
  f.data.assign(10, 0.0f);
  EXPECT_THROW(gaussianSmoothComponents(f, cube(4), 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace eik
