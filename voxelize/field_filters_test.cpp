#include "voxelize/field_filters.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>

namespace eik {
namespace {

GridSpec makeGridSpec(glm::ivec3 dims, glm::dvec3 lo, glm::dvec3 hi) {
  GridSpec g;
  g.dims = dims;
  g.bounds_min = lo;
  g.bounds_max = hi;
  return g;
}

Field sampled(const GridSpec& g, const std::function<double(const glm::dvec3&)>& f) {
  Field field;
  field.components = 1;
  field.data.resize(g.count());
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = 0; j < g.dims.y; ++j)
      for (int i = 0; i < g.dims.x; ++i) field.data[g.index(i, j, k)] = static_cast<float>(f(g.center(i, j, k)));
  return field;
}

double sum(const Field& f) {
  double s = 0.0;
  for (float v : f.data) s += v;
  return s;
}

TEST(GaussianSmooth, KernelRadiusIsCeilThreeSigma) {
  EXPECT_EQ(gaussianRadius(0.0), 0);
  EXPECT_EQ(gaussianRadius(0.5), 2);
  EXPECT_EQ(gaussianRadius(0.75), 3);
  EXPECT_EQ(gaussianRadius(1.0), 3);
  EXPECT_EQ(gaussianRadius(1.1), 4);
}

TEST(GaussianSmooth, ZeroSigmaIsANoOp) {
  const GridSpec g = makeGridSpec({8, 8, 8}, glm::dvec3(0), glm::dvec3(1));
  Field f = sampled(g, [](const glm::dvec3& p) { return std::sin(7 * p.x) + p.y * p.z; });
  const Field before = f;
  gaussianSmooth(f, g, 0.0);
  EXPECT_EQ(f.data, before.data);
}

TEST(GaussianSmooth, ImpulseResponseIsTheNormalisedGaussian) {
  const GridSpec g = makeGridSpec({15, 15, 15}, glm::dvec3(0), glm::dvec3(15));
  Field f;
  f.data.assign(g.count(), 0.0f);
  f.data[g.index(7, 7, 7)] = 1.0f;
  const double sigma = 0.75;
  gaussianSmooth(f, g, sigma);
  // Separable, normalised exp(−k²/(2σ²)) (Eq. 3.2): the value at offset (a, b, c) is w_a·w_b·w_c.
  double norm = 0.0;
  for (int k = -3; k <= 3; ++k) norm += std::exp(-0.5 * k * k / (sigma * sigma));
  auto w = [&](int k) { return std::abs(k) > 3 ? 0.0 : std::exp(-0.5 * k * k / (sigma * sigma)) / norm; };
  for (int c = -4; c <= 4; ++c)
    for (int b = -4; b <= 4; ++b)
      for (int a = -4; a <= 4; ++a)
        EXPECT_NEAR(f.data[g.index(7 + a, 7 + b, 7 + c)], w(a) * w(b) * w(c), 1e-7) << a << " " << b << " " << c;
  EXPECT_NEAR(sum(f), 1.0, 1e-6);
}

TEST(GaussianSmooth, PreservesMassAwayFromTheBorders) {
  const GridSpec g = makeGridSpec({40, 36, 32}, glm::dvec3(-1), glm::dvec3(1));
  // A lumpy blob well inside the grid (its support ends 3σ + 1 voxels from every face).
  Field f = sampled(g, [](const glm::dvec3& p) {
    const double r = glm::length(p - glm::dvec3(0.1, -0.05, 0.0));
    return r < 0.6 ? 0.5 + 0.3 * std::sin(9 * p.x) * std::cos(5 * p.y) : 0.0;
  });
  const double before = sum(f);
  gaussianSmooth(f, g, 1.0);
  EXPECT_NEAR(sum(f), before, 1e-5 * before);
}

TEST(GaussianSmooth, KeepsConstantsEverywhereAndRampsInTheInterior) {
  const GridSpec g = makeGridSpec({24, 20, 18}, glm::dvec3(0), glm::dvec3(2.4, 2.0, 1.8));
  Field constant = sampled(g, [](const glm::dvec3&) { return 1.0; });
  gaussianSmooth(constant, g, 0.75);
  for (float v : constant.data) ASSERT_NEAR(v, 1.0f, 1e-6f);  // air stays air up to the borders

  auto ramp = [](const glm::dvec3& p) { return 1.0 + 0.2 * p.x - 0.1 * p.y + 0.3 * p.z; };
  Field f = sampled(g, ramp);
  const double sigma = 1.0;
  gaussianSmooth(f, g, sigma);
  const int r = gaussianRadius(sigma);
  for (int k = r; k < g.dims.z - r; ++k)
    for (int j = r; j < g.dims.y - r; ++j)
      for (int i = r; i < g.dims.x - r; ++i)
        ASSERT_NEAR(f.data[g.index(i, j, k)], ramp(g.center(i, j, k)), 2e-6) << i << " " << j << " " << k;
}

TEST(GaussianSmooth, RejectsBadArguments) {
  const GridSpec g = makeGridSpec({4, 4, 4}, glm::dvec3(0), glm::dvec3(1));
  Field f;
  f.data.assign(g.count(), 0.0f);
  EXPECT_THROW(gaussianSmooth(f, g, -1.0), std::invalid_argument);
  Field wrong;
  wrong.data.assign(7, 0.0f);
  EXPECT_THROW(gaussianSmooth(wrong, g, 1.0), std::invalid_argument);
  Field vec;
  vec.components = 3;
  vec.data.assign(g.count() * 3, 0.0f);
  EXPECT_THROW(gaussianSmooth(vec, g, 1.0), std::invalid_argument);
}

TEST(Gradient, OfALinearFieldIsExactEverywhereInWorldUnits) {
  // Non-cubic voxels, so each axis must divide by its own spacing.
  const GridSpec g = makeGridSpec({9, 7, 5}, glm::dvec3(-1, 0, 2), glm::dvec3(1, 0.5, 4));
  const glm::dvec3 slope(0.7, -2.5, 0.125);
  const Field f = sampled(g, [&](const glm::dvec3& p) { return 1.2 + glm::dot(slope, p); });
  for (GradientOperator op : {GradientOperator::CentralDifference, GradientOperator::Isotropic}) {
    const Field grad = gradient(f, g, op);
    ASSERT_EQ(grad.components, 3);
    ASSERT_EQ(grad.data.size(), g.count() * 3);
    for (std::size_t v = 0; v < g.count(); ++v)  // borders included (one-sided differences)
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(grad.voxel(v)[a], slope[a], 2e-4) << gradientOperatorName(op) << " " << v;
  }
}

TEST(Gradient, CentralDifferenceIsEquation31) {
  const GridSpec g = makeGridSpec({5, 4, 3}, glm::dvec3(0), glm::dvec3(5, 2, 3));  // h = (1, 0.5, 1)
  const Field f = sampled(g, [](const glm::dvec3& p) { return p.x * p.x + std::sin(p.y) * p.z; });
  const Field grad = centralDifferenceGradient(f, g);
  auto F = [&](int i, int j, int k) { return static_cast<double>(f.data[g.index(i, j, k)]); };
  const float* mid = grad.voxel(g.index(2, 1, 1));
  EXPECT_NEAR(mid[0], (F(3, 1, 1) - F(1, 1, 1)) / 2.0, 1e-6);
  EXPECT_NEAR(mid[1], (F(2, 2, 1) - F(2, 0, 1)) / 1.0, 1e-6);
  EXPECT_NEAR(mid[2], (F(2, 1, 2) - F(2, 1, 0)) / 2.0, 1e-6);
  const float* corner = grad.voxel(g.index(4, 0, 0));  // one-sided at the borders
  EXPECT_NEAR(corner[0], F(4, 0, 0) - F(3, 0, 0), 1e-6);
  EXPECT_NEAR(corner[1], (F(4, 1, 0) - F(4, 0, 0)) / 0.5, 1e-6);
  EXPECT_NEAR(corner[2], F(4, 0, 1) - F(4, 0, 0), 1e-6);
}

TEST(Gradient, IsotropicAveragesEquation31AcrossWith141) {
  const GridSpec g = makeGridSpec({5, 5, 5}, glm::dvec3(0), glm::dvec3(5));
  Field f;
  f.data.assign(g.count(), 0.0f);
  f.data[g.index(3, 2, 2)] = 1.0f;  // an impulse right of the centre voxel
  const Field grad = isotropicGradient(f, g);
  // d/dx at the centre: +1/2 from the impulse, weighted 4/6·4/6 on its own line.
  EXPECT_NEAR(grad.voxel(g.index(2, 2, 2))[0], 0.5 * (4.0 / 6.0) * (4.0 / 6.0), 1e-6);
  // … and 1/6·4/6 on a neighbouring line, 1/6·1/6 on a diagonal one.
  EXPECT_NEAR(grad.voxel(g.index(2, 3, 2))[0], 0.5 * (1.0 / 6.0) * (4.0 / 6.0), 1e-6);
  EXPECT_NEAR(grad.voxel(g.index(2, 3, 1))[0], 0.5 * (1.0 / 6.0) * (1.0 / 6.0), 1e-6);
}

TEST(Gradient, ThinAxisHasZeroDerivative) {
  const GridSpec g = makeGridSpec({6, 6, 1}, glm::dvec3(0), glm::dvec3(6, 6, 1));
  const Field f = sampled(g, [](const glm::dvec3& p) { return p.x + p.z; });
  for (GradientOperator op : {GradientOperator::CentralDifference, GradientOperator::Isotropic}) {
    const Field grad = gradient(f, g, op);
    for (std::size_t v = 0; v < g.count(); ++v) {
      EXPECT_NEAR(grad.voxel(v)[0], 1.0f, 1e-6f);
      EXPECT_EQ(grad.voxel(v)[2], 0.0f);
    }
  }
}

}  // namespace
}  // namespace eik
