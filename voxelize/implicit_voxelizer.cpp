#include "voxelize/implicit_voxelizer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <vector>

#include "core/parallel.h"

namespace eik {

using glm::dvec3;

namespace {

// Region::distance (and ior_at_center) at every voxel centre within `band` of the solid's bounds:
// the distance function clamped to ±band, which is exact near the surface (the band is what the
// programs interpolate across an interface) and only a bound farther out.
// The distances start as +band everywhere and n at the centres as the material's (voxelizeImplicit
// fills them beside the coverage).
void recordDistance(const ImplicitSolid& solid, const GridSpec& grid, double band, Region& region) {
  const bool graded = static_cast<bool>(solid.ior);
  if (grid.count() == 0 || solid.bounds.empty()) return;
  const dvec3 h = grid.voxelSize();
  glm::ivec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp(static_cast<int>(std::floor((solid.bounds.min[a] - band - grid.bounds_min[a]) / h[a])) - 1, 0,
                       grid.dims[a]);
    hi[a] = std::clamp(static_cast<int>(std::ceil((solid.bounds.max[a] + band - grid.bounds_min[a]) / h[a])) + 1, 0,
                       grid.dims[a]);
  }
  parallelFor(lo.z, hi.z, [&](std::int64_t zz) {
    const int k = static_cast<int>(zz);
    for (int j = lo.y; j < hi.y; ++j)
      for (int i = lo.x; i < hi.x; ++i) {
        const dvec3 c = grid.center(i, j, k);
        const double d = solid.sdf(c);
        const std::size_t at = grid.index(i, j, k);
        region.distance[at] = static_cast<float>(std::clamp(d, -band, band));
        if (graded && d < band) region.ior_at_center[at] = static_cast<float>(std::max(1.0, solid.ior(c)));
        // The next voxels along x whose distance the 1-Lipschitz bound clamps as this one's: at
        // least |d| − m·h.x ≥ band away on the same side (outside: the default already there;
        // inside: −band, unless a graded solid needs its n at each centre).
        const double beyond = (std::fabs(d) - band) / h.x;
        if (beyond >= 1.0 && (d > 0.0 || !graded)) {
          const int run = std::min(static_cast<int>(beyond), hi.x - 1 - i);
          if (d < 0.0) std::fill_n(&region.distance[at + 1], run, static_cast<float>(-band));
          i += run;
        }
      }
  });
}

}  // namespace

