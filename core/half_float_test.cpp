// Half-float conversion against the binary16 format's own values (IEEE 754-2008 §3.6).
#include "core/half_float.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace eik {
namespace {

TEST(HalfFloat, ExactValuesAndTheFormatsLimits) {
  EXPECT_EQ(toHalf(0.0f), 0x0000);
  EXPECT_EQ(toHalf(-0.0f), 0x8000);
  EXPECT_EQ(toHalf(1.0f), 0x3c00);
  EXPECT_EQ(toHalf(-2.0f), 0xc000);
  EXPECT_EQ(toHalf(65504.0f), 0x7bff);                 // the largest finite half
  EXPECT_EQ(toHalf(1e6f), 0x7c00);                     // beyond it: infinity
  EXPECT_EQ(toHalf(std::ldexp(1.0f, -24)), 0x0001);    // the smallest subnormal
  EXPECT_EQ(toHalf(std::ldexp(1.0f, -14)), 0x0400);    // the smallest normal
  EXPECT_TRUE(std::isnan(fromHalf(toHalf(std::numeric_limits<float>::quiet_NaN()))));
  for (const float v : {0.0f, 1.0f, -2.0f, 65504.0f, 0.5f, 1.5f, std::ldexp(1.0f, -24)}) EXPECT_EQ(fromHalf(toHalf(v)), v) << v;
}

// Round to nearest, ties to even: 1 + 2⁻¹¹ lies halfway between 1 and 1 + 2⁻¹⁰ and goes to 1 (even);
// 1 + 3·2⁻¹¹ halfway between 1 + 2⁻¹⁰ and 1 + 2⁻⁹ goes up to the even 1 + 2⁻⁹. Any float is within
// half a unit of the last place, 2⁻¹¹ relative, of its half.
TEST(HalfFloat, RoundsToNearestEven) {
  EXPECT_EQ(toHalf(1.0f + std::ldexp(1.0f, -11)), 0x3c00);
  EXPECT_EQ(toHalf(1.0f + 3.0f * std::ldexp(1.0f, -11)), 0x3c02);
  std::vector<float> values;
  for (int i = 0; i < 1000; ++i) values.push_back(std::ldexp(1.0f + 0.000731f * static_cast<float>(i), i % 20 - 10));
  std::vector<std::uint16_t> bits(values.size());
  toHalf(values, bits);
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(bits[i], toHalf(values[i]));
    EXPECT_LE(std::abs(fromHalf(bits[i]) - values[i]), std::ldexp(values[i], -11)) << values[i];
  }
  std::vector<std::uint16_t> short_output(3);
  EXPECT_THROW(toHalf(values, short_output), std::invalid_argument);
}

}  // namespace
}  // namespace eik
