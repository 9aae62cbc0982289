// The histogram pyramid's CPU reference (see histo_pyramid_cpu.h; test-only).
#include "lightsim/histo_pyramid_cpu.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.h"

namespace eik {
namespace {

constexpr const char* kWhat = "HistoPyramid";

}  // namespace

HistoPyramidCpu::HistoPyramidCpu(int baseSize, std::span<const float> counts, std::size_t liveSlots)
    : base_(baseSize), levels_(hpCheckedLevels(baseSize)) {
  const std::size_t n = static_cast<std::size_t>(baseSize) * static_cast<std::size_t>(baseSize);
  if (counts.size() != n) {
    throw InputError(kWhat, "counts", std::to_string(counts.size()) + " values for a base of " + std::to_string(n));
  }
  level_.resize(static_cast<std::size_t>(levels_) + 1);
  level_[0].assign(n, 0);
  const std::size_t live = std::min(liveSlots, n);
  for (std::size_t slot = 0; slot < live; ++slot) {
    const std::size_t i = hpTexelIndex(hpSlotTexel(static_cast<std::uint32_t>(slot)), base_);
    const float c = counts[i];
    if (!std::isfinite(c) || c < 0.0f || c != std::floor(c)) {
      throw InputError(
          kWhat, "counts",
          "slot " + std::to_string(slot) + " holds " + std::to_string(c) + " (counts are non-negative integers)");
    }
    level_[0][i] = static_cast<std::uint64_t>(c);
  }
  for (int l = 1; l <= levels_; ++l) {
    const int side = base_ >> l, below = base_ >> (l - 1);
    std::vector<std::uint64_t>& out = level_[static_cast<std::size_t>(l)];
    const std::vector<std::uint64_t>& in = level_[static_cast<std::size_t>(l - 1)];
    out.assign(static_cast<std::size_t>(side) * static_cast<std::size_t>(side), 0);
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        const std::size_t c = hpTexelIndex({2 * x, 2 * y}, below);
        out[hpTexelIndex({x, y}, side)] =
            in[c] + in[c + 1] + in[c + static_cast<std::size_t>(below)] + in[c + static_cast<std::size_t>(below) + 1];
      }
    }
  }
}

std::uint64_t HistoPyramidCpu::at(int level, glm::ivec2 t) const {
  return level_.at(static_cast<std::size_t>(level)).at(hpTexelIndex(t, base_ >> level));
}

HistoPyramidEntry HistoPyramidCpu::find(std::uint64_t k) const {
  if (k >= total()) throw std::out_of_range("HistoPyramidCpu::find: slot beyond the total");
  glm::ivec2 node{0};
  for (int l = levels_ - 1; l >= 0; --l) {
    node *= 2;
    static constexpr glm::ivec2 kChild[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    int child = 0;
    for (; child < 3; ++child) {
      const std::uint64_t c = at(l, node + kChild[child]);
      if (k < c) break;
      k -= c;
    }
    node += kChild[child];
  }
  return {hpTexelSlot(node), node, static_cast<std::uint32_t>(k)};
}

std::vector<HistoPyramidEntry> HistoPyramidCpu::expand() const {
  std::vector<HistoPyramidEntry> out;
  out.reserve(static_cast<std::size_t>(total()));
  for (std::uint64_t k = 0; k < total(); ++k) out.push_back(find(k));
  return out;
}

std::vector<HistoPyramidEntry> hpExpandByPrefixSum(std::span<const std::uint32_t> countsBySlot) {
  std::vector<HistoPyramidEntry> out;
  for (std::size_t s = 0; s < countsBySlot.size(); ++s) {
    const auto slot = static_cast<std::uint32_t>(s);
    for (std::uint32_t j = 0; j < countsBySlot[s]; ++j) out.push_back({slot, hpSlotTexel(slot), j});
  }
  return out;
}

std::vector<float> hpRandomCounts(int side, std::size_t live, const std::vector<float>& values,
                                  const std::vector<double>& weights, std::mt19937& rng, float beyond) {
  std::discrete_distribution<int> pick(weights.begin(), weights.end());
  std::vector<float> counts(std::size_t(side) * std::size_t(side), beyond);
  for (std::size_t s = 0; s < std::min(live, counts.size()); ++s) {
    counts[hpTexelIndex(hpSlotTexel(std::uint32_t(s)), side)] = values[std::size_t(pick(rng))];
  }
  return counts;
}

}  // namespace eik
