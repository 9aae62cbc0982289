// Spectral bands (docs/physics.md "Dispersion", "Spectral bake"): the wavelengths a dispersive
// volume is baked at and the share of a light's linear RGB power each carries, so that a light
// split into bands and summed again is the light (white in, white out), while each band refracts
// with its own n(λ) = n + B·(1/λ² − 1/λ_d²) (Cauchy, the volume's `dispersion` field and slot table).
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace eik {

constexpr double kLambdaD = 0.5876;  // µm, the helium d line: n is given there
constexpr int kMaxSpectralBands = 16;

// 1/λ² − 1/λ_d² (µm⁻²): n(λ) = n + B·cauchyTerm(λ).
inline double cauchyTerm(double lambda_um) { return 1.0 / (lambda_um * lambda_um) - 1.0 / (kLambdaD * kLambdaD); }

struct SpectralBand {
  double lambda_um = kLambdaD;  // the wavelength the band refracts at (its centre)
  glm::dvec3 rgb{1.0};          // its share of a light's (linear) R, G and B power
};

// `count` bands, their shares summing to (1, 1, 1) channel by channel:
//  - 1: one band at λ_d carrying everything (no dispersion);
//  - 3: red, green and blue at 0.61, 0.55 and 0.465 µm, each carrying its own channel: the
//    wavelengths of the viewer's dispersion (viewer/IMAGE_FORMATION.md);
//  - 4 … 16: equal widths over 0.38 – 0.78 µm; band b's share is its part of the CIE 1931
//    colour-matching functions (cieXyz) taken to linear sRGB, negative parts (spectral colours lie
//    outside sRGB) set to 0, then each channel normalised over the bands.
// Throws InputError naming "--bands" for a count outside 1 … 16 or 2.
std::vector<SpectralBand> spectralBands(int count);

// The CIE 1931 2° colour-matching functions x̄, ȳ, z̄ at λ (µm), by the multi-lobe Gaussian fit of
// Wyman, Sloan and Shirley, "Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", JCGT 2(2), 2013 (within about 1 % of the tabulated functions).
glm::dvec3 cieXyz(double lambda_um);

// Linear sRGB (D65) of CIE XYZ (IEC 61966-2-1).
glm::dvec3 xyzToLinearSrgb(const glm::dvec3& xyz);

}  // namespace eik
