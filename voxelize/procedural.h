// Procedural objects: `voxelize procedural:NAME[,key=value...]` (DESIGN §4.2), the scenes of the
// thesis (glass sphere Fig. 5.1/7.4a, layered rounded cube Fig. 1.2/7.3a, wine glass Fig. 3.1/3.3b/
// 7.4b, glass block with an embedded logo Fig. 1.1/7.2a) and analytic test objects (Luneburg lens,
// gradient-index slab, floor receiver).
//
// Shapes are signed-distance functions voxelised with exact-by-supersampling occupancy: a voxel
// whose centre lies farther than half its diagonal from the surface is wholly inside or outside
// (the distance functions are 1-Lipschitz, so |sdf| never overestimates the distance); only voxels
// in the boundary band are supersampled with S³ points (see ProceduralOptions). All shapes are centred at the origin
// (shift them with `center=X:Y:Z`), Y up, about one world unit in size.
// `proceduralShapes()` lists every shape with its parameters and defaults (for --help and README).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/progress.h"
#include "voxelize/grid_builder.h"
#include "voxelize/material.h"
#include "voxelize/region.h"

namespace eik {

constexpr const char* kProceduralPrefix = "procedural:";

struct ProceduralSpec {
  std::string name;                           // shape name, e.g. "sphere"
  std::map<std::string, std::string> params;  // key -> value text as given (validated on use)

  // "procedural:NAME[,key=value...]", for messages.
  std::string text() const;
};

struct ProceduralOptions {
  int supersample = 4;  // S: boundary voxels are sampled with S³ points (4 ⇒ 64)
  // Weight each subsample by the fraction of its sub-cell (side Δ = h/S) inside, estimated from the
  // distance, clamp(1/2 − sdf/Δ, 0, 1), instead of counting it 0 or 1. Exact for faces parallel to
  // an axis, and it removes the 1/S³ quantisation noise that otherwise tilts ∇n by ~2° after
  // smoothing (measured on a 128³ sphere). Both estimators converge to the exact occupancy.
  bool antialias = true;
};

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

// A solid given by a signed distance function: negative inside, and 1-Lipschitz (|sdf(p)| is at
// most the distance from p to the surface) — exact SDFs and their min/max/abs combinations are.
struct ImplicitSolid {
  std::string name;
  Material material;
  std::function<double(const glm::dvec3&)> sdf;
  // Optional spatially varying n (e.g. Luneburg lens): the region gets a per-voxel `ior`, the mean
  // over the covered subsamples (the value at the centre for a voxel wholly inside).
  std::function<double(const glm::dvec3&)> ior;
  Bounds bounds;            // encloses every point with sdf < 0
  bool open_surface = false;  // receiver layer: enclosed_volume 0, so it wins over solids around it
};

// Voxelises one solid: coverage of each voxel by the classify-then-supersample scheme above.
// `progress` receives fractions in [0, 1].
Region voxelizeImplicit(const ImplicitSolid& solid, const GridSpec& grid, const ProceduralOptions& options = {},
                        const ProgressFn& progress = {});

// The solids a spec describes (what voxelizeProcedural voxelises on `grid`; the grid only matters
// for sizes given in voxels, such as the floor's default thickness of one voxel).
std::vector<ImplicitSolid> proceduralSolids(const ProceduralSpec& spec, const GridSpec& grid);

}  // namespace eik
