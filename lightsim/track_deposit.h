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
//    footprint; with the hat's spectrum (sinc² per axis) the lattice leaves ~0.5 % ripple in a
//    plane wave at any angle (0 along the axes); dim light takes a lattice of one voxel, whose
//    larger ripple is as small against the brightest light (trackSpacing).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
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

// One cell of the voxel-centre lattice that a segment crosses: the voxel at its low corner
// (`origin`, its linear index, and `cell`, its coordinates; either may lie outside the grid, by one)
// and the integrals of the eight hats there (`weight[k]` for the voxel origin + (k&1, k>>1&1, k>>2&1)).
// `interior`: all eight voxels lie in the grid.
struct TrackCell {
  long long origin = 0;
  glm::ivec3 cell{0};
  std::array<double, 8> weight{};
  bool interior = false;
  // With the nodes (forEachTrackCell<true>): the parameters of the piece's two Gauss nodes along
  // the segment given to forEachTrackCell, or along the range it was given (t_a at a, t_b at b), and
  // each node's share of the weights (node_weight[0][k] + node_weight[1][k] = weight[k]), so that a
  // caller can weight the path by a function of the parameter (a flux that decays along the step).
  std::array<double, 2> node_t{};
  std::array<std::array<double, 8>, 2> node_weight{};
};

// The walk is always inlined into its caller, so that it is compiled with the caller's instruction
// set: the CPU twin's deposits (track_deposit_cpu.cpp) compile their callers once per SIMD target.
#if defined(__GNUC__)
#define EIK_TRACK_INLINE inline __attribute__((always_inline))
#else
#define EIK_TRACK_INLINE inline
#endif

namespace detail {
// forEachTrackCell on a segment of a few dozen voxels at most, every weight multiplied by
// `scale`: a walk through the cells of the voxel-centre lattice (cells between planes through voxel
// centres, where the hats have their kinks), one piece per cell, each integrated with 2-point
// Gauss–Legendre (exact: the weights are cubic in the arc length there).
template <bool kNodes, typename VisitCell>
EIK_TRACK_INLINE void trackCellsShort(const glm::dvec3& a, const glm::dvec3& b, const glm::ivec3& dims, double scale,
                     VisitCell&& visit_cell, double t_a = 0.0, double t_b = 1.0) {
  const glm::dvec3 c0 = a - 0.5;  // lattice coordinates: cell k spans [k, k + 1)
  const glm::dvec3 delta = b - a;
  glm::ivec3 cell, step;
  glm::dvec3 next, every;  // parameter of the next plane crossing along each axis, and between planes
  for (int axis = 0; axis < 3; ++axis) {
    const double f = std::floor(c0[axis]);
    cell[axis] = static_cast<int>(f);
    if (delta[axis] > 0.0) {
      step[axis] = 1;
      every[axis] = 1.0 / delta[axis];
      next[axis] = (f + 1.0 - c0[axis]) * every[axis];
    } else if (delta[axis] < 0.0) {
      step[axis] = -1;
      every[axis] = -1.0 / delta[axis];
      // Starting on a plane and moving down: the cell below it.
      if (f == c0[axis]) cell[axis] -= 1;
      next[axis] = (c0[axis] - static_cast<double>(cell[axis])) * every[axis];
    } else {
      step[axis] = 0;
      every[axis] = 0.0;
      next[axis] = std::numeric_limits<double>::infinity();
    }
  }
  const long long sx = 1, sy = dims.x, sz = static_cast<long long>(dims.x) * dims.y;
  constexpr double kGauss = 0.28867513459481288225;  // 1/(2√3): the 2-point nodes at ½ ± this
  TrackCell out;
  double t0 = 0.0;
  while (t0 < 1.0) {
    int axis = next.x <= next.y ? (next.x <= next.z ? 0 : 2) : (next.y <= next.z ? 1 : 2);
    const double t1 = std::min(1.0, next[axis]);
    const double length = t1 - t0;
    if (length > 0.0) {
      // Both nodes lie in this cell and share its eight hats: their weights are summed first.
      const glm::dvec3 base(cell);
      const glm::dvec3 p = glm::clamp(c0 + (t0 + (0.5 - kGauss) * length) * delta - base, 0.0, 1.0);
      const glm::dvec3 q = glm::clamp(c0 + (t0 + (0.5 + kGauss) * length) * delta - base, 0.0, 1.0);
      const double pxy[4] = {(1.0 - p.x) * (1.0 - p.y), p.x * (1.0 - p.y), (1.0 - p.x) * p.y, p.x * p.y};
      const double qxy[4] = {(1.0 - q.x) * (1.0 - q.y), q.x * (1.0 - q.y), (1.0 - q.x) * q.y, q.x * q.y};
      const double piece = scale * 0.5 * length;
      for (int k = 0; k < 8; ++k) {
        const double wp = pxy[k & 3] * ((k & 4) ? p.z : 1.0 - p.z);
        const double wq = qxy[k & 3] * ((k & 4) ? q.z : 1.0 - q.z);
        out.weight[static_cast<std::size_t>(k)] = piece * (wp + wq);
        if constexpr (kNodes) {
          out.node_weight[0][static_cast<std::size_t>(k)] = piece * wp;
          out.node_weight[1][static_cast<std::size_t>(k)] = piece * wq;
        }
      }
      if constexpr (kNodes) {
        out.node_t[0] = t_a + (t_b - t_a) * (t0 + (0.5 - kGauss) * length);
        out.node_t[1] = t_a + (t_b - t_a) * (t0 + (0.5 + kGauss) * length);
      }
      out.cell = cell;
      out.origin = cell.x * sx + cell.y * sy + cell.z * sz;
      out.interior = cell.x >= 0 && cell.y >= 0 && cell.z >= 0 && cell.x + 1 < dims.x && cell.y + 1 < dims.y &&
                     cell.z + 1 < dims.z;
      visit_cell(static_cast<const TrackCell&>(out));
    }
    if (t1 >= 1.0) break;
    t0 = t1;
    cell[axis] += step[axis];
    next[axis] += every[axis];
  }
}
}  // namespace detail

