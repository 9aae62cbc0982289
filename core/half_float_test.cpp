// Half-float conversion against the binary16 format's own values (IEEE 754-2008 §3.6).
#include "core/half_float.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
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

// The span conversion (F16C eight at a time where the CPU has it, then a scalar tail) gives the bits
// the scalar one gives: for every half's own value, the midpoints between neighbouring halves (the
// ties, rounded to even) and a hair either side of them, both signs, beyond the largest finite half,
// and NaN (a NaN either way). 2¹⁶·4 values in a span of odd length (the tail taken too).
TEST(HalfFloat, TheSpanConversionIsTheScalarOne) {
  std::vector<float> values;
  for (std::uint32_t bits = 0; bits < 0x7c00; ++bits) {  // the finite non-negative halves
    const float v = fromHalf(static_cast<std::uint16_t>(bits));
    const float next = bits + 1 < 0x7c00 ? fromHalf(static_cast<std::uint16_t>(bits + 1)) : 65520.0f;  // 65520: overflows
    const float mid = 0.5f * (v + next);
    for (const float x : {v, mid, std::nextafter(mid, 0.0f), std::nextafter(mid, 1e30f)}) {
      values.push_back(x);
      values.push_back(-x);
    }
  }
  values.push_back(std::numeric_limits<float>::infinity());
  values.push_back(1e30f);
  values.push_back(std::numeric_limits<float>::quiet_NaN());
  values.push_back(std::numeric_limits<float>::denorm_min());
  if (values.size() % 8 == 0) values.push_back(0.25f);
  std::vector<std::uint16_t> bits(values.size());
  toHalf(values, bits);
  int differ = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isnan(values[i])) {
      EXPECT_TRUE(std::isnan(fromHalf(bits[i])));
      continue;
    }
    differ += bits[i] != toHalf(values[i]);
    if (bits[i] != toHalf(values[i]) && differ < 5) ADD_FAILURE() << values[i] << ": " << bits[i] << " vs " << toHalf(values[i]);
  }
  EXPECT_EQ(differ, 0);
}

}  // namespace
}  // namespace eik
