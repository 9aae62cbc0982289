// Flat 3D ("atlas") render targets for the deposit step (ALGORITHM.md step 4, thesis §6.2.3,
// Harris et al. 2003): GL 3.3 cannot rasterise into a 3D texture in one draw, so the z-slices of
// the grid are tiled into one 2D texture, tiles.x slices a row, and each patch is a GL_POINTS
// primitive that lands on the atlas texel of the voxel holding its midpoint (deposit_pass.h).
//
//   voxel (i, j, k)  ↔  atlas texel (tx·dims.x + i, ty·dims.y + j),  tx = k mod tiles.x,
//                                                                   ty = k div tiles.x
//
// Deposit modes (docs/physics.md):
//   accumulate  target 0 += (Φ·Δs_m / V_voxel, 0)           additive blending
//               target 1 += (lum(Φ)·Δs_m · d, 1)            direction sum, deposit count
//   max         target 0  = (E, lum(E)), target 1 = (d, 1)  of the patch with the largest lum(E),
//               kept by a Depth32F test on depth = ½ / (1 + lum(E)/E_ref) (GL_LESS: the first of
//               equal patches wins, as in the CPU twin's strict comparison)
// toFields() reads the targets back and turns them into the `irradiance` and `light_dir` fields.
#pragma once

#include <cstddef>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/volume.h"
#include "gl/framebuffer.h"
#include "gl/shader_library.h"
#include "gl/texture.h"
#include "lightsim/simulator.h"

namespace eik {

struct AtlasLayout {
  glm::ivec3 dims{0};
  glm::ivec2 tiles{0};   // slices per row, rows
  glm::ivec2 size{0};    // tiles · dims.xy

  // The most compact tiling (smallest larger side, then least area) whose size fits in
  // maxTextureSize. InputError "SOURCE: dims: volume too large for the GPU: ..." naming the grid,
  // the atlas it would need and the limit when none fits.
  static AtlasLayout plan(glm::ivec3 dims, int maxTextureSize, const std::string& source = "volume",
                          const std::string& renderer = "");

  glm::ivec2 texel(glm::ivec3 voxel) const {
    return {(voxel.z % tiles.x) * dims.x + voxel.x, (voxel.z / tiles.x) * dims.y + voxel.y};
  }
  // The voxel an atlas texel stores, or (−1, −1, −1) for the unused tiles of the last row.
  glm::ivec3 voxel(glm::ivec2 texel) const;
  std::size_t texelCount() const { return static_cast<std::size_t>(size.x) * static_cast<std::size_t>(size.y); }
  // GLSL defines (ATLAS_DIMS, ATLAS_TILES_X, ATLAS_SIZE) for shaders/lightsim/atlas.glsl.
  gl::ShaderDefines defines() const;
};

// The two RGBA32F atlas targets (and, for max mode, a Depth32F attachment).
class AtlasTargets {
 public:
  AtlasTargets() = default;
  AtlasTargets(const AtlasLayout& layout, DepositMode mode);

  const AtlasLayout& layout() const { return layout_; }
  DepositMode mode() const { return mode_; }
  gl::Framebuffer& framebuffer() { return framebuffer_; }
  // Zero colour, depth 1.
  void clear();
  std::size_t bytes() const;
  static std::size_t bytesFor(const AtlasLayout& layout, DepositMode mode);

  // Reads the atlas back: irradiance (RGB, W/m²) and light_dir (unit, 0 where nothing passed).
  void toFields(Field& irradiance, Field& lightDir) const;

 private:
  AtlasLayout layout_;
  DepositMode mode_ = DepositMode::Accumulate;
  gl::Texture2D energy_;
  gl::Texture2D direction_;
  gl::Texture2D depth_;
  gl::Framebuffer framebuffer_;
};

}  // namespace eik