// Calls visit_cell(const TrackCell&) for every lattice cell the segment a → b (continuous voxel
// coordinates) crosses within the hats' reach: the cell's eight weights are ∫ K_v ds / |b − a|,
// exactly, and all weights sum to 1 over the voxels in the grid (those outside it must be skipped:
// TrackCell::interior says whether any is). A cell may be visited more than once. Only the part
// within the hats' reach is integrated, and a long one (a free flight) in equal pieces of at most 48
// voxels of Σ|b − a| each (exact too: each piece is integrated exactly). kNodes: also the Gauss
// nodes (TrackCell::node_t, node_weight), their parameters running from t_a at a to t_b at b.
template <bool kNodes = false, typename VisitCell>
EIK_TRACK_INLINE void forEachTrackCell(const glm::dvec3& a, const glm::dvec3& b, const glm::ivec3& dims, VisitCell&& visit_cell,
                      double t_a = 0.0, double t_b = 1.0) {
  // The part of the segment within the hats' reach, (−½, dims + ½) along every axis: the rest
  // visits nothing. A segment that leaves it (a flight out of the grid) is cut, its weights scaled
  // by the share of the length kept.
  const glm::dvec3 delta = b - a;
  if (!std::isfinite(delta.x + delta.y + delta.z + a.x + a.y + a.z)) return;  // nothing to integrate
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
  const double t_from = t_a + (t_b - t_a) * f0, t_to = t_a + (t_b - t_a) * f1;
  if (!(l1 > kPiece)) {
    detail::trackCellsShort<kNodes>(from, to, dims, kept, visit_cell, t_from, t_to);
    return;
  }
  const int pieces = static_cast<int>(std::ceil(l1 / kPiece));
  for (int i = 0; i < pieces; ++i) {
    const double s0 = static_cast<double>(i) / pieces, s1 = static_cast<double>(i + 1) / pieces;
    detail::trackCellsShort<kNodes>(from + s0 * span, from + s1 * span, dims, kept / pieces, visit_cell,
                                    t_from + (t_to - t_from) * s0, t_from + (t_to - t_from) * s1);
  }
}

// The same weights voxel by voxel: visit(voxel_index, weight) for each non-zero weight of a voxel
// in the grid (a voxel may be visited more than once).
template <typename Visit>
void forEachTrackWeight(const glm::dvec3& a, const glm::dvec3& b, const glm::ivec3& dims, Visit&& visit) {
  const long long sy = dims.x, sz = static_cast<long long>(dims.x) * dims.y;
  forEachTrackCell(a, b, dims, [&](const TrackCell& c) {
    for (int k = 0; k < 8; ++k) {
      const double w = c.weight[static_cast<std::size_t>(k)];
      if (w == 0.0) continue;
      const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
      if (!c.interior) {
        const int x = c.cell.x + dx, y = c.cell.y + dy, z = c.cell.z + dz;
        if (x < 0 || y < 0 || z < 0 || x >= dims.x || y >= dims.y || z >= dims.z) continue;
      }
      visit(c.origin + dx + dy * sy + dz * sz, w);
    }
  });
}

// Sub-paths across a patch along one of its parameter directions: n = ceil(edge / spacing) of them
// (at least 1, at most kMaxTrackLattice), at the centres of n equal parameter intervals, so that
// neighbouring sub-paths are at most `spacing_voxels` apart. `edge_voxels` is the longer of the two
// patch edges along that direction, in voxels. The spacing is kTrackSpacing, or kDimTrackSpacing
// for dim light (trackSpacing).
constexpr int kMaxTrackLattice = 16;
inline int trackLattice(double edge_voxels, double spacing_voxels = 0.5) {
  if (!(edge_voxels > spacing_voxels)) return 1;
  return std::min(kMaxTrackLattice, static_cast<int>(std::ceil(edge_voxels / spacing_voxels - 1e-9)));
}

// The spacing of the sub-path lattice, in voxels, and the ripple it leaves in a plane wave's deposit
// (the largest deviation of a voxel from the beam's irradiance, over directions every 7.5° in polar
// and azimuth angle, measured on a 24³ grid): ½ voxel leaves 0.54 %, 1 voxel 7.5 % (the hat's
// spectrum, sinc² an axis, vanishes at whole frequencies; the 1-voxel lattice's replicas fall
// there only along the axes). A patch-step whose irradiance is under kDimTrackFraction of the
// brightest light in the grid (trackSpacing) takes the 1-voxel lattice: its ripple is then at
// most 7.5 % / 16 = 0.47 % of that light's irradiance, below the ½-voxel lattice's on the light
// itself, for a quarter of the sub-paths. Such light is common: the dim fans that leave a glass
// object past its silhouette cover as much volume as the direct beam and carry a thousandth of
// its flux.
constexpr double kTrackSpacing = 0.5;
constexpr double kDimTrackSpacing = 1.0;
constexpr double kDimTrackFraction = 1.0 / 16.0;

// The lattice spacing for a patch-step carrying `flux` (max channel) whose smaller end (before or
// after the step) has area `area`, where `dim_irradiance` is kDimTrackFraction of the brightest
// light in the grid (0: every patch-step takes the fine lattice).
inline double trackSpacing(double flux, double area, double dim_irradiance) {
  return dim_irradiance > 0.0 && flux < dim_irradiance * area ? kDimTrackSpacing : kTrackSpacing;
}

}  // namespace eik
