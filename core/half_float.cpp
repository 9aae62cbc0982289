// Half-float conversion (see half_float.h).
#include "core/half_float.h"

#include <Imath/half.h>

#include <stdexcept>

namespace eik {

std::uint16_t toHalf(float value) { return Imath::half(value).bits(); }

void toHalf(std::span<const float> from, std::span<std::uint16_t> to) {
  if (from.size() != to.size()) throw std::invalid_argument("toHalf: the spans differ in length");
  for (std::size_t i = 0; i < from.size(); ++i) to[i] = Imath::half(from[i]).bits();
}

float fromHalf(std::uint16_t bits) {
  Imath::half h;
  h.setBits(bits);
  return static_cast<float>(h);
}

}  // namespace eik
