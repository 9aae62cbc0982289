#include "core/spectrum.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace eik {

namespace {

// A Gaussian lobe with different widths either side of its peak (Wyman et al. 2013, Eq. 2); nm.
double lobe(double lambda_nm, double mu, double sigma_below, double sigma_above) {
  const double t = (lambda_nm - mu) / (lambda_nm < mu ? sigma_below : sigma_above);
  return std::exp(-0.5 * t * t);
}

}  // namespace

glm::dvec3 cieXyz(double lambda_um) {
  const double l = 1000.0 * lambda_um;
  const double x = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
                   0.065 * lobe(l, 501.1, 20.4, 26.2);
  const double y = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
  const double z = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
  return {x, y, z};
}

glm::dvec3 xyzToLinearSrgb(const glm::dvec3& c) {
  return {3.2406 * c.x - 1.5372 * c.y - 0.4986 * c.z, -0.9689 * c.x + 1.8758 * c.y + 0.0415 * c.z,
          0.0557 * c.x - 0.2040 * c.y + 1.0570 * c.z};
}

std::vector<SpectralBand> spectralBands(int count) {
  if (count < 1 || count == 2 || count > kMaxSpectralBands)
    throw InputError("--bands", std::to_string(count), "expected 1, 3, or 4 to 16 bands");
  if (count == 1) return {SpectralBand{}};
  if (count == 3)
    return {SpectralBand{0.61, {1.0, 0.0, 0.0}}, SpectralBand{0.55, {0.0, 1.0, 0.0}},
            SpectralBand{0.465, {0.0, 0.0, 1.0}}};
  constexpr double kFrom = 0.38, kTo = 0.78;
  std::vector<SpectralBand> bands(static_cast<std::size_t>(count));
  glm::dvec3 total(0.0);
  for (int b = 0; b < count; ++b) {
    const double lo = kFrom + (kTo - kFrom) * b / count, hi = kFrom + (kTo - kFrom) * (b + 1) / count;
    SpectralBand& band = bands[static_cast<std::size_t>(b)];
    band.lambda_um = 0.5 * (lo + hi);
    // ∫ over the band by the midpoint rule on 1 nm steps (the functions vary over tens of nm).
    const int steps = std::max(1, static_cast<int>(std::lround((hi - lo) * 1000.0)));
    glm::dvec3 xyz(0.0);
    for (int s = 0; s < steps; ++s) xyz += cieXyz(lo + (hi - lo) * (s + 0.5) / steps);
    band.rgb = glm::max(xyzToLinearSrgb(xyz), glm::dvec3(0.0));
    total += band.rgb;
  }
  for (SpectralBand& band : bands) band.rgb /= total;
  return bands;
}

}  // namespace eik
