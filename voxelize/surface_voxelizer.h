// Open surfaces → a thin receiver layer (the open-surface half of voxelizeMesh, mesh_voxelizer.h).
//
// OPEN SURFACES (a floor, a table top as a single sheet) are not solids: they become a thin opaque
// receiver layer — coverage = clamp((T/2 + h/2 − d)/h, 0, 1) with d the exact distance from the
// voxel centre to the nearest triangle, h the voxel size and T = surface_thickness_voxels·h, so a
// plane yields T·area of coverage volume (plus a rounded rim of πh/6 × T/h per unit length of
// open boundary, half a voxel of blur at the edge) — with enclosed_volume = 0 and the material made
// opaque (albedo kept) by voxelizeMesh.
#pragma once

#include <vector>

#include "core/grid.h"
#include "core/progress.h"
#include "voxelize/mesh.h"
#include "voxelize/mesh_voxelizer.h"

namespace eik {

// Writes the receiver layer's coverage of `mesh` (thickness options.surface_thickness_voxels) into
// `coverage` (grid.count() values; voxels no triangle reaches are left as they are). `progress`
// receives fractions in [0, 1]. Parallel over z-slices and deterministic.
void voxelizeSurfaceLayer(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                          const ProgressFn& progress, std::vector<float>& coverage);

}  // namespace eik
