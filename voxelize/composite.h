// Compositing voxelised objects (Regions) into one material Volume (docs/volume-format.md, thesis §6.1).
//
// Nested objects: the innermost wins. Regions are ordered by enclosed_volume, smallest first
// (ties: the later input first); each voxel hands out its space greedily, f_i = min(cov_i,
// remaining), remaining −= f_i, and air takes what is left. The fields are then the
// fraction-weighted mixtures
//   n  = 1 + Σ f_i (n_i − 1)              (per-voxel n_i where a region has one)
//   σa = Σ f_i σa_i,   L_e = Σ f_i L_e,i,   dispersion B = Σ f_i B_i   (air: 0)
//   scatter ω̂ = Σ f_i ω̂_i,   g = Σ f_i ω̂_i g_i / Σ f_i ω̂_i   (g of the scattering part)
//   opaque indicator = Σ f_i over opaque regions, albedo = their f-weighted mean albedo
// The result's `ior` is raw (unsmoothed); see pipeline.h for smoothing and ∇n.
#pragma once

#include <vector>

#include "core/grid.h"
#include "core/progress.h"
#include "core/volume.h"
#include "voxelize/region.h"

namespace eik {

struct CompositeOptions {
  // Write sigma_a, emission, scatter, opaque and dispersion even when no region needs them
  // (by default only fields some region makes non-zero are written).
  bool all_fields = false;
  // Blend `ior` by coverage (smooth interfaces). False: the field is left out, for a caller that
  // takes n from somewhere else (sharp interfaces: n at the voxel centres from the distances,
  // sharp_interfaces.h), which then neither computes nor touches that grid of floats.
  bool ior = true;
  ProgressFn progress;
};

// Composites `regions` (each coverage (and ior, if any) grid.count() long) into a Volume on `grid`
// with field `ior` (unless CompositeOptions::ior is false) and, as needed, `sigma_a`, `emission`, `scatter`, `opaque`, `dispersion`.
// volume.metadata["materials"] gets one entry per region, in input order: name, ior, sigma_a,
// emission, scatter, g, dispersion_b, opaque (+ albedo), enclosed_volume and `volume`, the world
// volume it holds after compositing (Σ f_i·V_voxel). Throws std::invalid_argument for a region
// whose arrays do not match the grid.
Volume compositeRegions(const std::vector<Region>& regions, const GridSpec& grid, const CompositeOptions& options = {});

// Whether a region of this material makes compositeRegions write a field besides `ior` (σa,
// emission, scattering, opaque, dispersion), which blend the regions by their coverage. Without
// one, and with sharp interfaces (whose n comes from the distances, sharp_interfaces.h), a region's
// coverage decides nothing but its enclosed and reported volume.
bool blendsFields(const Material& material);

// The order in which compositeRegions hands out voxel space: indices into `regions`, innermost
// (smallest enclosed_volume) first, ties broken in favour of the later input.
std::vector<std::size_t> compositeOrder(const std::vector<Region>& regions);

}  // namespace eik
