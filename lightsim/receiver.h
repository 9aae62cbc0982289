// Receivers (ALGORITHM.md "Receivers"; docs/physics.md "Receivers"): a diffuse plane — the scene's
// ground — that stops the light and gets its own map of planar irradiance, finer than the volume.
//
// Where a patch crosses the plane, each corner's ray meets the plane: the four points are the
// patch's footprint, and its flux Φ spreads uniformly over it. A texel gets Φ·(area of footprint ∩
// texel)/(area of footprint): exact, so footprints that tile the plane (a wavefront in free air)
// give every texel its exact irradiance, and the flux is conserved to the last texel. The
// irradiance of a texel is its flux over its area. It is planar irradiance — flux through the
// plane per area — which carries the cos θ of oblique light, unlike the volume's fluence-like
// `irradiance` field.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/receiver_map.h"
#include "lightsim/simulator.h"

namespace eik {

struct Patch;

// The map's geometry for a bake: the box `box_lo`..`box_hi` seen from the light (projected along a
// directional light, or from a point light) onto the plane — the volume's shadow — grown by its
// own size on every side (for the light the object reflects or bends beyond it), within the square
// of half extent `spec.half_extent` around `spec.point`; texels of spec.pitch_voxels·h (h the
// grid's smallest voxel edge; coarser if the map would exceed kMaxReceiverTexels per axis, the
// NRRD limit). The irradiance is left empty. Throws InputError naming "receiver" when the light
// does not reach the plane from its front (normal) side.
ReceiverMap receiverGeometry(const ReceiverSpec& spec, const LightSpec& light, const GridSpec& grid,
                             const glm::dvec3& box_lo, const glm::dvec3& box_hi);
constexpr int kMaxReceiverTexels = 1024;

// Where the rays of a patch's corners (x_c along w_c) meet the plane, in the plane's (u, v)
// coordinates. False when a corner's ray runs parallel to the plane.
bool patchFootprint(const Patch& patch, const ReceiverMap& map, std::array<glm::dvec2, 4>& footprint);

// Adds flux Φ spread uniformly over the quadrilateral `footprint` ((u, v) coordinates) to the
// per-texel flux sums `texel_flux` (W, texelCount() long): split into the triangles (0, 1, 2) and
// (0, 2, 3), each taking Φ·|its area|/(|area 1| + |area 2|) (a fold or twist keeps its flux), each
// clipped exactly against every texel it touches. Flux falling outside the map is dropped.
// Only the texel rows [row_begin, row_end) are written (each row's share is computed the same way
// whatever the range), so that bands of rows can be filled in parallel with the same sums.
void depositFootprint(const ReceiverMap& map, const std::array<glm::dvec2, 4>& footprint, const glm::dvec3& flux,
                      std::vector<glm::dvec3>& texel_flux, int row_begin = 0,
                      int row_end = std::numeric_limits<int>::max());

// Area of the intersection of triangle (a, b, c) with the axis-aligned square [lo, hi] (exact,
// Sutherland–Hodgman clipping).
double triangleSquareOverlap(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& lo,
                             const glm::dvec2& hi);

}  // namespace eik
