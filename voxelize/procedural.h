// Procedural objects: `voxelize procedural:NAME[,key=value...]` (docs/programs.md), the scenes of the
// thesis (glass sphere Fig. 5.1/7.4a, layered rounded cube Fig. 1.2/7.3a, wine glass Fig. 3.1/3.3b/
// 7.4b, glass block with an embedded logo Fig. 1.1/7.2a) and analytic test objects (Luneburg lens,
// gradient-index slab, floor receiver).
//
// Shapes are signed-distance functions (distance_functions.h, the table in procedural_shapes.cpp)
// voxelised with exact-by-supersampling occupancy (implicit_voxelizer.h). All shapes are centred at
// the origin (shift them with `center=X:Y:Z`), Y up, about one world unit in size; their keys are
// validated against each shape's schema (shape_params.h).
// `proceduralShapes()` lists every shape with its parameters and defaults (for --help and README).
#pragma once

#include <string>
#include <vector>

#include "core/grid.h"
#include "core/progress.h"
#include "voxelize/grid_builder.h"
#include "voxelize/implicit_voxelizer.h"
#include "voxelize/region.h"
#include "voxelize/shape_params.h"

namespace eik {

// Documentation of a shape's parameter (or of a material key the shape accepts).
struct ProceduralParamInfo {
  std::string key;
  std::string default_value;  // as the user would write it
  std::string meaning;
};

struct ProceduralShapeInfo {
  std::string name;
  std::string description;
  std::vector<ProceduralParamInfo> params;   // the shape's own keys
  std::vector<std::string> material_keys;    // material_spec.h keys it also accepts
  std::vector<std::string> regions;          // names of the regions it produces
};

// Every shape, in documentation order.
const std::vector<ProceduralShapeInfo>& proceduralShapes();

// True when an input argument names a procedural shape ("procedural:...").
bool isProceduralSpec(const std::string& input);

// Parses "procedural:NAME[,key=value...]" (the "procedural:" prefix is optional) and validates it
// fully. Throws InputError "procedural:NAME: KEY: what" for an unknown shape (listing the shapes),
// an unknown key (listing the valid keys), a value that is not a number or out of range.
ProceduralSpec parseProceduralSpec(const std::string& text);

// World-space bounding box of the shape with its parameters (all its regions together).
// Throws InputError like parseProceduralSpec.
Bounds proceduralBounds(const ProceduralSpec& spec);

// Voxelises the shape on `grid`: one Region per material (e.g. "glass" and "wine"), coverage in
// [0, 1] per voxel, `enclosed_volume` = Σ coverage·V_voxel (0 for the floor, an open receiver).
// Parallel over z-slices and deterministic. Throws InputError like parseProceduralSpec, and
// std::invalid_argument for supersample outside [1, 16].
std::vector<Region> voxelizeProcedural(const ProceduralSpec& spec, const GridSpec& grid,
                                       const ProceduralOptions& options = {}, const ProgressFn& progress = {});

// The solids a spec describes (what voxelizeProcedural voxelises on `grid`; the grid only matters
// for sizes given in voxels, such as the floor's default thickness of one voxel).
std::vector<ImplicitSolid> proceduralSolids(const ProceduralSpec& spec, const GridSpec& grid);

}  // namespace eik
