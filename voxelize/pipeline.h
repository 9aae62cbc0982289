// From voxelised objects to the volume the light simulator and viewer read (thesis §3.1, §6.1):
// composite the regions, pre-smooth n with a Gaussian (Eq. 3.2), take ∇n by central differences
// (Eq. 3.1).
#pragma once

#include <vector>

#include "core/grid.h"
#include "core/progress.h"
#include "core/volume.h"
#include "voxelize/composite.h"
#include "voxelize/field_filters.h"
#include "voxelize/region.h"

namespace eik {

struct PipelineOptions {
  double smooth_sigma_voxels = kDefaultSmoothSigmaVoxels;  // σ of the pre-smoothing of n; 0: none
  GradientOperator gradient = GradientOperator::Isotropic;  // how ∇n is differenced (field_filters.h)
  bool all_fields = false;                                 // see CompositeOptions::all_fields
  ProgressFn progress;
};

// compositeRegions → gaussianSmooth(ior, σ) → ior_grad = gradient(ior) (Eq. 3.1; by default with
// the isotropic cross-average, see field_filters.h).
// Only n (and the Cauchy B of `dispersion`, which is part of n(λ)) is smoothed, as in the thesis:
// σa, emission, scatter and opaque keep their sharp box-filtered boundaries (they enter the image
// linearly, so blocky edges do not bend rays).
// metadata["ior_smoothing_sigma_voxels"] records σ, metadata["ior_gradient"] the operator.
Volume buildVolume(const std::vector<Region>& regions, const GridSpec& grid, const PipelineOptions& options = {});

}  // namespace eik
