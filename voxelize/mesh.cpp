#include "voxelize/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

namespace eik {

MeshBounds TriangleMesh::bounds() const {
  MeshBounds b;
  for (const glm::uvec3& t : triangles)
    for (int c = 0; c < 3; ++c) b.extend(positions[t[c]]);
  return b;
}

double TriangleMesh::area() const {
  double sum = 0.0;
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 &a = positions[t[0]], &b = positions[t[1]], &c = positions[t[2]];
    sum += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return sum;
}

glm::dvec3 TriangleMesh::vectorArea() const {
  glm::dvec3 sum(0.0);
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 &a = positions[t[0]], &b = positions[t[1]], &c = positions[t[2]];
    sum += 0.5 * glm::cross(b - a, c - a);
  }
  return sum;
}

double TriangleMesh::openness() const {
  const double total = area();
  return total > 0.0 ? std::min(1.0, glm::length(vectorArea()) / total) : 0.0;
}

glm::dvec3 TriangleMesh::areaCentroid() const {
  glm::dvec3 weighted(0.0);
  double total = 0.0;
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 &a = positions[t[0]], &b = positions[t[1]], &c = positions[t[2]];
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
    weighted += area * (a + b + c) / 3.0;
    total += area;
  }
  if (total > 0.0) return weighted / total;
  return bounds().empty() ? glm::dvec3(0.0) : bounds().center();
}

double TriangleMesh::signedVolume() const {
  const glm::dvec3 o = areaCentroid();
  double sum = 0.0;
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 a = positions[t[0]] - o, b = positions[t[1]] - o, c = positions[t[2]] - o;
    sum += glm::dot(a, glm::cross(b, c));
  }
  return sum / 6.0;
}

namespace {

// Welding: one id per distinct position (lexicographic sort, exact comparison). Returns the count.
std::uint32_t weldPositions(const std::vector<glm::dvec3>& positions, std::vector<std::uint32_t>& weld) {
  std::vector<std::uint32_t> order(positions.size());
  std::iota(order.begin(), order.end(), 0u);
  auto less = [&](std::uint32_t a, std::uint32_t b) {
    const glm::dvec3 &p = positions[a], &q = positions[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    return p.z < q.z;
  };
  std::sort(order.begin(), order.end(), less);
  weld.assign(positions.size(), 0);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (i > 0 && positions[order[i]] != positions[order[i - 1]]) ++next;
    weld[order[i]] = next;
  }
  return positions.empty() ? 0 : next + 1;
}

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

}  // namespace

MeshTopology TriangleMesh::topology() const {
  MeshTopology topo;
  std::vector<std::uint32_t> weld;
  topo.vertices = weldPositions(positions, weld);

  std::vector<std::uint64_t> edges;
  edges.reserve(triangles.size() * 3);
  for (const glm::uvec3& t : triangles) {
    const std::uint32_t v[3] = {weld[t[0]], weld[t[1]], weld[t[2]]};
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
      ++topo.degenerate_triangles;
      continue;
    }
    for (int e = 0; e < 3; ++e) {
      std::uint32_t a = v[e], b = v[(e + 1) % 3];
      if (a > b) std::swap(a, b);
      edges.push_back((static_cast<std::uint64_t>(a) << 32) | b);
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    ++topo.edges;
    if (j - i == 1) ++topo.boundary_edges;
    if (j - i >= 3) ++topo.nonmanifold_edges;
    i = j;
  }
  return topo;
}

std::vector<std::uint32_t> TriangleMesh::triangleComponents(std::uint32_t* count) const {
  std::vector<std::uint32_t> weld;
  const std::uint32_t vertices = weldPositions(positions, weld);
  std::vector<std::uint32_t> parent(vertices);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const glm::uvec3& t : triangles) {
    const std::uint32_t a = findRoot(parent, weld[t[0]]);
    for (int c = 1; c < 3; ++c) {
      const std::uint32_t b = findRoot(parent, weld[t[c]]);
      if (b != a) parent[b] = a;
    }
  }
  std::vector<std::uint32_t> ids(triangles.size());
  std::vector<std::uint32_t> label(vertices, UINT32_MAX);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    std::uint32_t& l = label[findRoot(parent, weld[triangles[i][0]])];
    if (l == UINT32_MAX) l = next++;
    ids[i] = l;
  }
  if (count) *count = next;
  return ids;
}

void TriangleMesh::transform(const glm::dmat4& matrix) {
  for (glm::dvec3& p : positions) p = glm::dvec3(matrix * glm::dvec4(p, 1.0));
  if (glm::determinant(glm::dmat3(matrix)) < 0.0) flipWinding();
}

void TriangleMesh::append(const TriangleMesh& other) {
  const auto offset = static_cast<std::uint32_t>(positions.size());
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  triangles.reserve(triangles.size() + other.triangles.size());
  for (const glm::uvec3& t : other.triangles) triangles.push_back(t + glm::uvec3(offset));
}

void TriangleMesh::flipWinding() {
  for (glm::uvec3& t : triangles) std::swap(t[1], t[2]);
}

TriangleMesh withoutEmptyOrRepeatedTriangles(const TriangleMesh& mesh, std::size_t* dropped) {
  using Key = std::array<double, 9>;
  // Each triangle's corners, rotated so the smallest position comes first (the cyclic order, and
  // with it the orientation, kept); empty triangles have no key.
  std::vector<std::pair<Key, std::uint32_t>> keys;
  keys.reserve(mesh.triangles.size());
  auto less = [](const glm::dvec3& a, const glm::dvec3& b) {
    return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
  };
  std::vector<char> keep(mesh.triangles.size(), 0);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::dvec3 c[3] = {mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)};
    if (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) continue;
    const int first = less(c[1], c[0]) ? (less(c[2], c[1]) ? 2 : 1) : (less(c[2], c[0]) ? 2 : 0);
    Key key;
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) key[static_cast<std::size_t>(3 * i + a)] = c[(first + i) % 3][a];
    keys.emplace_back(key, static_cast<std::uint32_t>(t));
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (i == 0 || keys[i].first != keys[i - 1].first) keep[keys[i].second] = 1;  // the first of equal keys
  TriangleMesh out;
  out.name = mesh.name;
  out.material = mesh.material;
  out.positions = mesh.positions;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (keep[t]) out.triangles.push_back(mesh.triangles[t]);
  if (dropped) *dropped = mesh.triangles.size() - out.triangles.size();
  return out;
}

}  // namespace eik
