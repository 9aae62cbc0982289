// The voxelize pipeline (thesis §3.1, §6.1; docs/programs.md): from input files and procedural
// specs to the volume the light simulator and viewer read, in five steps — load the inputs, choose
// the grid, voxelise every object into Regions, composite them and pre-smooth n with a Gaussian
// (Eq. 3.2) and take ∇n by central differences (Eq. 3.1), write the volume, its scene and stats.
#pragma once

#include <string>
#include <vector>

#include "core/grid.h"
#include "core/progress.h"
#include "core/volume.h"
#include "voxelize/composite.h"
#include "voxelize/field_filters.h"
#include "voxelize/grid_builder.h"
#include "voxelize/region.h"

namespace eik {

enum class InterfaceMode { Sharp, Smooth };

struct PipelineOptions {
  // Sharp (default): buildSharpVolume (sharp_interfaces.h); every region must carry its distance.
  // Smooth: the thesis' pre-smoothed n, below.
  InterfaceMode interfaces = InterfaceMode::Sharp;
  double band = 0.0;  // Sharp: the distance band in world units (0: kInterfaceBandVoxels voxels)
  double smooth_sigma_voxels = kDefaultSmoothSigmaVoxels;  // σ of the pre-smoothing of n; 0: none
  GradientOperator gradient = GradientOperator::Isotropic;  // how ∇n is differenced (field_filters.h)
  bool all_fields = false;                                 // see CompositeOptions::all_fields
  ProgressFn progress;
};

// Sharp: buildSharpVolume. Smooth: compositeRegions → gaussianSmooth(ior, σ) → ior_grad = gradient(ior) (Eq. 3.1; by default with
// the isotropic cross-average, see field_filters.h).
// Only n (and the Cauchy B of `dispersion`, which is part of n(λ)) is smoothed, as in the thesis:
// σa, emission, scatter and opaque keep their sharp box-filtered boundaries (they enter the image
// linearly, so blocky edges do not bend rays).
// metadata["ior_smoothing_sigma_voxels"] records σ, metadata["ior_gradient"] the operator.
Volume buildVolume(const std::vector<Region>& regions, const GridSpec& grid, const PipelineOptions& options = {});
// The same, releasing the regions' arrays as soon as they are read (sharp: see buildSharpVolume).
Volume buildVolume(std::vector<Region>&& regions, const GridSpec& grid, const PipelineOptions& options = {});

// The default band of the sharp interfaces' distance field: kInterfaceBandVoxels of the largest
// voxel edge, in world units.
double interfaceBand(const GridSpec& grid);

// What `voxelize` is asked to do: its command line (docs/programs.md), flag by flag.
struct VoxelizeOptions {
  std::vector<std::string> inputs;  // mesh files (.gltf, .glb, .obj) and procedural:NAME[,key=value...]
  std::string output;               // the manifest, OUT.vol.json
  int res = 128;                    // voxels along the longest axis of the objects
  std::string bounds;               // explicit world box "MINX,MINY,MINZ,MAXX,MAXY,MAXZ" (empty: from the objects)
  double pad = kDefaultPadVoxels;   // voxels of air around the objects
  std::string interfaces = "sharp";  // sharp, or smooth (the thesis' pre-smoothed n)
  double smooth = kDefaultSmoothSigmaVoxels;  // σ of the pre-smoothing of n, in voxels (smooth mode)
  std::vector<std::string> materials;  // --material specs: one for all OBJ/procedural inputs, or one each
  int supersample = 4;              // sub-samples per voxel and axis
  std::string surface = "auto";     // how meshes are read: auto, solid or surface
  bool raw = false;                 // raw NRRD data instead of gzip
  bool detached = false;            // detached NRRD headers
  bool quiet = false;               // no progress bars and summary lines on stderr
  std::string stats;                // --stats FILE.json (empty: none)
  std::string scene;                // --scene FILE (empty: OUT.scene.json when a glTF input has lights or cameras)
};

// Runs the whole pipeline: validates the options and reads and validates every input before any
// heavy work, then voxelises, builds the fields and writes the volume atomically (and the scene and
// stats when asked for). Progress bars, warnings and a summary go to stderr (warnings also when
// quiet). Throws InputError for bad options or inputs, RuntimeError for failures.
void voxelizeFiles(const VoxelizeOptions& options);

}  // namespace eik
