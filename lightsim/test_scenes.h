// Small in-memory scenes for the light simulator's tests (CPU and GPU): procedural volumes built
// with the voxelize library, and helpers that read the bake back (irradiance on a line, planar
// flux through a layer of voxels).
//
// Header-only on purpose: lightsim/CMakeLists.txt globs every lightsim/*.cpp that is not a test
// into eikonal_lightsim, which does not link eikonal_voxelize; only the test binary does. Tests
// include this file and link both.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/volume.h"
#include "lightsim/wavefront.h"
#include "voxelize/grid_builder.h"
#include "voxelize/pipeline.h"
#include "voxelize/procedural.h"

namespace eik::test_scenes {

// The pre-smoothing every scene here assumes unless it says otherwise (DESIGN §5: tests state the
// σ they assume): the voxelizer's default, 0.75 voxel.
constexpr double kSmoothSigmaVoxels = 0.75;

// Voxelises a procedural spec ("procedural:sphere,r=0.5,ior=1.5") like `voxelize` does: on the
// explicit `bounds` when given (h = longest extent / res), otherwise on the shape's bounds with
// `pad_voxels` of air and `res` voxels across the longest axis of the shape.
inline Volume proceduralVolume(const std::string& spec_text, int res, std::optional<Bounds> bounds = std::nullopt,
                               double smooth_sigma_voxels = kSmoothSigmaVoxels, double pad_voxels = kDefaultPadVoxels) {
  const ProceduralSpec spec = parseProceduralSpec(spec_text);
  const GridSpec grid = makeGrid(proceduralBounds(spec), res, pad_voxels, bounds);
  PipelineOptions options;
  options.smooth_sigma_voxels = smooth_sigma_voxels;
  return buildVolume(voxelizeProcedural(spec, grid), grid, options);
}

// The box [−a, a]³.
inline Bounds cube(double half) {
  Bounds b;
  b.min = glm::dvec3(-half);
  b.max = glm::dvec3(half);
  return b;
}

inline Bounds box(const glm::dvec3& lo, const glm::dvec3& hi) {
  Bounds b;
  b.min = lo;
  b.max = hi;
  return b;
}

// A homogeneous volume: n everywhere, ∇n = 0, σa everywhere (no sigma_a field when zero).
inline Volume uniformVolume(const GridSpec& grid, double n, const glm::dvec3& sigma_a = glm::dvec3(0.0)) {
  Volume v;
  v.grid = grid;
  Field& ior = v.addField("ior", 1);
  std::fill(ior.data.begin(), ior.data.end(), static_cast<float>(n));
  v.addField("ior_grad", 3);
  if (sigma_a != glm::dvec3(0.0)) {
    Field& sa = v.addField("sigma_a", 3);
    for (std::size_t i = 0; i < grid.count(); ++i)
      for (int c = 0; c < 3; ++c) sa.voxel(i)[c] = static_cast<float>(sigma_a[c]);
  }
  return v;
}

inline GridSpec cubicGrid(int res, double half) {
  GridSpec g;
  g.dims = glm::ivec3(res);
  g.bounds_min = glm::dvec3(-half);
  g.bounds_max = glm::dvec3(half);
  return g;
}

// ---------------------------------------------------------------------------------------------
// The scenes of the tests.

// A glass sphere of radius r and index n centred at the origin in the box `bounds`.
inline Volume glassSphere(int res, const Bounds& bounds, double r = 0.5, double n = 1.5) {
  return proceduralVolume("procedural:sphere,r=" + std::to_string(r) + ",ior=" + std::to_string(n), res, bounds);
}

// A Luneburg lens of radius r (n = sqrt(2 − (ρ/r)²)) in the box `bounds`.
inline Volume luneburgLens(int res, const Bounds& bounds, double r = 0.5) {
  return proceduralVolume("procedural:luneburg,r=" + std::to_string(r), res, bounds);
}

// A horizontal slab (procedural box, y from y0 to y0 + thickness) wider than the grid in x and z,
// so that it fills the grid's whole cross-section: index n and absorption σa (per world unit).
inline Volume slab(int res, const Bounds& bounds, double y0, double thickness, double n, const glm::dvec3& sigma_a) {
  const glm::dvec3 e = bounds.extent();
  const std::string size = std::to_string(4.0 * e.x) + ":" + std::to_string(thickness) + ":" + std::to_string(4.0 * e.z);
  const glm::dvec3 c(bounds.center().x, y0 + 0.5 * thickness, bounds.center().z);
  const std::string spec = "procedural:box,size=" + size + ",center=" + std::to_string(c.x) + ":" + std::to_string(c.y) +
                           ":" + std::to_string(c.z) + ",ior=" + std::to_string(n) + ",sigma_a=" +
                           std::to_string(sigma_a.x) + ":" + std::to_string(sigma_a.y) + ":" + std::to_string(sigma_a.z);
  return proceduralVolume(spec, res, bounds);
}

// A sphere of index n = 1 (no refraction) and absorption σa: a pure occluder for shadow tests.
inline Volume absorbingSphere(int res, const Bounds& bounds, double r, double sigma_a) {
  const std::string s = std::to_string(sigma_a);
  return proceduralVolume("procedural:sphere,r=" + std::to_string(r) + ",ior=1,sigma_a=" + s + ":" + s + ":" + s, res, bounds);
}

// ---------------------------------------------------------------------------------------------
// Reading a bake.

inline glm::dvec3 voxelValue(const Field& f, const GridSpec& g, int i, int j, int k) {
  const float* p = f.voxel(g.index(i, j, k));
  return glm::dvec3(p[0], p[1], p[2]);
}

// Flux (per channel, W) crossing the y-layers [j0, j1) downwards (towards −y), averaged over the
// layers: Σ E·(light_dir·(−ŷ))·h_x·h_z·h_y / (thickness). In accumulate mode a patch of flux Φ that
// crosses a layer of thickness Δy at angle θ deposits Φ·(Δy/cos θ)/V in it, so
// Σ_layer E·cos θ·V/Δy = Φ (ALGORITHM.md step 4). Where patches of different directions share a
// voxel, light_dir is their mean and the cosine is that of the mean: exact only for parallel light.
inline glm::dvec3 downwardFlux(const Field& irradiance, const Field& light_dir, const GridSpec& g, int j0, int j1) {
  const glm::dvec3 h = g.voxelSize();
  glm::dvec3 sum(0.0);
  for (int k = 0; k < g.dims.z; ++k)
    for (int j = j0; j < j1; ++j)
      for (int i = 0; i < g.dims.x; ++i) {
        const glm::dvec3 e = voxelValue(irradiance, g, i, j, k);
        const double cos_down = -voxelValue(light_dir, g, i, j, k).y;
        sum += e * cos_down;
      }
  return sum * (h.x * h.z) / static_cast<double>(j1 - j0);
}

// Net flux (per channel, W) leaving the grid through its six faces, each measured like
// downwardFlux over the `layers` voxel layers next to the face, along the face's outward normal.
inline glm::dvec3 outwardFlux(const Field& irradiance, const Field& light_dir, const GridSpec& g, int layers = 2) {
  const glm::dvec3 h = g.voxelSize();
  glm::dvec3 total(0.0);
  for (int axis = 0; axis < 3; ++axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? -1.0 : 1.0;
      glm::dvec3 sum(0.0);
      for (int l = 0; l < layers; ++l) {
        const int i = side == 0 ? l : g.dims[axis] - 1 - l;
        for (int u = 0; u < g.dims[a1]; ++u)
          for (int v = 0; v < g.dims[a2]; ++v) {
            glm::ivec3 c;
            c[axis] = i;
            c[a1] = u;
            c[a2] = v;
            const glm::dvec3 e = voxelValue(irradiance, g, c.x, c.y, c.z);
            sum += e * (sign * voxelValue(light_dir, g, c.x, c.y, c.z)[axis]);
          }
      }
      total += sum * (h[a1] * h[a2]) / static_cast<double>(layers);
    }
  }
  return total;
}

}  // namespace eik::test_scenes
