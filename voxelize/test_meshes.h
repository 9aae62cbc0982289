// Closed and open reference meshes with known volumes and areas, for tests and benchmarks:
// UV sphere, torus, box, rectangle (all wound counter-clockwise seen from outside), leaky copies of
// them, and the cubic grids the tests voxelise on.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "voxelize/mesh.h"

namespace eik {

// Sphere of `radius` around `center`: `slices` meridians, `stacks` parallels (single pole vertices);
// 2·slices·(stacks − 1) triangles, vertices on the sphere (the polyhedron is inscribed).
TriangleMesh makeUvSphere(const glm::dvec3& center, double radius, int slices, int stacks);

// Torus around the z axis through `center`: tube centre-line radius R, tube radius r,
// 2·major·minor triangles, vertices on the torus.
TriangleMesh makeTorus(const glm::dvec3& center, double major_radius, double minor_radius, int major_segments,
                       int minor_segments);

// Axis-aligned box, 12 triangles.
TriangleMesh makeBox(const glm::dvec3& min, const glm::dvec3& max);

// Flat rectangle corner, corner + u, corner + u + v, corner + v (normal u × v), 2 triangles.
TriangleMesh makeRectangle(const glm::dvec3& corner, const glm::dvec3& u, const glm::dvec3& v);

// `mesh` without the triangle whose centroid direction (from `center`) is closest to each of
// `directions`: one hole per direction.
TriangleMesh punchHoles(const TriangleMesh& mesh, const glm::dvec3& center, const std::vector<glm::dvec3>& directions);

// res³ cubic voxels on the cube of side `side` around `center`.
GridSpec cubeGrid(const glm::dvec3& center, double side, int res);

}  // namespace eik
