// The generalized winding number: the hierarchical (Barnes–Hut) evaluation against the brute-force
// sum on a leaky torus.
#include "voxelize/winding_number.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "voxelize/test_meshes.h"

namespace eik {
namespace {

TEST(WindingNumber, FastMatchesBruteForce) {
  const TriangleMesh torus = punchHoles(makeTorus(glm::dvec3(0.1, 0, 0), 0.6, 0.25, 64, 32), glm::dvec3(0.0),
                                        {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  const FastWindingNumber fast(torus), exacter(torus, 3.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0, worst_exacter = 0.0;
  for (int i = 0; i < 300; ++i) {
    const glm::dvec3 q(u(rng), u(rng), 0.5 * u(rng));
    const double exact = windingNumberBruteForce(torus, q);
    worst = std::max(worst, std::abs(fast(q) - exact));
    worst_exacter = std::max(worst_exacter, std::abs(exacter(q) - exact));
  }
  EXPECT_LT(worst, 0.03);
  EXPECT_LT(worst_exacter, 0.01);
  EXPECT_NEAR(windingNumberBruteForce(torus, {0.7, 0.0, 0.0}), 1.0, 0.05);
  EXPECT_NEAR(windingNumberBruteForce(torus, {0.1, 0.0, 0.0}), 0.0, 0.05);
}

}  // namespace
}  // namespace eik
