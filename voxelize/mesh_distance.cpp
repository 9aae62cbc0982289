#include "voxelize/mesh_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"
#include "voxelize/winding_number.h"

namespace eik {

using glm::dvec3;

dvec3 closestPointOnTriangle(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;  // vertex region a
  const dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;  // vertex region b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;  // edge ab
  const dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;  // vertex region c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;  // edge ac
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);  // edge bc
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0.0)) return a;  // degenerate triangle: any corner
  const double v = vb / denom, w = vc / denom;
  return a + v * ab + w * ac;  // face region
}

std::vector<float> meshUnsignedDistance(const TriangleMesh& mesh, const GridSpec& grid, double band) {
  std::vector<float> distance(grid.count(), static_cast<float>(band));
  if (grid.count() == 0 || mesh.triangles.empty()) return distance;
  const dvec3 h = grid.voxelSize();
  // Each triangle's voxel box (its bounds grown by the band), and the triangles of each z-slice,
  // so that slices are filled independently.
  struct VoxelBox {
    glm::ivec3 lo, hi;  // [lo, hi)
  };
  std::vector<VoxelBox> boxes(mesh.triangles.size());
  std::vector<std::vector<std::uint32_t>> by_slice(static_cast<std::size_t>(grid.dims.z));
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const dvec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
    const dvec3 lo = glm::min(a, glm::min(b, c)) - band, hi = glm::max(a, glm::max(b, c)) + band;
    VoxelBox& box = boxes[t];
    for (int axis = 0; axis < 3; ++axis) {
      // Centres min + (i + ½)h inside [lo, hi].
      box.lo[axis] = std::clamp(static_cast<int>(std::ceil((lo[axis] - grid.bounds_min[axis]) / h[axis] - 0.5)), 0,
                                grid.dims[axis]);
      box.hi[axis] = std::clamp(static_cast<int>(std::floor((hi[axis] - grid.bounds_min[axis]) / h[axis] - 0.5)) + 1,
                                0, grid.dims[axis]);
    }
    for (int k = box.lo.z; k < box.hi.z; ++k) by_slice[static_cast<std::size_t>(k)].push_back(static_cast<std::uint32_t>(t));
  }
  parallelFor(0, grid.dims.z, [&](std::int64_t zz) {
    const int k = static_cast<int>(zz);
    for (const std::uint32_t t : by_slice[static_cast<std::size_t>(k)]) {
      const dvec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
      const VoxelBox& box = boxes[t];
      for (int j = box.lo.y; j < box.hi.y; ++j)
        for (int i = box.lo.x; i < box.hi.x; ++i) {
          const dvec3 p = grid.center(i, j, k);
          const float d = static_cast<float>(glm::length(p - closestPointOnTriangle(p, a, b, c)));
          float& slot = distance[grid.index(i, j, k)];
          slot = std::min(slot, d);
        }
    }
  });
  return distance;
}

std::vector<float> meshSignedDistance(const TriangleMesh& mesh, const GridSpec& grid, double band,
                                      const std::vector<float>& coverage) {
  std::vector<float> distance = meshUnsignedDistance(mesh, grid, band);
  const FastWindingNumber winding(mesh);
  parallelFor(0, grid.dims.z, [&](std::int64_t zz) {
    const int k = static_cast<int>(zz);
    for (int j = 0; j < grid.dims.y; ++j)
      for (int i = 0; i < grid.dims.x; ++i) {
        const std::size_t at = grid.index(i, j, k);
        const float cover = coverage[at];
        bool inside = cover >= 1.0f;
        if (cover > 0.0f && cover < 1.0f) inside = winding(grid.center(i, j, k)) > 0.5;
        if (inside) distance[at] = -distance[at];
      }
  });
  return distance;
}

std::vector<float> sheetSignedDistance(const TriangleMesh& mesh, const GridSpec& grid, double band, double thickness) {
  std::vector<float> distance = meshUnsignedDistance(mesh, grid, band + 0.5 * thickness);
  for (float& d : distance) d = std::clamp(d - static_cast<float>(0.5 * thickness), -static_cast<float>(band), static_cast<float>(band));
  return distance;
}

}  // namespace eik
