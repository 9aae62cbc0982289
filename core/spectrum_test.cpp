// The spectral bands (spectrum.h): the colour-matching fit against the CIE 1931 table's known
// values, and bands that add up to the light they split.
#include "core/spectrum.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace eik {
namespace {

// The fit against the CIE 1931 2° table (CIE 15:2004) at its peaks and landmarks: ȳ(555 nm) =
// 1.0000, x̄(600) = 1.0622, z̄(445) = 1.7826 (the fit's 1.78), x̄(445) = 0.3481; and ∫ȳ dλ =
// 106.86 nm over 360–830 nm. Wyman et al. give the fit as within a few per cent of the table
// pointwise: 3 % here, 1 % on the integral.
TEST(Spectrum, ColourMatchingFitMatchesTheCie1931Table) {
  EXPECT_NEAR(cieXyz(0.555).y, 1.0, 0.03);
  EXPECT_NEAR(cieXyz(0.600).x, 1.0622, 0.03);
  EXPECT_NEAR(cieXyz(0.445).z, 1.7826, 0.05);
  EXPECT_NEAR(cieXyz(0.445).x, 0.3481, 0.02);
  double y = 0.0;
  for (int nm = 360; nm < 830; ++nm) y += cieXyz((nm + 0.5) / 1000.0).y;
  EXPECT_NEAR(y / 106.86, 1.0, 0.01);
  // Equal energy (CIE illuminant E) is white: x = y = z = 1/3 in chromaticity.
  glm::dvec3 e(0.0);
  for (int nm = 360; nm < 830; ++nm) e += cieXyz((nm + 0.5) / 1000.0);
  EXPECT_NEAR(e.x / (e.x + e.y + e.z), 1.0 / 3.0, 0.005);
  EXPECT_NEAR(e.y / (e.x + e.y + e.z), 1.0 / 3.0, 0.005);
}

// Bands split a light and give it back: every channel's shares sum to 1, none negative; red is
// carried by the long waves and blue by the short; 3 bands are the viewer's R, G, B wavelengths.
TEST(Spectrum, BandsSplitWhiteAndSumBackToIt) {
  for (const int count : {1, 3, 4, 7, 16}) {
    const std::vector<SpectralBand> bands = spectralBands(count);
    ASSERT_EQ(bands.size(), static_cast<std::size_t>(count));
    glm::dvec3 total(0.0);
    for (const SpectralBand& b : bands) {
      EXPECT_GE(glm::min(b.rgb.x, glm::min(b.rgb.y, b.rgb.z)), 0.0);
      total += b.rgb;
    }
    EXPECT_NEAR(glm::length(total - glm::dvec3(1.0)), 0.0, 1e-12) << count;
    for (std::size_t i = 1; i < bands.size(); ++i) EXPECT_NE(bands[i].lambda_um, bands[i - 1].lambda_um);
  }
  const std::vector<SpectralBand> three = spectralBands(3);
  EXPECT_EQ(three[0].lambda_um, 0.61);
  EXPECT_EQ(three[2].lambda_um, 0.465);
  EXPECT_EQ(three[1].rgb, glm::dvec3(0.0, 1.0, 0.0));
  const std::vector<SpectralBand> sixteen = spectralBands(16);
  // Band centres 392.5 … 767.5 nm, 25 nm wide: red's largest share lies at 600–625 nm (band 9),
  // blue's at 430–455 (band 2), and the ends carry little.
  auto peak = [&](int channel) {
    int best = 0;
    for (int b = 0; b < 16; ++b)
      if (sixteen[static_cast<std::size_t>(b)].rgb[channel] > sixteen[static_cast<std::size_t>(best)].rgb[channel]) best = b;
    return best;
  };
  EXPECT_EQ(peak(0), 9);
  EXPECT_EQ(peak(2), 2);
  EXPECT_LT(peak(2), peak(1));
  EXPECT_LT(peak(1), peak(0));
  EXPECT_LT(sixteen[15].rgb.x, 0.01);
  for (const int bad : {0, 2, 17}) EXPECT_THROW(spectralBands(bad), InputError) << bad;
}

// n(λ) = n + B(1/λ² − 1/λ_d²): 0 at λ_d, blue bends more than red for B > 0.
TEST(Spectrum, CauchyTermIsZeroAtTheDLine) {
  EXPECT_EQ(cauchyTerm(kLambdaD), 0.0);
  EXPECT_GT(cauchyTerm(0.465), 0.0);
  EXPECT_LT(cauchyTerm(0.61), 0.0);
}

}  // namespace
}  // namespace eik
