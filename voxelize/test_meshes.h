// Closed and open reference meshes with known volumes and areas, for tests and benchmarks:
// UV sphere, torus, box, rectangle. All wound counter-clockwise seen from outside.
#pragma once

#include <glm/glm.hpp>

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

}  // namespace eik
