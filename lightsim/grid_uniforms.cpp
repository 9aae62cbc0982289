// The grid's uniforms of the light simulator's passes (see grid_uniforms.h).
#include "lightsim/grid_uniforms.h"

#include <algorithm>

namespace eik::gpu {

GridUniforms GridUniforms::from(const GridSpec& grid) {
  GridUniforms u;
  u.boundsMin = glm::vec3(grid.bounds_min);
  u.boundsMax = glm::vec3(grid.bounds_max);
  u.invExtent = glm::vec3(1.0 / grid.extent());
  const glm::dvec3 h = grid.voxelSize();
  u.voxelEdge = static_cast<float>(std::min({h.x, h.y, h.z}));
  u.voxelVolume = static_cast<float>(grid.voxelVolume());
  u.dims = grid.dims;
  return u;
}

void GridUniforms::set(const gl::Program& program) const {
  program.set("uBoundsMin", boundsMin);
  program.set("uBoundsMax", boundsMax);
  program.set("uInvExtent", invExtent);
  program.set("uVoxelEdge", voxelEdge);
  program.set("uVoxelVolume", voxelVolume);
  program.set("uDims", dims);
}

}  // namespace eik::gpu
