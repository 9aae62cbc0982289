// GridUniforms: the volume grid as the light simulator's shaders see it (shaders/lightsim/grid.glsl:
// uBoundsMin, uBoundsMax, uInvExtent, uVoxelEdge, uVoxelVolume, uDims), in float. Every full-screen
// pass that samples the volume (update, analysis, compaction) sets them. GpuSimulator builds them
// from the grid in grid-local coordinates (x − the grid's centre), so that float positions keep their
// precision however far the volume sits from the world origin.
// With sharp interfaces (core/interfaces.h) they also carry the slot table of shaders/lightsim/
// sharp.glsl: uSlotCount, uSlotIor[4], uSlotGraded and uSlotOpaque (bit k: slot k), and uSlotSigmaA[4]
// (σa per material, VolumeSampler::absorptionPerMaterial; MATERIAL_ABSORPTION in the shaders).
#pragma once

#include <array>

#include <glm/vec3.hpp>

#include "core/grid.h"
#include "core/interfaces.h"
#include "gl/program.h"

namespace eik::gpu {

struct GridUniforms {
  glm::vec3 boundsMin{0.0f};
  glm::vec3 boundsMax{0.0f};
  glm::vec3 invExtent{1.0f};  // uvw = (x − boundsMin) · invExtent
  float voxelEdge = 1.0f;     // h, the smallest voxel edge
  float voxelVolume = 1.0f;   // V_voxel
  glm::ivec3 dims{1};         // voxels per axis
  int slotCount = 0;          // sharp interfaces: the slot table
  std::array<float, 4> slotIor{1.0f, 1.0f, 1.0f, 1.0f};
  int slotGraded = 0, slotOpaque = 0;
  std::array<glm::vec3, 4> slotSigmaA{};
  static GridUniforms from(const GridSpec& grid, const InterfaceTable& interfaces = {});
  void set(const gl::Program& program) const;
};

}  // namespace eik::gpu
