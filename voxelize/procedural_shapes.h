// The table of procedural shapes: the nine shapes of `voxelize procedural:NAME` (procedural.h),
// each with its parameter schema (shape_params.h), the regions it produces and the builder that
// turns validated parameters into signed-distance solids (implicit_voxelizer.h).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "voxelize/implicit_voxelizer.h"
#include "voxelize/shape_params.h"

namespace eik {

// The solids of a shape; `voxel_height` is that of the grid being voxelised (0 when only bounds are
// wanted).
using ShapeBuilder = std::function<std::vector<ImplicitSolid>(const ShapeParams&, double voxel_height)>;

struct ShapeDef {
  std::string name;
  std::string description;
  std::vector<ParamDef> params;
  std::vector<std::string> material_keys;
  std::vector<std::string> regions;
  ShapeBuilder build;
};

// Every shape, in documentation order.
const std::vector<ShapeDef>& shapeDefs();

// The shape called `name`; InputError naming `source` and listing the shapes if there is none.
const ShapeDef& findShape(const std::string& name, const std::string& source);

// The names of all shapes, "sphere, box, ...", for messages.
std::string shapeNames();

// Validates the spec's parameters against its shape and builds its solids. Throws InputError for an
// unknown shape, bad parameters or an inconsistent combination (e.g. radius > size/2).
std::vector<ImplicitSolid> buildShapeSolids(const ProceduralSpec& spec, double voxel_height);

}  // namespace eik
