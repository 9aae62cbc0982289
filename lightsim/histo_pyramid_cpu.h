// HistoPyramidCpu: the CPU reference of the histogram pyramid (histo_pyramid.h, ALGORITHM.md
// step 6), in exact integers, for the tests of the GPU pyramid: the same levels and the same descent
// as hpFind in shaders/lightsim/histo_pyramid.glsl. And hpExpandByPrefixSum, the plain prefix sum
// the CPU twin's compaction is (CpuSimulator::run), which the descent must equal.
//
// Also the count patterns the pyramid's tests draw (hpRandomCounts).
//
// Test-only support code: nothing in the product uses it (the CPU twin compacts with its own
// prefix sum); it belongs with the tests, not in eikonal_lightsim.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include <glm/vec2.hpp>

#include "lightsim/histo_pyramid.h"

namespace eik {

struct HistoPyramidEntry {
  std::uint32_t slot = 0;  // source slot (list index)
  glm::ivec2 texel{0};     // source texel in the base (= hpSlotTexel(slot))
  std::uint32_t sub = 0;   // sub-index j in [0, count of the source)
  bool operator==(const HistoPyramidEntry&) const = default;
};

// The pyramid built on the CPU in exact integers, and the same descent as hpFind.
class HistoPyramidCpu {
 public:
  // `counts`: baseSize² values in texel order (x fastest, rows from the bottom: Texture2D data);
  // only slots < liveSlots count. Throws InputError for a base that is not a power of two, a wrong
  // number of counts, or a count that is negative, not an integer or not finite (at a live slot).
  HistoPyramidCpu(int baseSize, std::span<const float> counts, std::size_t liveSlots = HistoPyramidLimits::kAllSlots);

  int baseSize() const { return base_; }
  int levels() const { return levels_; }  // K = log2(baseSize); the top is level K
  std::uint64_t total() const { return level_.back()[0]; }
  // Value of texel `t` at `level` (0 = the masked counts).
  std::uint64_t at(int level, glm::ivec2 t) const;
  // Output slot k < total() → its source and sub-index (std::out_of_range for k ≥ total()).
  HistoPyramidEntry find(std::uint64_t k) const;
  // find(k) for every k < total().
  std::vector<HistoPyramidEntry> expand() const;

 private:
  int base_ = 0;
  int levels_ = 0;
  std::vector<std::vector<std::uint64_t>> level_;  // level_[l]: (base >> l)² values, texel order
};

// Plain prefix-sum reference: counts by slot (list order) → for each output k, its source slot and
// sub-index (texel = hpSlotTexel(slot)). This is what the CPU twin does; it equals
// HistoPyramidCpu::expand() for the same counts placed at hpSlotTexel.
std::vector<HistoPyramidEntry> hpExpandByPrefixSum(std::span<const std::uint32_t> countsBySlot);

// Index of texel t in texel order (x fastest, rows from the bottom) of a side × side texture.
inline std::size_t hpTexelIndex(glm::ivec2 t, int side) {
  return static_cast<std::size_t>(t.y) * static_cast<std::size_t>(side) + static_cast<std::size_t>(t.x);
}

// Counts in texel order for `live` slots (Morton order) drawn from `values` with `weights`; slots
// beyond `live` get `beyond`.
std::vector<float> hpRandomCounts(int side, std::size_t live, const std::vector<float>& values,
                                  const std::vector<double>& weights, std::mt19937& rng, float beyond = 0.0f);

}  // namespace eik
