// Where a straight step is exact: the quiet bricks of a volume (ALGORITHM.md "Free flight").
//
// A region is quiet when every trilinear sample in it gives one material with constant optics: the
// same interface signs (with sharp interfaces), ∇n = 0, and the same n and σa. There the ray
// equation (Eq. 4.12/4.13) has straight solutions, x(t) = x₀ + t·w/n², with w and Φ's absorption
// rate constant, so a patch can cross the region in one step of any length and its track deposits
// (track_deposit.h, exact along straight sub-paths) do not change.
//
// The map keeps one flag per brick of b³ voxels (b = 1 up to 100 voxels an axis with sharp
// interfaces, up to 160 otherwise; 2 up to 512, 4 beyond, so that the table stays under 32 M
// entries). At 132³ with sharp interfaces bricks of 2³ build in 0.04 s instead of 0.13 and answer
// from tables that stay in cache, which outweighs the 16 % more patch-steps of their coarser band;
// a smoothed n's wide band of ∇n ≠ 0 takes 9 % more patch-steps and 11 % more time per brick
// (BENCHMARKS.md "Patches split at 1.5 voxels"). Noisy when a voxel in it is noisy itself
// (∇n ≠ 0, a distance exactly 0, a graded material) or differs from a face neighbour, in which
// case both bricks are noisy. A box of voxels without a noisy brick holds one signature (it is
// connected through face neighbours, none of which differ), and a summed-area table over the flags
// answers "is this box quiet?" with eight lookups. Most boxes a flight asks about are answered
// with one: each brick's clearance (its chessboard distance to the nearest noisy brick) says at
// once that a box within it around its middle brick is quiet, or that a box around a noisy brick
// is not; the table decides the rest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid.h"
#include "core/interfaces.h"

namespace eik {

class QuietMap {
 public:

  QuietMap() = default;
  // The fields as VolumeSampler holds them: (n, ∇n) per voxel; the four slot distances per voxel
  // (empty without sharp interfaces) with their table; σa per voxel (empty: none).
  QuietMap(const GridSpec& grid, const std::vector<glm::vec4>& ior_grad, const std::vector<glm::vec4>& distances,
           const InterfaceTable& table, const std::vector<glm::vec3>& sigma_a);
  // The same from strided views of the fields, grid.count() voxels each: a Volume's own fields, so
  // that a sampler need not copy what it does not read (VolumeSampler).
  struct FieldViews {
    const float* ior = nullptr;        // n, every ior_stride floats
    std::size_t ior_stride = 1;
    const float* grad = nullptr;       // ∇n (3 floats), every grad_stride floats
    std::size_t grad_stride = 3;
    const float* distances = nullptr;  // the slot distances, every distances_stride floats; null: none
    std::size_t distances_stride = 4;
    const float* sigma_a = nullptr;    // σa (3 floats), every sigma_stride floats; null: none
    std::size_t sigma_stride = 3;
    // The distances' signs a voxel, if known (VolumeSampler): bit k slot k's distance < 0, bit 4 + k
    // it is 0; read instead of the distances.
    const std::uint8_t* slot_signs = nullptr;
  };
  QuietMap(const GridSpec& grid, const FieldViews& fields, const InterfaceTable& table);

  // From flags of the voxels themselves (no neighbours compared): a box is quiet when no trilinear
  // sample in it touches a flagged voxel. VolumeSampler::absorberMap flags the absorbing voxels, so
  // a quiet box is one where σa = 0 everywhere (straight steps in absorbing volumes).
  QuietMap(const GridSpec& grid, const std::vector<std::uint8_t>& flagged_voxels);

  // Does every trilinear sample (GL_LINEAR, clamp-to-edge) at a point of the world box [lo, hi]
  // see the same material with constant optics? Points outside the grid sample its edge voxels,
  // so a box beyond the grid is quiet when the edge voxels it clamps to are. False for a box that
  // is not finite.
  bool quiet(const glm::dvec3& lo, const glm::dvec3& hi) const;

  bool empty() const { return sat_.empty(); }
  glm::ivec3 bricks() const { return bricks_; }
  int brickVoxels() const { return brick_; }  // voxels per brick edge
  std::size_t noisyBricks() const { return noisy_; }
  // The summed-area table, (bricks + 1)³ entries, x fastest: entry (i, j, k) counts the noisy
  // bricks with indices below (i, j, k) (the GPU's copy: quiet_texture.h).
  const std::vector<std::uint32_t>& table() const { return sat_; }
  // Per brick (x fastest), its chessboard distance in bricks to the nearest noisy brick: 0 for a
  // noisy one, at most 255 (also where none is noisy).
  const std::vector<std::uint8_t>& clearances() const { return clearance_; }

 private:
  GridSpec grid_;
  glm::dvec3 inv_voxel_size_{1.0};  // 1/grid_.voxelSize(), once (quiet multiplies by it: toVoxel)
  int brick_ = 2;
  int brick_shift_ = 1;  // log₂ brick_
  glm::ivec3 bricks_{0};
  std::size_t noisy_ = 0;
  // Summed-area table of the noisy flags, (bricks + 1)³ entries; entry (i, j, k) counts the noisy
  // bricks with indices below (i, j, k).
  std::vector<std::uint32_t> sat_;
  // Per brick (x fastest), the chessboard distance in bricks to the nearest noisy brick: 0 for a
  // noisy brick, at most 255 (also where none is noisy).
  std::vector<std::uint8_t> clearance_;
  void buildClearance();  // from the summed-area table
  // The brick size for the grid (1 voxel up to `per_voxel_up_to` voxels an axis, then 2 up to 512,
  // then 4), and the summed-area table over per-brick flags.
  void chooseBricks(int per_voxel_up_to);
  std::vector<std::uint8_t>::reference brickFlag(std::vector<std::uint8_t>& flags, int x, int y, int z) const;
  void buildTable(const std::vector<std::uint8_t>& brick_flags);
  std::uint32_t sat(int i, int j, int k) const {
    return sat_[static_cast<std::size_t>(i) +
                static_cast<std::size_t>(bricks_.x + 1) *
                    (static_cast<std::size_t>(j) + static_cast<std::size_t>(bricks_.y + 1) * static_cast<std::size_t>(k))];
  }
};

}  // namespace eik
