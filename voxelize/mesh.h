// A triangle mesh in world space, as the loaders produce it and the mesh voxeliser consumes it.
//
// Positions are already transformed into world space (node hierarchy applied); triangles index
// into them and are wound counter-clockwise seen from outside (outward normals, the glTF and OBJ
// convention). Nothing here assumes the mesh is closed: scanned meshes with holes and open sheets
// are ordinary inputs, and `topology()` / `openness()` say how far from a closed solid a mesh is.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "voxelize/material.h"

namespace eik {

// Axis-aligned box; empty (min > max) until a point is added.
struct MeshBounds {
  glm::dvec3 min{1e300};
  glm::dvec3 max{-1e300};

  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  void extend(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  glm::dvec3 center() const { return 0.5 * (min + max); }
  glm::dvec3 size() const { return empty() ? glm::dvec3(0.0) : max - min; }
};

// Edge statistics of a mesh after welding vertices with identical positions (exporters split
// vertices along UV seams and hard edges, which must not count as holes).
struct MeshTopology {
  std::size_t vertices = 0;           // distinct positions
  std::size_t edges = 0;              // distinct undirected edges
  std::size_t boundary_edges = 0;     // edges used by exactly one triangle (rims of holes)
  std::size_t nonmanifold_edges = 0;  // edges used by three or more triangles
  std::size_t degenerate_triangles = 0;  // triangles with two equal corners

  bool closed() const { return boundary_edges == 0 && nonmanifold_edges == 0; }
  double boundaryFraction() const {
    return edges == 0 ? 0.0 : static_cast<double>(boundary_edges) / static_cast<double>(edges);
  }
};

struct TriangleMesh;
// The mesh without its triangles that add nothing to a voxelisation: those with two equal corner
// positions (no area, no solid angle, no ray crossing) and repeats of an earlier triangle (the same
// three corner positions in the same cyclic order: they would only count the same face twice).
// Positions are kept. A hostile file that repeats one face 10⁵ times (a 600 KB OBJ fan) would
// otherwise cost 10⁵ times the work of one face. `dropped` receives how many were removed.
TriangleMesh withoutEmptyOrRepeatedTriangles(const TriangleMesh& mesh, std::size_t* dropped = nullptr);

struct TriangleMesh {
  std::string name;
  Material material;
  std::vector<glm::dvec3> positions;  // world space
  std::vector<glm::uvec3> triangles;  // indices into positions, counter-clockwise from outside

  bool empty() const { return triangles.empty(); }
  std::size_t triangleCount() const { return triangles.size(); }
  glm::dvec3 corner(std::size_t triangle, int c) const { return positions[triangles[triangle][c]]; }

  MeshBounds bounds() const;  // of the vertices that triangles use
  double area() const;
  // Σ over triangles of the area vector ½(b−a)×(c−a). Zero for a closed mesh; for an open one it is
  // the vector area spanned by its boundary loops (Stokes).
  glm::dvec3 vectorArea() const;
  // |vectorArea| / area, in [0, 1]: 0 for a closed surface, ≈ 0 for a solid with a few small holes,
  // ≈ 1 for a flat sheet. Scale-invariant measure of "how open" a surface is.
  double openness() const;
  // Area-weighted centroid of the surface (the reference point for signedVolume).
  glm::dvec3 areaCentroid() const;
  // Signed enclosed volume by the divergence theorem, Σ (a−o)·((b−o)×(c−o))/6, taken about the
  // area centroid o (which makes the value meaningful, and small, for open sheets). Positive for
  // outward-facing triangles, negative for a mesh whose normals all point inwards.
  double signedVolume() const;
  MeshTopology topology() const;
  // Connected components (triangles sharing a vertex position): one id per triangle, ids 0..count−1
  // in order of first appearance.
  std::vector<std::uint32_t> triangleComponents(std::uint32_t* count = nullptr) const;
  std::size_t boundaryEdgeCount() const { return topology().boundary_edges; }
  bool isClosed() const { return topology().closed(); }

  // Applies an affine transform to the positions; a transform that mirrors (det < 0) also reverses
  // the winding of every triangle so normals keep pointing outwards (glTF §3.7.4).
  void transform(const glm::dmat4& matrix);
  // Appends another mesh's triangles (material and name of `this` are kept).
  void append(const TriangleMesh& other);
  // Reverses every triangle's winding (flips the normals).
  void flipWinding();
};

}  // namespace eik
