#include "voxelize/surface_voxelizer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"

namespace eik {
namespace {

glm::dvec3 closestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  // Ericson, Real-Time Collision Detection §5.1.5.
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = va + vb + vc;
  if (!(denom != 0.0)) return a;  // degenerate
  const double v = vb / denom, w = vc / denom;
  return a + ab * v + ac * w;
}

// Bounding box in x, y of the part of triangle (a, b, c) with z in [z0, z1]; false if none.
bool clippedXYBounds(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, double z0, double z1,
                     glm::dvec2& lo, glm::dvec2& hi) {
  std::array<glm::dvec3, 9> poly{a, b, c}, next{};
  int n = 3;
  auto clip = [&](double plane, double side) {  // keep side·(z − plane) ≥ 0
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const glm::dvec3& p = poly[static_cast<std::size_t>(i)];
      const glm::dvec3& q = poly[static_cast<std::size_t>((i + 1) % n)];
      const double dp = side * (p.z - plane), dq = side * (q.z - plane);
      if (dp >= 0.0) next[static_cast<std::size_t>(m++)] = p;
      if ((dp >= 0.0) != (dq >= 0.0)) next[static_cast<std::size_t>(m++)] = p + (q - p) * (dp / (dp - dq));
    }
    poly = next;
    n = m;
  };
  clip(z0, 1.0);
  if (n > 0) clip(z1, -1.0);
  if (n == 0) return false;
  lo = glm::dvec2(1e300);
  hi = glm::dvec2(-1e300);
  for (int i = 0; i < n; ++i) {
    lo = glm::min(lo, glm::dvec2(poly[static_cast<std::size_t>(i)]));
    hi = glm::max(hi, glm::dvec2(poly[static_cast<std::size_t>(i)]));
  }
  return true;
}

}  // namespace

// A slab of thickness T around the triangles.
void voxelizeSurfaceLayer(const TriangleMesh& mesh, const GridSpec& grid, const MeshVoxelizeOptions& options,
                          const ProgressFn& progress, std::vector<float>& coverage) {
  const glm::dvec3 h3 = grid.voxelSize();
  const double h = (h3.x + h3.y + h3.z) / 3.0;
  const double thickness = std::max(options.surface_thickness_voxels, 0.0) * h;
  const double reach = 0.5 * thickness + 0.5 * h;  // beyond this distance a voxel centre gets nothing
  const int nx = grid.dims.x, ny = grid.dims.y, nz = grid.dims.z;
  // Slab of voxel centres k that a triangle can reach.
  auto slabRange = [&](double zmin, double zmax, int& k0, int& k1) {
    k0 = static_cast<int>(std::ceil((zmin - reach - grid.bounds_min.z) / h3.z - 0.5));
    k1 = static_cast<int>(std::floor((zmax + reach - grid.bounds_min.z) / h3.z - 0.5));
    k0 = std::max(k0, 0);
    k1 = std::min(k1, nz - 1);
  };
  std::vector<std::size_t> start(static_cast<std::size_t>(nz) + 1, 0);
  auto forEachSlab = [&](auto&& body) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::dvec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
      int k0, k1;
      slabRange(std::min({a.z, b.z, c.z}), std::max({a.z, b.z, c.z}), k0, k1);
      for (int k = k0; k <= k1; ++k) body(k, t);
    }
  };
  forEachSlab([&](int k, std::size_t) { ++start[static_cast<std::size_t>(k) + 1]; });
  for (int k = 0; k < nz; ++k) start[static_cast<std::size_t>(k) + 1] += start[static_cast<std::size_t>(k)];
  std::vector<std::uint32_t> slab_triangles(start[static_cast<std::size_t>(nz)]);
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    forEachSlab([&](int k, std::size_t t) { slab_triangles[fill[static_cast<std::size_t>(k)]++] = static_cast<std::uint32_t>(t); });
  }
  std::atomic<int> done{0};
  parallelFor(0, nz, [&](std::int64_t k64) {
    const int k = static_cast<int>(k64);
    const std::size_t begin = start[static_cast<std::size_t>(k)], end = start[static_cast<std::size_t>(k) + 1];
    if (begin != end) {
      const double zc = grid.bounds_min.z + (k + 0.5) * h3.z;
      std::vector<double> nearest(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), reach);
      for (std::size_t n = begin; n < end; ++n) {
        const std::size_t t = slab_triangles[n];
        const glm::dvec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
        glm::dvec2 lo, hi;
        if (!clippedXYBounds(a, b, c, zc - reach, zc + reach, lo, hi)) continue;
        const int i0 = std::max(0, static_cast<int>(std::ceil((lo.x - reach - grid.bounds_min.x) / h3.x - 0.5)));
        const int i1 = std::min(nx - 1, static_cast<int>(std::floor((hi.x + reach - grid.bounds_min.x) / h3.x - 0.5)));
        const int j0 = std::max(0, static_cast<int>(std::ceil((lo.y - reach - grid.bounds_min.y) / h3.y - 0.5)));
        const int j1 = std::min(ny - 1, static_cast<int>(std::floor((hi.y + reach - grid.bounds_min.y) / h3.y - 0.5)));
        for (int j = j0; j <= j1; ++j)
          for (int i = i0; i <= i1; ++i) {
            const glm::dvec3 p = grid.center(i, j, k);
            const double d = glm::length(p - closestPointOnTriangle(p, a, b, c));
            double& best = nearest[static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * j];
            best = std::min(best, d);
          }
      }
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const double d = nearest[static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * j];
          coverage[grid.index(i, j, k)] = static_cast<float>(std::clamp((reach - d) / h, 0.0, 1.0));
        }
    }
    const int finished = ++done;
    if (progress) progress(static_cast<double>(finished) / nz);
  });
}

}  // namespace eik