Region voxelizeImplicit(const ImplicitSolid& solid, const GridSpec& grid, const ProceduralOptions& options,
                        const ProgressFn& progress) {
  const int supersample = options.supersample;
  if (supersample < 1 || supersample > 16)
    throw std::invalid_argument("voxelizeImplicit: supersample must lie in [1, 16], got " + std::to_string(supersample));
  if (!solid.sdf) throw std::invalid_argument("voxelizeImplicit: solid '" + solid.name + "' has no distance function");
  Region region;
  region.name = solid.name;
  region.material = solid.material;
  // The arrays' first values, each filled on a thread of its own: filling one is mostly the kernel
  // zeroing its fresh pages (9 MB each at 132³), which one thread did for all of them in turn.
  const bool distances = options.distance_band > 0.0;
  const std::vector<std::function<void()>> fills = {
      [&] { region.coverage.assign(grid.count(), 0.0f); },
      [&] { if (solid.ior) region.ior.assign(grid.count(), solid.material.ior); },
      [&] { if (distances) region.distance.assign(grid.count(), static_cast<float>(options.distance_band)); },
      [&] { if (distances && solid.ior) region.ior_at_center.assign(grid.count(), solid.material.ior); }};
  parallelFor(0, static_cast<std::int64_t>(fills.size()), [&](std::int64_t k) { fills[static_cast<std::size_t>(k)](); });
  if (grid.count() == 0 || solid.bounds.empty()) {
    if (progress) progress(1.0);
    return region;
  }

  const dvec3 h = grid.voxelSize();
  const double half_diagonal = 0.5 * glm::length(h);
  // Voxels that can touch the solid's bounds (one voxel of margin against rounding).
  glm::ivec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::clamp(static_cast<int>(std::floor((solid.bounds.min[a] - grid.bounds_min[a]) / h[a])) - 1, 0, grid.dims[a]);
    hi[a] = std::clamp(static_cast<int>(std::ceil((solid.bounds.max[a] - grid.bounds_min[a]) / h[a])) + 1, 0, grid.dims[a]);
  }
  const int S = supersample;
  std::vector<double> offset_x(S), offset_y(S), offset_z(S);
  for (int s = 0; s < S; ++s) {
    const double t = (s + 0.5) / S - 0.5;
    offset_x[s] = t * h.x;
    offset_y[s] = t * h.y;
    offset_z[s] = t * h.z;
  }
  const float inv_samples = 1.0f / static_cast<float>(S * S * S);
  const bool antialias = options.antialias;
  const double sub_width = std::min(h.x, std::min(h.y, h.z)) / S;
  // With an even S ≥ 4 the S³ sub-samples fall into eight octants of (S/2)³. Where the distance at
  // an octant's centre exceeds the farthest of its sub-samples from it (octant_radius) by what the
  // weight needs (half a sub-sample's width with antialiasing, 0 without) and a hair for rounding,
  // every sub-sample of the octant has weight 0 (outside) or 1 (inside), as the distance is
  // 1-Lipschitz (the bound the whole-voxel skips below rely on too): their distances are not
  // evaluated, and the sums are those of evaluating them.
  const int half = S / 2;
  std::vector<int> octant_of(static_cast<std::size_t>(S));  // a sub-sample's octant along an axis: 0 or 1
  for (int s = 0; s < S; ++s) octant_of[static_cast<std::size_t>(s)] = s < half ? 0 : 1;
  double octant_radius = -1.0, octant_margin = 0.0;
  dvec3 octant_centre[8];
  if (S >= 4 && S % 2 == 0) {
    const dvec3 spread = (0.5 * (half - 1)) * h / static_cast<double>(S);  // centre to farthest sub-sample, per axis
    octant_radius = glm::length(spread);
    octant_margin = octant_radius + (antialias ? 0.5 * sub_width : 0.0) + 1e-9 * glm::length(h);
    for (int o = 0; o < 8; ++o) {
      const int ox = o & 1, oy = (o >> 1) & 1, oz = (o >> 2) & 1;
      octant_centre[o] = dvec3(0.5 * (offset_x[ox * half] + offset_x[ox * half + half - 1]),
                               0.5 * (offset_y[oy * half] + offset_y[oy * half + half - 1]),
                               0.5 * (offset_z[oz * half] + offset_z[oz * half + half - 1]));
    }
  }
  const auto& sdf = solid.sdf;
  const auto& ior = solid.ior;
  std::atomic<std::int64_t> slices_done{0};
  const double slices = std::max(1, hi.z - lo.z);

  parallelFor(lo.z, hi.z, [&](std::int64_t zz) {
    const int k = static_cast<int>(zz);
    for (int j = lo.y; j < hi.y; ++j) {
      for (int i = lo.x; i < hi.x; ++i) {
        const dvec3 c = grid.center(i, j, k);
        const double d = sdf(c);
        if (d >= half_diagonal) {
          // Wholly outside; by the Lipschitz bound so are the next voxels along x while
          // d − m·h.x ≥ half_diagonal.
          i += static_cast<int>(std::min((d - half_diagonal) / h.x, static_cast<double>(hi.x)));
          continue;
        }
        const std::size_t at = grid.index(i, j, k);
        if (d <= -half_diagonal) {
          // Wholly inside, and so are the next voxels along x while −d − m·h.x ≥ half_diagonal.
          const int run = std::min(static_cast<int>((-d - half_diagonal) / h.x), hi.x - 1 - i);
          for (int m = 0; m <= run; ++m) {
            region.coverage[at + static_cast<std::size_t>(m)] = 1.0f;
            if (ior) region.ior[at + static_cast<std::size_t>(m)] = static_cast<float>(ior(grid.center(i + m, j, k)));
          }
          i += run;
          continue;
        }
        // Octants of sub-samples whose weights the distance at their centre settles (all 0 or all 1),
        // then every sub-sample in the same order as ever, the settled ones without a distance.
        double settled[8];
        if (octant_radius >= 0.0)
          for (int o = 0; o < 8; ++o) {
            const double d_octant = sdf(c + octant_centre[o]);
            settled[o] = d_octant >= octant_margin ? 0.0 : d_octant <= -octant_margin ? 1.0 : -1.0;
          }
        double inside = 0.0;
        double n_sum = 0.0;
        for (int sz = 0; sz < S; ++sz)
          for (int sy = 0; sy < S; ++sy)
            for (int sx = 0; sx < S; ++sx) {
              double weight = octant_radius >= 0.0 ? settled[octant_of[sx] | octant_of[sy] << 1 | octant_of[sz] << 2] : -1.0;
              if (weight == 0.0) continue;
              const dvec3 p = c + dvec3(offset_x[sx], offset_y[sy], offset_z[sz]);
              if (weight < 0.0) {
                const double ds = sdf(p);
                weight = antialias ? std::clamp(0.5 - ds / sub_width, 0.0, 1.0) : (ds < 0.0 ? 1.0 : 0.0);
              }
              if (weight > 0.0) {
                inside += weight;
                if (ior) n_sum += weight * ior(p);
              }
            }
        region.coverage[at] = static_cast<float>(inside) * inv_samples;
        if (ior && inside > 0.0) region.ior[at] = static_cast<float>(n_sum / inside);
      }
    }
    if (progress) progress(static_cast<double>(++slices_done) / slices);
  });

  if (options.distance_band > 0.0) recordDistance(solid, grid, options.distance_band, region);

  if (!solid.open_surface) {
    double sum = 0.0;  // serial, so the result does not depend on the thread count
    for (float c : region.coverage) sum += c;
    region.enclosed_volume = sum * grid.voxelVolume();
  }
  return region;
}

}  // namespace eik
