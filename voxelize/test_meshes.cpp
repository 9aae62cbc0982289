#include "voxelize/test_meshes.h"

#include <cmath>
#include <numbers>

namespace eik {

TriangleMesh makeUvSphere(const glm::dvec3& center, double radius, int slices, int stacks) {
  TriangleMesh mesh;
  mesh.name = "sphere";
  const double pi = std::numbers::pi;
  mesh.positions.push_back(center + glm::dvec3(0.0, 0.0, radius));  // north pole
  for (int s = 1; s < stacks; ++s) {
    const double theta = pi * s / stacks;
    for (int l = 0; l < slices; ++l) {
      const double phi = 2.0 * pi * l / slices;
      mesh.positions.push_back(center + radius * glm::dvec3(std::sin(theta) * std::cos(phi),
                                                            std::sin(theta) * std::sin(phi), std::cos(theta)));
    }
  }
  mesh.positions.push_back(center + glm::dvec3(0.0, 0.0, -radius));  // south pole
  const auto south = static_cast<unsigned>(mesh.positions.size() - 1);
  auto ring = [&](int s, int l) { return static_cast<unsigned>(1 + (s - 1) * slices + (l % slices)); };
  for (int l = 0; l < slices; ++l) mesh.triangles.emplace_back(0u, ring(1, l), ring(1, l + 1));
  for (int s = 1; s + 1 < stacks; ++s)
    for (int l = 0; l < slices; ++l) {
      mesh.triangles.emplace_back(ring(s, l), ring(s + 1, l), ring(s + 1, l + 1));
      mesh.triangles.emplace_back(ring(s, l), ring(s + 1, l + 1), ring(s, l + 1));
    }
  for (int l = 0; l < slices; ++l) mesh.triangles.emplace_back(south, ring(stacks - 1, l + 1), ring(stacks - 1, l));
  return mesh;
}

TriangleMesh makeTorus(const glm::dvec3& center, double major_radius, double minor_radius, int major_segments,
                       int minor_segments) {
  TriangleMesh mesh;
  mesh.name = "torus";
  const double pi = std::numbers::pi;
  for (int i = 0; i < major_segments; ++i) {
    const double u = 2.0 * pi * i / major_segments;
    for (int j = 0; j < minor_segments; ++j) {
      const double v = 2.0 * pi * j / minor_segments;
      const double rho = major_radius + minor_radius * std::cos(v);
      mesh.positions.push_back(center + glm::dvec3(rho * std::cos(u), rho * std::sin(u), minor_radius * std::sin(v)));
    }
  }
  auto at = [&](int i, int j) {
    return static_cast<unsigned>((i % major_segments) * minor_segments + (j % minor_segments));
  };
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j) {
      mesh.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      mesh.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return mesh;
}

TriangleMesh makeBox(const glm::dvec3& lo, const glm::dvec3& hi) {
  TriangleMesh mesh;
  mesh.name = "box";
  for (int i = 0; i < 8; ++i)
    mesh.positions.emplace_back((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
  // Faces as quads (counter-clockwise from outside), split into two triangles each.
  const unsigned quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

TriangleMesh makeRectangle(const glm::dvec3& corner, const glm::dvec3& u, const glm::dvec3& v) {
  TriangleMesh mesh;
  mesh.name = "rectangle";
  mesh.positions = {corner, corner + u, corner + u + v, corner + v};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TriangleMesh punchHoles(const TriangleMesh& mesh, const glm::dvec3& center, const std::vector<glm::dvec3>& directions) {
  std::vector<bool> removed(mesh.triangles.size(), false);
  for (const glm::dvec3& d : directions) {
    std::size_t best = 0;
    double best_dot = -2.0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::dvec3 c = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0 - center;
      const double dot = glm::dot(glm::normalize(c), glm::normalize(d));
      if (dot > best_dot && !removed[t]) {
        best_dot = dot;
        best = t;
      }
    }
    removed[best] = true;
  }
  TriangleMesh out = mesh;
  out.triangles.clear();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (!removed[t]) out.triangles.push_back(mesh.triangles[t]);
  return out;
}

GridSpec cubeGrid(const glm::dvec3& center, double side, int res) {
  GridSpec g;
  g.dims = glm::ivec3(res);
  g.bounds_min = center - glm::dvec3(side / 2);
  g.bounds_max = center + glm::dvec3(side / 2);
  return g;
}

}  // namespace eik
