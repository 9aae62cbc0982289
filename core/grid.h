// A regular, cell-centred voxel grid in world space.
// Voxel (i,j,k) covers [min + (i,j,k)·h, min + (i+1,j+1,k+1)·h]; its sample sits at the centre
// min + (i+0.5, j+0.5, k+0.5)·h. Data arrays are x fastest, then y, then z (docs/volume-format.md).
#pragma once

#include <cstddef>
#include <glm/glm.hpp>

namespace eik {

struct GridSpec {
  glm::ivec3 dims{0};
  glm::dvec3 bounds_min{0.0};
  glm::dvec3 bounds_max{0.0};

  glm::dvec3 extent() const { return bounds_max - bounds_min; }
  glm::dvec3 voxelSize() const { return extent() / glm::dvec3(dims); }
  double voxelVolume() const {
    glm::dvec3 h = voxelSize();
    return h.x * h.y * h.z;
  }
  std::size_t count() const {
    return static_cast<std::size_t>(dims.x) * static_cast<std::size_t>(dims.y) *
           static_cast<std::size_t>(dims.z);
  }
  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims.x) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(k));
  }
  glm::dvec3 center(int i, int j, int k) const {
    return bounds_min + (glm::dvec3(i, j, k) + 0.5) * voxelSize();
  }
  // Continuous voxel coordinate of a world point (voxel centres at integer + 0.5).
  glm::dvec3 toVoxel(const glm::dvec3& world) const { return (world - bounds_min) / voxelSize(); }
  bool operator==(const GridSpec&) const = default;
};

}  // namespace eik
