#include "voxelize/winding_number.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace eik {

namespace {
constexpr double kInv4Pi = 0.07957747154594767;  // 1 / 4π
}

double triangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& q) {
  const glm::dvec3 ra = a - q, rb = b - q, rc = c - q;
  const double la = glm::length(ra), lb = glm::length(rb), lc = glm::length(rc);
  const double numerator = glm::dot(ra, glm::cross(rb, rc));
  const double denominator = la * lb * lc + glm::dot(ra, rb) * lc + glm::dot(ra, rc) * lb + glm::dot(rb, rc) * la;
  return 2.0 * std::atan2(numerator, denominator);
}

double windingNumberBruteForce(const TriangleMesh& mesh, const glm::dvec3& q) {
  double sum = 0.0;
  for (const glm::uvec3& t : mesh.triangles)
    sum += triangleSolidAngle(mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]], q);
  return sum * kInv4Pi;
}

FastWindingNumber::FastWindingNumber(const TriangleMesh& mesh, double beta, int leaf_size)
    : beta_(beta), leaf_size_(std::max(1, leaf_size)) {
  triangles_.reserve(mesh.triangles.size());
  std::vector<glm::dvec3> centroids;
  centroids.reserve(mesh.triangles.size());
  for (const glm::uvec3& t : mesh.triangles) {
    Triangle tri{mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
    triangles_.push_back(tri);
    centroids.push_back((tri.a + tri.b + tri.c) / 3.0);
  }
  if (triangles_.empty()) return;
  nodes_.reserve(2 * triangles_.size() / static_cast<std::size_t>(leaf_size_) + 2);
  build(0, static_cast<std::uint32_t>(triangles_.size()), centroids);
}

std::uint32_t FastWindingNumber::build(std::uint32_t first, std::uint32_t count, std::vector<glm::dvec3>& centroids) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  // Expansion data of this node.
  glm::dvec3 area_normal(0.0), weighted(0.0);
  double area = 0.0;
  glm::dvec3 lo(1e300), hi(-1e300);
  for (std::uint32_t i = first; i < first + count; ++i) {
    const Triangle& t = triangles_[i];
    const glm::dvec3 an = 0.5 * glm::cross(t.b - t.a, t.c - t.a);
    const double a = glm::length(an);
    area_normal += an;
    weighted += a * centroids[i];
    area += a;
    lo = glm::min(lo, centroids[i]);
    hi = glm::max(hi, centroids[i]);
  }
  glm::dvec3 center = area > 0.0 ? weighted / area : 0.5 * (lo + hi);
  double radius = 0.0;
  glm::dmat3 moment(0.0);
  for (std::uint32_t i = first; i < first + count; ++i) {
    const Triangle& t = triangles_[i];
    radius = std::max({radius, glm::length(t.a - center), glm::length(t.b - center), glm::length(t.c - center)});
    const glm::dvec3 an = 0.5 * glm::cross(t.b - t.a, t.c - t.a);
    moment += glm::outerProduct(an, centroids[i] - center);  // column j = an * (c − p̃)_j
  }
  {
    Node& node = nodes_[index];
    node.center = center;
    node.radius = radius;
    node.area_normal = area_normal;
    node.moment = moment;
    node.first = first;
    node.count = count;
  }
  if (count <= static_cast<std::uint32_t>(leaf_size_)) return index;

  // Median split along the longest axis of the centroid bounds.
  const glm::dvec3 extent = hi - lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), first);
  const std::uint32_t half = count / 2;
  std::nth_element(order.begin(), order.begin() + half, order.end(), [&](std::uint32_t x, std::uint32_t y) {
    return centroids[x][axis] < centroids[y][axis] || (centroids[x][axis] == centroids[y][axis] && x < y);
  });
  std::vector<Triangle> tris(count);
  std::vector<glm::dvec3> cents(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    tris[i] = triangles_[order[i]];
    cents[i] = centroids[order[i]];
  }
  std::copy(tris.begin(), tris.end(), triangles_.begin() + first);
  std::copy(cents.begin(), cents.end(), centroids.begin() + first);

  const std::uint32_t left = build(first, half, centroids);
  const std::uint32_t right = build(first + half, count - half, centroids);
  Node& node = nodes_[index];
  node.leaf = false;
  node.left = left;
  node.right = right;
  return index;
}

double FastWindingNumber::operator()(const glm::dvec3& q) const {
  if (nodes_.empty()) return 0.0;
  double omega = 0.0;      // exact solid angles (×1)
  double far_field = 0.0;  // expansion terms (already Ω-equivalent, i.e. ×1)
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    const glm::dvec3 r = node.center - q;
    const double dist2 = glm::dot(r, r);
    if (dist2 > beta_ * beta_ * node.radius * node.radius) {
      const double inv = 1.0 / std::sqrt(dist2);
      const double inv3 = inv * inv * inv;
      const double inv5 = inv3 * inv * inv;
      const glm::dmat3& m = node.moment;
      const double trace = m[0][0] + m[1][1] + m[2][2];
      // rᵀ M r with M_ij = (area normal)_i (c − p̃)_j stored as m[j][i].
      const double rMr = glm::dot(r, m * r);
      far_field += glm::dot(node.area_normal, r) * inv3 + trace * inv3 - 3.0 * rMr * inv5;
      continue;
    }
    if (node.leaf || top + 2 > 128) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        omega += triangleSolidAngle(triangles_[i].a, triangles_[i].b, triangles_[i].c, q);
      continue;
    }
    stack[top++] = node.left;
    stack[top++] = node.right;
  }
  return (omega + far_field) * kInv4Pi;
}

}  // namespace eik
