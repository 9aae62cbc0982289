// The oracle checked against closed-form optics, so that the tests that lean on it lean on
// something right.
#include "tests/reference/exact_optics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace eik::reference {
namespace {

TEST(ExactOptics, FresnelMatchesTabulatedValues) {
  EXPECT_NEAR(fresnelReflectance(1.0, 1.5, 1.0), 0.04, 1e-15);
  EXPECT_NEAR(fresnelReflectance(1.5, 1.0, 1.0), 0.04, 1e-15);
  // At Brewster's angle Rp = 0, so R = Rs/2; Rs = 0.1479 for n = 1.5 (Hecht, Optics, Fig. 4.49).
  const double brewster = std::atan(1.5);
  EXPECT_NEAR(fresnelReflectance(1.0, 1.5, std::cos(brewster)), 0.0739, 1e-4);
  // Total internal reflection past the critical angle asin(1/1.5) = 41.8°.
  EXPECT_EQ(fresnelReflectance(1.5, 1.0, std::cos(42.0 * std::numbers::pi / 180.0)), 1.0);
  EXPECT_LT(fresnelReflectance(1.5, 1.0, std::cos(41.0 * std::numbers::pi / 180.0)), 1.0);
}

TEST(ExactOptics, IntersectsSpheresAndPolyhedraFromBothSides) {
  const Solid sphere = Solid::sphere({0, 0, 0}, 1.0, 1.5);
  Hit hit;
  ASSERT_TRUE(sphere.intersect({0, 5, 0}, {0, -1, 0}, 1e-9, hit));
  EXPECT_NEAR(hit.t, 4.0, 1e-12);
  EXPECT_NEAR(hit.normal.y, 1.0, 1e-12);
  ASSERT_TRUE(sphere.intersect({0, 0, 0}, {0, -1, 0}, 1e-9, hit));  // from inside
  EXPECT_NEAR(hit.t, 1.0, 1e-12);
  EXPECT_NEAR(hit.normal.y, -1.0, 1e-12);
  EXPECT_FALSE(sphere.intersect({2, 5, 0}, {0, -1, 0}, 1e-9, hit));

  const Solid prism = Solid::prism({0, 0}, {2, 0}, {1, 1.5}, -1, 1, 1.5);
  EXPECT_TRUE(prism.contains({1, 0.5, 0}));
  EXPECT_FALSE(prism.contains({0.1, 1.0, 0}));
  ASSERT_TRUE(prism.intersect({1, 5, 0}, {0, -1, 0}, 1e-9, hit));
  EXPECT_NEAR(hit.t, 3.5, 1e-12);
  ASSERT_TRUE(prism.intersect({1, 0.5, 0}, {0, -1, 0}, 1e-9, hit));
  EXPECT_NEAR(hit.t, 0.5, 1e-12);
  EXPECT_NEAR(hit.normal.y, -1.0, 1e-12);
}

// With n = 1 the sphere is invisible: the plane is lit uniformly, and the low-discrepancy beam
// makes the rings flat to far better than independent samples would (1/sqrt(N) per ring).
TEST(ExactOptics, AnIndexMatchedSphereIsInvisible) {
  DirectionalBeam beam;
  beam.beam_center = {0, 1.5, 0};
  beam.beam_radius = 2.0;
  Receiver receiver;
  receiver.ring_width = 0.1;
  receiver.max_radius = 2.0;
  TraceOptions options;
  options.rays = 200'000;
  const ReceiverTally tally = trace({Solid::sphere({0, 1.5, 0}, 1.0, 1.0)}, beam, receiver, options);
  EXPECT_NEAR(tally.flux_received, tally.flux_emitted, 1e-9 * tally.flux_emitted);
  for (double r = 0.1; r < 1.95; r += 0.1) EXPECT_NEAR(tally.ringIrradiance(r, r + 0.1), 1.0, 0.01) << "ring at r = " << r;
  EXPECT_NEAR(tally.encircledFlux(1.0), std::numbers::pi, 0.005);
}

// A slab wider than the beam at normal incidence transmits (1 − R)/(1 + R) of the light, summing
// every internal reflection (R = 0.04 for n = 1.5: T = 0.923); the rest goes back up.
TEST(ExactOptics, ASlabTransmitsTheIncoherentFresnelSum) {
  DirectionalBeam beam;
  beam.beam_center = {0, 1.5, 0};
  beam.beam_radius = 0.5;
  Receiver receiver;
  receiver.max_radius = 1.0;
  TraceOptions options;
  options.rays = 400'000;
  const ReceiverTally tally = trace({Solid::box({-50, 1, -50}, {50, 2, 50}, 1.5)}, beam, receiver, options);
  const double r = 0.04, expected = (1.0 - r) / (1.0 + r);
  // Russian roulette: the received fraction is binomial, σ = sqrt(T(1 − T)/N) = 4·10⁻⁴; 4σ.
  EXPECT_NEAR(tally.flux_received / tally.flux_emitted, expected, 1.6e-3);
  EXPECT_NEAR(tally.flux_received + tally.flux_escaped + tally.flux_dropped, tally.flux_emitted,
              1e-9 * tally.flux_emitted);
}

// The fluence tally and absorption: a vertical beam through an absorbing, index-matched slab
// (n = 1: no refraction, no reflection; σa = 2, 0.4 thick) over a grid of cells 0.05 high. Each
// cell's fluence rate is the beam's irradiance averaged over its height, E·e^(−σa (0.2 − y)) in the
// slab, E above it and E·e^(−0.8) below; the absorbed flux is E·A·(1 − e^(−0.8)). Cells cut at
// random offsets by the DDA's faces, so rounding there would show.
TEST(ExactOptics, TheFluenceInAnAbsorbingSlabFollowsBeerLambertCellByCell) {
  DirectionalBeam beam;
  beam.beam_center = {0, 1.0, 0};
  beam.beam_radius = 1.0;
  Receiver receiver;
  receiver.point = {0, -2, 0};
  TraceOptions options;
  options.rays = 20'000;
  options.fluence.lo = {-0.3, -0.3, -0.3};
  options.fluence.hi = {0.3, 0.3, 0.3};
  options.fluence.dims = {3, 12, 3};
  Solid slab = Solid::box({-50, -0.2, -50}, {50, 0.2, 50}, 1.0);
  slab.sigma_a = 2.0;
  const ReceiverTally tally = trace({slab}, beam, receiver, options);
  const double sigma = 2.0, dy = 0.05;
  for (int j = 0; j < 12; ++j) {
    const double y0 = -0.3 + j * dy, y1 = y0 + dy;
    // ∫ e^(−σ (0.2 − y)) dy / dy over the part in the slab, plus the parts above and below.
    auto inside = [&](double a, double b) { return (std::exp(-sigma * (0.2 - b)) - std::exp(-sigma * (0.2 - a))) / sigma; };
    double expected = 0.0;
    if (y1 > 0.2) expected += y1 - std::max(y0, 0.2);
    if (y0 < -0.2) expected += std::exp(-0.8) * (std::min(y1, -0.2) - y0);
    if (y1 > -0.2 && y0 < 0.2) expected += inside(std::max(y0, -0.2), std::min(y1, 0.2));
    expected /= dy;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        // The beam covers every cell wholly, and every ray's path through a cell is the same: the
        // tally is exact up to the rays' density over the cell's 0.2² top, 20 000 rays on π m² in a
        // low-discrepancy pattern, ~0.6 % (R2 sequence's star discrepancy over ~250 rays per cell).
        EXPECT_NEAR(tally.fluence[static_cast<std::size_t>(i + 3 * (j + 12 * k))], expected, 0.02 * expected)
            << "layer " << j;
  }
  EXPECT_NEAR(tally.flux_absorbed, std::numbers::pi * (1.0 - std::exp(-0.8)), 1e-9);
  EXPECT_NEAR(tally.flux_received + tally.flux_absorbed, tally.flux_emitted, 1e-9);
}

// A ray through a prism at minimum deviation: D = 2·asin(n·sin(A/2)) − A. An equilateral prism
// (A = 60°, n = 1.5) deviates a thin beam by 37.18°; the beam lands where that angle says.
TEST(ExactOptics, APrismDeviatesByTheMinimumDeviationAngle) {
  const double n = 1.5, apex = std::numbers::pi / 3.0;
  const double deviation = 2.0 * std::asin(n * std::sin(apex / 2.0)) - apex;
  // Apex up, side 1: the left face's inward normal points 30° below the horizontal. At minimum
  // deviation the ray inside runs parallel to the base, θt = A/2 from that normal, so the beam
  // arrives θi = (A + D)/2 from it: tilted up by θi − 30°, and leaves tilted down by as much.
  const double theta_i = (apex + deviation) / 2.0;
  const double tilt = theta_i - std::numbers::pi / 6.0;
  DirectionalBeam beam;
  beam.direction = {std::cos(tilt), std::sin(tilt), 0.0};
  beam.beam_center = {-0.25, std::sqrt(3.0) / 4.0, 0.0};  // the middle of the left face
  beam.beam_radius = 0.01;
  Receiver receiver;
  receiver.point = {0, -5, 0};
  receiver.center = {0, -5, 0};
  receiver.ring_width = 0.001;
  receiver.max_radius = 20.0;
  TraceOptions options;
  options.rays = 20'000;
  const Solid prism = Solid::prism({-0.5, 0}, {0.5, 0}, {0, std::sqrt(3.0) / 2.0}, -1, 1, n);
  const ReceiverTally tally = trace({prism}, beam, receiver, options);
  // From the middle of the right face (0.25, √3/4) the beam reaches y = −5 at
  // x = 0.25 + (5 + √3/4) / tan(D − tilt).
  const double expected_x = 0.25 + (5.0 + std::sqrt(3.0) / 4.0) / std::tan(deviation - tilt);
  // Flux-weighted landing point of the main beam (everything within 0.5 of where it should be;
  // internal reflections land elsewhere).
  double flux = 0.0, moment = 0.0;
  for (std::size_t i = 0; i < tally.ring_flux.size(); ++i) {
    const double r = (static_cast<double>(i) + 0.5) * tally.ring_width;
    if (std::abs(r - expected_x) > 0.5) continue;
    flux += tally.ring_flux[i];
    moment += r * tally.ring_flux[i];
  }
  // 1 − R twice at these angles: about 0.9 of the beam arrives there.
  EXPECT_GT(flux, 0.85 * tally.flux_emitted);
  // The beam's footprint is symmetric about its axis; rings of 0.001 bound the error: 0.002.
  EXPECT_NEAR(moment / flux, expected_x, 0.002);
  EXPECT_NEAR(deviation * 180.0 / std::numbers::pi, 37.18, 0.01);
}

}  // namespace
}  // namespace eik::reference
