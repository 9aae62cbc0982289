// Track-length deposits with a trilinear (cloud-in-cell) kernel: ALGORITHM.md step 4.
//
// A patch-step deposits its flux times the path length it travels, divided by the voxel volume,
// spread over the voxels its footprint covers. Each voxel v collects ∫ K_v(x) ds along the paths,
// where K_v is the trilinear hat of voxel v (1 at its centre, 0 at its neighbours' centres). The
// hats sum to 1 everywhere, so no flux is lost or gained, and a uniform beam deposits its exact
// irradiance in every voxel however the patches and steps fall on the grid:
//  - along a path the integral is exact: the path is cut where it crosses a plane through voxel
//    centres (where the hats have kinks), and on each piece the weights are cubic polynomials of
//    the arc length, which 2-point Gauss–Legendre integrates exactly;
//  - across the patch, sub-paths on a lattice of at most half a voxel (trackLattice) sample the
//    footprint; with the hat's spectrum (sinc² per axis) the lattice leaves < 0.5 % ripple in a
//    plane wave at any angle (measured: 0.45 % at worst, 45°, 32³; 0 along the axes).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include <glm/glm.hpp>

namespace eik {

// The 8 voxels of the trilinear hats that are non-zero at `p` (continuous voxel coordinates,
// voxel centres at integer + ½) and their weights (summing to 1). Voxels outside [0, dims) are
// reported with index −1 and must be skipped by the caller (their share belongs to no voxel).
struct HatWeights {
  std::array<long long, 8> index;
  std::array<double, 8> weight;
};

inline HatWeights hatWeights(const glm::dvec3& p, const glm::ivec3& dims) {
  const glm::dvec3 f = p - 0.5;
  const glm::dvec3 base = glm::floor(f);
  const glm::dvec3 t = f - base;
  const glm::ivec3 i0(base);
  HatWeights hw;
  for (int k = 0; k < 8; ++k) {
    const glm::ivec3 o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    const glm::ivec3 v = i0 + o;
    const double w = (o.x ? t.x : 1.0 - t.x) * (o.y ? t.y : 1.0 - t.y) * (o.z ? t.z : 1.0 - t.z);
    const bool inside = v.x >= 0 && v.y >= 0 && v.z >= 0 && v.x < dims.x && v.y < dims.y && v.z < dims.z;
    hw.index[static_cast<std::size_t>(k)] =
        inside ? static_cast<long long>(v.x) + static_cast<long long>(dims.x) *
                                                   (static_cast<long long>(v.y) + static_cast<long long>(dims.y) * v.z)
               : -1;
    hw.weight[static_cast<std::size_t>(k)] = w;
  }
  return hw;
}

namespace detail {
// forEachTrackWeight on a segment that crosses at most kMaxBreaks planes through voxel centres;
// every weight is multiplied by `scale`.
template <typename Visit>
void trackWeightsShort(const glm::dvec3& a, const glm::dvec3& b, const glm::ivec3& dims, double scale, Visit&& visit) {
  // Parameters in (0, 1) where the segment crosses a plane through voxel centres: at most
  // 3 + Σ|b − a| of them.
  constexpr int kMaxBreaks = 64;
  std::array<double, kMaxBreaks + 2> breaks;
  int count = 0;
  breaks[count++] = 0.0;
  const glm::dvec3 delta = b - a;
  for (int axis = 0; axis < 3; ++axis) {
    if (delta[axis] == 0.0) continue;
    const double s0 = a[axis] - 0.5, s1 = b[axis] - 0.5;
    const double lo = std::min(s0, s1), hi = std::max(s0, s1);
    for (double k = std::floor(lo) + 1.0; k < hi && count <= kMaxBreaks; k += 1.0)
      breaks[static_cast<std::size_t>(count++)] = (k - s0) / (s1 - s0);
  }
  breaks[static_cast<std::size_t>(count++)] = 1.0;
  // Insertion sort: a step crosses few planes.
  for (int i = 2; i < count - 1; ++i) {
    const double v = breaks[static_cast<std::size_t>(i)];
    int j = i - 1;
    while (j >= 1 && breaks[static_cast<std::size_t>(j)] > v) {
      breaks[static_cast<std::size_t>(j + 1)] = breaks[static_cast<std::size_t>(j)];
      --j;
    }
    breaks[static_cast<std::size_t>(j + 1)] = v;
  }
  constexpr double kGauss = 0.28867513459481288225;  // 1/(2√3): the 2-point nodes at ½ ± this
  for (int piece = 0; piece + 1 < count; ++piece) {
    const double t0 = breaks[static_cast<std::size_t>(piece)], t1 = breaks[static_cast<std::size_t>(piece + 1)];
    const double length = t1 - t0;
    if (!(length > 0.0)) continue;
    // A piece lies in one cell of the voxel-centre lattice, so both nodes share its eight hats:
    // their weights are summed first and each hat visited once.
    const glm::dvec3 base = glm::floor(a + (t0 + 0.5 * length) * delta - 0.5);
    std::array<double, 8> weight{};
    for (const double node : {0.5 - kGauss, 0.5 + kGauss}) {
      const glm::dvec3 t = glm::clamp(a + (t0 + node * length) * delta - 0.5 - base, 0.0, 1.0);
      for (int k = 0; k < 8; ++k)
        weight[static_cast<std::size_t>(k)] += ((k & 1) ? t.x : 1.0 - t.x) * ((k & 2) ? t.y : 1.0 - t.y) * ((k & 4) ? t.z : 1.0 - t.z);
    }
    const glm::ivec3 i0(base);
    for (int k = 0; k < 8; ++k) {
      const glm::ivec3 v = i0 + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
      const double w = weight[static_cast<std::size_t>(k)];
      if (w == 0.0 || v.x < 0 || v.y < 0 || v.z < 0 || v.x >= dims.x || v.y >= dims.y || v.z >= dims.z) continue;
      visit(static_cast<long long>(v.x) + static_cast<long long>(dims.x) * (static_cast<long long>(v.y) + static_cast<long long>(dims.y) * v.z),
            scale * (0.5 * length * w));
    }
  }
}
}  // namespace detail

// Calls visit(voxel_index, weight) for the hats along the segment a → b (continuous voxel
// coordinates): the weights are ∫ K_v ds / |b − a|, exactly, and sum to 1 over all voxels (those
// outside the grid are not visited). A voxel may be visited more than once. Only the part within
// the hats' reach is integrated, and a long one (a free flight) in equal pieces of at most 48
// voxels of Σ|b − a| each (exact too: each piece is integrated exactly).
template <typename Visit>
void forEachTrackWeight(const glm::dvec3& a, const glm::dvec3& b, const glm::ivec3& dims, Visit&& visit) {
  // The part of the segment within the hats' reach, (−½, dims + ½) along every axis: the rest
  // visits nothing. A segment that leaves it (a flight out of the grid) is cut, its weights scaled
  // by the share of the length kept.
  const glm::dvec3 delta = b - a;
  double f0 = 0.0, f1 = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = -0.5, hi = dims[axis] + 0.5;
    if (std::max(a[axis], b[axis]) <= lo || std::min(a[axis], b[axis]) >= hi) return;
    if (a[axis] >= lo && a[axis] <= hi && b[axis] >= lo && b[axis] <= hi) continue;
    const double g0 = (lo - a[axis]) / delta[axis], g1 = (hi - a[axis]) / delta[axis];
    f0 = std::max(f0, std::min(g0, g1));
    f1 = std::min(f1, std::max(g0, g1));
  }
  if (!(f1 > f0)) return;
  const glm::dvec3 from = f0 > 0.0 ? a + f0 * delta : a, to = f1 < 1.0 ? a + f1 * delta : b;
  const double kept = f1 - f0;
  const glm::dvec3 span = to - from;
  const double l1 = std::fabs(span.x) + std::fabs(span.y) + std::fabs(span.z);
  constexpr double kPiece = 48.0;
  if (!(l1 > kPiece)) {
    detail::trackWeightsShort(from, to, dims, kept, visit);
    return;
  }
  const int pieces = static_cast<int>(std::ceil(l1 / kPiece));
  for (int i = 0; i < pieces; ++i)
    detail::trackWeightsShort(from + (static_cast<double>(i) / pieces) * span,
                              from + (static_cast<double>(i + 1) / pieces) * span, dims, kept / pieces, visit);
}

// Sub-paths across a patch along one of its parameter directions: n = ceil(edge / ½ voxel) of them
// (at least 1, at most kMaxTrackLattice), at the centres of n equal parameter intervals, so that
// neighbouring sub-paths are at most half a voxel apart. `edge_voxels` is the longer of the two
// patch edges along that direction, in voxels.
constexpr int kMaxTrackLattice = 16;
inline int trackLattice(double edge_voxels) {
  if (!(edge_voxels > 0.5)) return 1;
  return std::min(kMaxTrackLattice, static_cast<int>(std::ceil(edge_voxels / 0.5 - 1e-9)));
}

}  // namespace eik
