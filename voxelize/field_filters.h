// Filters on voxel fields used to turn a raw (box-filtered) refractive-index field into the smooth
// n and ∇n the ray equation needs (thesis §3.1).
#pragma once

#include "core/gaussian_filter.h"
#include "core/grid.h"
#include "core/volume.h"

namespace eik {

// Default standard deviation of the pre-smoothing kernel, in voxels (thesis §3.1: 0.5–1).
constexpr double kDefaultSmoothSigmaVoxels = 0.75;

// gaussianRadius and gaussianSmooth (Eq. 3.2) live in core/gaussian_filter.h.

// ∇f of a 1-component field by central differences (thesis Eq. 3.1), in 1/world-unit:
// (f(i+1) − f(i−1)) / 2h per axis, one-sided (f(1) − f(0)) / h at the borders, 0 along an axis
// that is one voxel thick. Returns a 3-component field.
//
// Eq. 3.1 alone is anisotropic on boundaries only a few voxels wide: its response sin(ωh)/h
// under-reads steep profiles more along the axes than along diagonals, so on a glass sphere
// pre-smoothed with σ = 0.75 voxel the gradient of a surface voxel points up to ~5.5° away from
// the normal (measured, 128³; see pipeline_test.cpp).
Field centralDifferenceGradient(const Field& scalar, const GridSpec& grid);

// Eq. 3.1 along each axis, averaged over the neighbouring parallel lines with the weights
// [1, 4, 1]/6 in each of the two other axes (a 3×3×3 stencil in the Sobel family, which the thesis
// §3.1 names as equally valid). The cross-average cancels the second-order anisotropy of the
// central difference, sin ω·(1 − (1 − cos ω')/3)… ≈ ω (1 − |ω|²/6), so ∇n keeps its direction to
// about 1.6° on the same sphere (0.6° on an exactly smoothed profile). Borders as above.
Field isotropicGradient(const Field& scalar, const GridSpec& grid);

enum class GradientOperator {
  CentralDifference,  // centralDifferenceGradient: Eq. 3.1 exactly as printed
  Isotropic,          // isotropicGradient (default)
};
Field gradient(const Field& scalar, const GridSpec& grid, GradientOperator op);
const char* gradientOperatorName(GradientOperator op);  // "central_difference" | "isotropic"

}  // namespace eik
