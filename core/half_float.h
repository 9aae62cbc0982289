// IEEE 754 binary16 ("half") values for textures that need no more than half precision: the
// viewer's ground texture (viewer/shadow_edge.h receiverTexelsHalf), uploaded as RGBA16F. Through
// OpenEXR's Imath::half (round to nearest even; overflow to infinity, as the GPU converts).
#pragma once

#include <cstdint>
#include <span>

namespace eik {

// The half nearest to `value`, as its 16 bits.
std::uint16_t toHalf(float value);
// Each value of `from` into `to` (the same length).
void toHalf(std::span<const float> from, std::span<std::uint16_t> to);
// The float a half's bits stand for (exact).
float fromHalf(std::uint16_t bits);

}  // namespace eik
