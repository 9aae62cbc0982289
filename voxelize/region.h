// The result of voxelising one object: how much of each voxel it covers, with its material.
// Regions from all inputs are composited into a Volume by `compositeRegions` (composite.h):
// where regions overlap the innermost one wins (smallest `enclosed_volume` first).
#pragma once

#include <string>
#include <vector>

#include "core/grid.h"
#include "voxelize/material.h"

namespace eik {

struct Region {
  std::string name;                 // for messages and --stats, e.g. "sphere", "wine", "mesh:Cube"
  Material material;
  std::vector<float> coverage;      // fraction of each voxel inside, in [0, 1]; GridSpec::count() long
  // Optional spatially varying refractive index (Luneburg lens, gradient slab): the mean n over the
  // covered part of each voxel. Empty: the material's constant ior.
  std::vector<float> ior;
  // Sharp interfaces (core/interfaces.h): the signed distance from each voxel centre to the
  // object's surface in world units, negative inside, clamped to ±band. Empty when not asked for.
  std::vector<float> distance;
  // A graded object (non-empty `ior`) in sharp mode: n at each voxel centre inside the object and
  // within the band around it, the material's n(x) continued across the surface, so that n and ∇n
  // near the surface come without the jump to the neighbouring material.
  std::vector<float> ior_at_center;
  // World-space volume enclosed by the object (for the innermost-wins rule and --stats). An open
  // surface (receiver layer) has 0 and so always wins over the solids around it.
  double enclosed_volume = 0.0;
};

}  // namespace eik
