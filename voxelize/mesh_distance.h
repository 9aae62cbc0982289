// Narrow-band signed distance of a triangle mesh at the voxel centres, for sharp interfaces
// (core/interfaces.h): the exact distance to the nearest triangle within `band` of the surface,
// clamped to ±band beyond it, negative inside.
//
// The unsigned distance is exact (closest point on each triangle, Ericson, Real-Time Collision
// Detection §5.1.5) over every voxel whose centre lies within `band` of a triangle's bounding box.
// The sign of a solid comes from its coverage where that is decisive (0: outside, 1: inside) and
// from the generalized winding number at the centre (> ½: inside) in the voxels the surface cuts,
// so holes and seams are treated as robustly as by the solid voxeliser. An open surface (a
// receiver layer of thickness T) is the slab around the sheet: d = |distance| − T/2.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "voxelize/mesh.h"

namespace eik {

// Closest point to p on the triangle (a, b, c).
glm::dvec3 closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// The unsigned distance from every voxel centre to the mesh, min(exact distance, band).
// Parallel over z-slices; the result does not depend on the thread count.
std::vector<float> meshUnsignedDistance(const TriangleMesh& mesh, const GridSpec& grid, double band);

// Signed distance of a solid whose anti-aliased `coverage` is known (see above).
std::vector<float> meshSignedDistance(const TriangleMesh& mesh, const GridSpec& grid, double band,
                                      const std::vector<float>& coverage);

// Signed distance of an open surface voxelised as a layer of thickness `thickness`.
std::vector<float> sheetSignedDistance(const TriangleMesh& mesh, const GridSpec& grid, double band, double thickness);

}  // namespace eik
