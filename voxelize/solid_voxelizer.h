// Solid meshes → coverage (the solid half of voxelizeMesh, mesh_voxelizer.h).
//
// SOLIDS — signed ray-crossing counts along voxel columns in all three axis directions, with
// per-ray consistency checks, per-voxel voting between the axes, and the generalized winding
// number as the fallback:
//  1. For each axis, S×S parallel sub-rays per voxel column (S = supersample, regular pattern)
//     are intersected with the triangles binned into that column by projected bounding box. The
//     2-D point-in-triangle test uses exact integer edge functions on vertices snapped to a
//     2^-20-voxel fixed-point lattice (__int128 products), with ties broken by Simulation of
//     Simplicity (Edelsbrunner & Mücke 1990: the sub-ray is displaced by (ε, ε²)), so a ray through
//     a shared edge or vertex crosses exactly one of the triangles around it — watertight in the
//     sense of Woop, Benthin & Wald (JCGT 2013), without their floating-point fallbacks.
//  2. Crossings are sorted along the ray; each adds −sign(n·d) (entering +1, leaving −1). The
//     winding at −∞ is 0, so a ray whose crossings do not sum to 0 passed through a hole (or an
//     inconsistently oriented face): it abstains. A consistent ray is inside where its winding
//     is ≠ 0 (so flipped normals, nested or duplicated parts are inside too), and adds the exact
//     1-D overlap of those intervals with each voxel (difference array + prefix sum).
//  3. Per voxel and axis the estimate c_a = inside length / valid sub-ray length is exact along the
//     axis and S×S-supersampled across it. The axes vote: when every axis with valid rays (at least
//     two) agrees within `axis_agreement`, the voxel gets their mean weighted by valid sub-rays. A
//     ray that enters and leaves through two holes is consistent yet wrong ("outside" along a whole
//     chord), and along a seam — a lid resting in a body with a gap, a shell split at its equator —
//     rays of two axes slip through the same gap, so a majority would be wrong too: any
//     disagreement, and any voxel with fewer than two valid axes, is decided by the generalized
//     winding number instead (Jacobson et al. 2013, with the hierarchical evaluation of Barill et
//     al. 2018, winding_number.h): inside where |w| > ½, at the voxel centre when that is clearly
//     on one side and no ray crossed the surface inside the voxel, else at 8 and then S³ sub-samples.
//     (`majority_vote` outvotes a lone outlier instead: cheaper on very leaky meshes, wrong on seams.)
//  Why: on a closed mesh every ray is consistent and the result is exact along rays — no winding
//  number is evaluated at all and the cost is that of a scan conversion (linear in voxel count);
//  on leaky meshes only the voxels whose rays pass through holes pay for the (more robust, but
//  ~100× dearer) winding number. Parity counting would break on overlapping parts, a single axis
//  on any hole, and the winding number alone would cost far more than the 2-s budget at 256³.
//  Measured on 2 cores (Xeon, RelWithDebInfo): a closed 70k-triangle torus at 256³ in 0.29 s
//  (0.44 s on one thread), a 4k-triangle sphere at 128³ in 0.04 s; the torus with 0.5 % of its faces
//  removed 0.35 s (2 000 voxels by winding number, volume within 1e-5 of the closed one), with 10 %
//  removed 1.4 s (227 000 voxels, volume within 0.2 %); a sphere split at the equator with a
//  one-voxel gap comes out filled (within 0.01 % of sphere + band).
//
#pragma once

#include "core/grid.h"
#include "core/progress.h"
#include "voxelize/mesh.h"
#include "voxelize/mesh_voxelizer.h"
#include "voxelize/region.h"

namespace eik {

// Coverage of `mesh` as a solid on `grid` (only Region::coverage is set). Adds to stats.rays and
// stats.rays_through_holes, sets stats.winding_voxels and stats.winding_evaluations. `progress`
// receives fractions in [0, 1]. Deterministic whatever the thread count. The mesh's indices and
// positions and the grid must be valid (voxelizeMesh checks them).
Region voxelizeSolid(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                     const ProgressFn& progress, MeshVoxelizeStats& stats);

}  // namespace eik
