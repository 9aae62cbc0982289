// Sharp interfaces (core/interfaces.h; docs/physics.md "Sharp interfaces"): the fields of a volume
// whose material boundaries stay sharp, for `voxelize --interfaces sharp` (the default).
//
// From the regions (each with its coverage and its narrow-band signed distance, Region::distance):
//  - `interfaces`: the signed distance of each slot, a slot being one optical material — the union
//    of the regions that share it (same n and dispersion; all opaque regions together; a graded
//    region alone), innermost first. Regions of n = 1 outside every other material (smoke around
//    an object) need no slot;
//  - `ior`: n of the material at each voxel centre, unblended (for a graded region its n(x), also
//    continued over the band outside it); `ior_grad`: ∇n of the graded regions only (central
//    differences of their own n, so no jump enters), 0 elsewhere;
//  - `dispersion`: the Cauchy B of the material at each voxel centre;
//  - σa, emission, scatter and opaque as compositeRegions mixes them (they enter along the ray
//    linearly; no ray bends at their edges).
// No Gaussian pre-smoothing: Eq. 3.2 is the thesis' smoothed mode (`--interfaces smooth`).
#pragma once

#include <vector>

#include "core/grid.h"
#include "core/interfaces.h"
#include "core/volume.h"
#include "voxelize/composite.h"
#include "voxelize/region.h"

namespace eik {

// The slots of `regions` (innermost first) and, for each region, its slot or −1 (no slot). Throws
// InputError naming `--interfaces` when more than kMaxInterfaceSlots materials need one.
struct SlotAssignment {
  InterfaceTable table;
  std::vector<int> slot_of_region;
};
SlotAssignment assignInterfaceSlots(const std::vector<Region>& regions, double band);

// The volume described above. Every region must carry `distance` (and a graded one
// `ior_at_center`), grid.count() long; std::invalid_argument otherwise.
Volume buildSharpVolume(const std::vector<Region>& regions, const GridSpec& grid, double band,
                        const CompositeOptions& options = {});
// The same, releasing each region's arrays once they are read (coverage after compositing, the
// distances once the slots hold them), so that the volume's own fields reuse their memory: at 128³
// a full-grid array (9 MB) less at the peak. The regions keep their names and materials.
Volume buildSharpVolume(std::vector<Region>&& regions, const GridSpec& grid, double band,
                        const CompositeOptions& options = {});

}  // namespace eik
