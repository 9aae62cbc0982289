// The grid's uniforms of the light simulator's passes (see grid_uniforms.h).
#include "lightsim/grid_uniforms.h"

#include <algorithm>

namespace eik::gpu {

GridUniforms GridUniforms::from(const GridSpec& grid, const InterfaceTable& interfaces) {
  GridUniforms u;
  u.boundsMin = glm::vec3(grid.bounds_min);
  u.boundsMax = glm::vec3(grid.bounds_max);
  u.invExtent = glm::vec3(1.0 / grid.extent());
  const glm::dvec3 h = grid.voxelSize();
  u.voxelEdge = static_cast<float>(std::min({h.x, h.y, h.z}));
  u.voxelVolume = static_cast<float>(grid.voxelVolume());
  u.dims = grid.dims;
  u.slotCount = static_cast<int>(std::min<std::size_t>(interfaces.slots.size(), kMaxInterfaceSlots));
  for (int k = 0; k < u.slotCount; ++k) {
    const InterfaceSlot& slot = interfaces.slots[static_cast<std::size_t>(k)];
    u.slotIor[static_cast<std::size_t>(k)] = static_cast<float>(slot.ior);
    if (slot.graded) u.slotGraded |= 1 << k;
    if (slot.opaque) u.slotOpaque |= 1 << k;
  }
  return u;
}

void GridUniforms::set(const gl::Program& program) const {
  program.set("uBoundsMin", boundsMin);
  program.set("uBoundsMax", boundsMax);
  program.set("uInvExtent", invExtent);
  program.set("uVoxelEdge", voxelEdge);
  program.set("uVoxelVolume", voxelVolume);
  program.set("uDims", dims);
  if (slotCount > 0) {
    program.set("uSlotCount", slotCount);
    program.set("uSlotIor", std::span<const float>(slotIor));
    program.set("uSlotGraded", slotGraded);
    program.set("uSlotOpaque", slotOpaque);
    program.set("uSlotSigmaA", std::span<const glm::vec3>(slotSigmaA));
  }
}

}  // namespace eik::gpu
