// Triangle mesh → anti-aliased coverage Region, robust to meshes that are not watertight.
//
// A mesh is voxelised either as a SOLID (solid_voxelizer.h: signed ray-crossing counts along voxel
// columns in all three axes, the generalized winding number as the fallback) or as an OPEN SURFACE
// (surface_voxelizer.h: a thin opaque receiver layer around the triangles, a floor, a table top as
// a single sheet). Auto mode (SurfaceMode::Auto) calls a mesh an open surface when its openness
// |Σ area vectors| / area exceeds `open_surface_openness` (0 for any closed surface, ≈ 0 for a
// solid with holes or seams, whose rims cancel, ≈ 1 for a sheet), or when it encloses almost no
// volume, Σ_c |V_c| < thin_volume_voxels · area · h, with V_c the signed volume of connected
// component c about its own centroid (so an inverted twin cannot cancel a solid, and a floor and
// a ceiling in one mesh still enclose nothing). The boundary-edge fraction is reported but not
// used: a scan with many small holes has a large one, a finely tessellated floor a small one.
#pragma once

#include <cstdint>
#include <string>

#include "core/grid.h"
#include "core/progress.h"
#include "voxelize/mesh.h"
#include "voxelize/region.h"

namespace eik {

enum class SurfaceMode { Auto, Solid, Surface };

struct MeshVoxelizeOptions {
  int supersample = 4;                    // S: S×S sub-rays per column and axis, S³ winding samples (1..16)
  SurfaceMode surface_mode = SurfaceMode::Auto;
  double surface_thickness_voxels = 1.0;  // thickness T of an open surface's receiver layer
  double open_surface_openness = 0.25;    // Auto: openness above this → open surface
  double thin_volume_voxels = 0.05;       // Auto: |V| < this · area · h → open surface
  double axis_agreement = 0.35;           // per-axis voxel estimates closer than this agree
  // false: any disagreement between valid axes sends the voxel to the winding number (robust to
  // seams, where rays of two axes slip through the same gap); true: a lone outlier among three
  // axes is outvoted (cheaper on meshes with many holes, wrong on seams).
  bool majority_vote = false;
  double winding_threshold = 0.5;         // inside where the generalized winding number exceeds this
  double winding_beta = 2.0;              // Barnes–Hut accuracy of the winding number (larger: exacter)
  // > 0: also record Region::distance, the narrow-band signed distance (mesh_distance.h), clamped
  // to ± this many world units, for sharp interfaces.
  double distance_band = 0.0;
};

// What happened, for --stats and the lead's report.
struct MeshVoxelizeStats {
  bool open_surface = false;
  std::string decision;                   // why it was voxelised as a solid or a surface
  MeshTopology topology;
  double area = 0.0;
  double signed_volume = 0.0;
  double openness = 0.0;
  std::uint64_t rays = 0;                 // sub-rays shot (all axes)
  std::uint64_t rays_through_holes = 0;   // sub-rays whose crossings did not sum to 0
  std::uint64_t winding_voxels = 0;       // voxels decided by the generalized winding number
  std::uint64_t winding_evaluations = 0;
  std::uint64_t dropped_triangles = 0;    // zero-area or repeated triangles (withoutEmptyOrRepeatedTriangles)
  double seconds = 0.0;
};

// Whether Auto mode voxelises `mesh` as an open surface on `grid`; `reason` says why (optional).
bool isOpenSurface(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                   std::string* reason = nullptr);

// Coverage of `mesh` on `grid`. Region::name is "mesh:NAME", with " (open surface)" appended when
// voxelised as a receiver layer. Deterministic whatever the thread count.
Region voxelizeMesh(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options = {},
                    ProgressFn progress = {}, MeshVoxelizeStats* stats = nullptr);

}  // namespace eik
