// Separable 3D Gaussian filtering of voxel fields: the pre-smoothing of n (thesis Eq. 3.2, used by
// voxelize) and the reconstruction filter of a bake's irradiance (lightsim --smooth-irradiance).
#pragma once

#include "core/grid.h"
#include "core/volume.h"

namespace eik {

// Radius in voxels of the discrete Gaussian kernel: ceil(3σ) (0 for σ = 0).
int gaussianRadius(double sigma_voxels);

// Clamps a voxel index into [0, n).
inline int clampIndex(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }

// Separable 3D Gaussian convolution of a 1-component field, in place (thesis Eq. 3.2).
// σ is the standard deviation in voxels along every axis; the discrete kernel
// w_k ∝ exp(−k²/(2σ²)), |k| ≤ ceil(3σ), is normalised to sum 1, so constants and (away from the
// borders) linear ramps and the field's sum are preserved. Borders clamp to the edge voxel, so a
// grid surrounded by air stays air. σ = 0 does nothing. Throws std::invalid_argument for σ < 0,
// a field that is not 1-component or whose size does not match the grid.
void gaussianSmooth(Field& scalar, const GridSpec& grid, double sigma_voxels);

// The same for each component of a field with any number of components.
void gaussianSmoothComponents(Field& field, const GridSpec& grid, double sigma_voxels);

}  // namespace eik
