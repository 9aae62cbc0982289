// Tests of the histogram pyramid's CPU reference (histo_pyramid_cpu.h): its descent equals a plain
// prefix sum over the counts in slot order (what the CPU twin does) for random patterns and live
// counts that are not powers of two, and it rejects bad input.
#include "lightsim/histo_pyramid_cpu.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/error.h"

namespace eik {
namespace {

TEST(HistoPyramidCpuTest, DescentEqualsPrefixSum) {
  std::mt19937 rng(7);
  for (int side : {1, 2, 4, 8, 32}) {
    const std::size_t n = std::size_t(side) * std::size_t(side);
    for (std::size_t live : {n, n / 2 + 1, std::size_t(1), n > 3 ? n - 3 : n}) {
      std::vector<float> counts = hpRandomCounts(side, live, {0, 1, 2, 3, 4}, {3, 3, 1, 1, 2}, rng, 3.0f);
      HistoPyramidCpu cpu(side, counts, live);
      std::vector<std::uint32_t> bySlot(live);
      for (std::size_t s = 0; s < live; ++s) {
        bySlot[s] = std::uint32_t(counts[hpTexelIndex(hpSlotTexel(std::uint32_t(s)), side)]);
      }
      const std::vector<HistoPyramidEntry> reference = hpExpandByPrefixSum(bySlot);
      EXPECT_EQ(cpu.total(), reference.size());
      EXPECT_EQ(cpu.expand(), reference) << "side " << side << ", live " << live;
    }
  }
}

TEST(HistoPyramidCpuTest, RejectsBadInput) {
  std::vector<float> counts(16, 1.0f);
  EXPECT_THROW(HistoPyramidCpu(3, std::vector<float>(9, 1.0f)), InputError);
  EXPECT_THROW(HistoPyramidCpu(4, std::vector<float>(15, 1.0f)), InputError);
  counts[5] = 1.5f;
  EXPECT_THROW(HistoPyramidCpu(4, counts), InputError);
  counts[5] = -1.0f;
  EXPECT_THROW(HistoPyramidCpu(4, counts), InputError);
  counts[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(HistoPyramidCpu(4, counts), InputError);
  // Beyond the live slots anything goes.
  counts.assign(16, 1.0f);
  counts[hpTexelIndex(hpSlotTexel(12), 4)] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(HistoPyramidCpu(4, counts, 12).total(), 12u);
  EXPECT_THROW(HistoPyramidCpu(4, counts, 12).find(12), std::out_of_range);
}

}  // namespace
}  // namespace eik
