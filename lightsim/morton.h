// Morton (Z-order) placement of a list in a square texture: list index k lives at texel
// (x, y) with x from the even bits of k and y from the odd ones. The patch lists
// (patch_textures.h) and the histogram pyramid (histo_pyramid.h) share it, so a list's index order
// is the pyramid's traversal order, and the first `count` entries fill the rectangle
// mortonBox(count) (GLSL twin: shaders/lightsim/histo_pyramid.glsl).
#pragma once

#include <bit>
#include <cstdint>
#include <stdexcept>

#include <glm/vec2.hpp>

namespace eik {

// The low 16 bits of v spread to the even bits (…b2 0 b1 0 b0), and back.
constexpr std::uint32_t mortonSpreadBits(std::uint32_t v) {
  v &= 0x0000ffffu;
  v = (v | (v << 8)) & 0x00ff00ffu;
  v = (v | (v << 4)) & 0x0f0f0f0fu;
  v = (v | (v << 2)) & 0x33333333u;
  v = (v | (v << 1)) & 0x55555555u;
  return v;
}
constexpr std::uint32_t mortonCompactBits(std::uint32_t v) {
  v &= 0x55555555u;
  v = (v | (v >> 1)) & 0x33333333u;
  v = (v | (v >> 2)) & 0x0f0f0f0fu;
  v = (v | (v >> 4)) & 0x00ff00ffu;
  v = (v | (v >> 8)) & 0x0000ffffu;
  return v;
}

// Index → texel and back.
constexpr glm::ivec2 mortonTexel(std::uint32_t index) {
  return {static_cast<int>(mortonCompactBits(index)), static_cast<int>(mortonCompactBits(index >> 1))};
}
constexpr std::uint32_t mortonIndex(glm::ivec2 texel) {
  return mortonSpreadBits(static_cast<std::uint32_t>(texel.x)) |
         (mortonSpreadBits(static_cast<std::uint32_t>(texel.y)) << 1);
}

// The smallest power-of-two rectangle at the origin holding indices 0 .. count − 1:
// 2^⌈b/2⌉ × 2^⌊b/2⌋ with b the bit length of count − 1; (0, 0) for count 0. The viewport of a pass
// over the first `count` entries. std::out_of_range above 2^32 entries.
inline glm::ivec2 mortonBox(std::uint64_t count) {
  if (count == 0) return {0, 0};
  if (count > (std::uint64_t{1} << 32)) throw std::out_of_range("mortonBox: more than 2^32 entries");
  const int bits = static_cast<int>(std::bit_width(count - 1));
  return {1 << ((bits + 1) / 2), 1 << (bits / 2)};
}

}  // namespace eik
