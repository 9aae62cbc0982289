#include "core/tonemap.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace eik {

ToneMapper parseToneMapper(std::string_view text, std::string_view source) {
  if (text == "linear") return ToneMapper::Linear;
  if (text == "reinhard") return ToneMapper::Reinhard;
  if (text == "aces") return ToneMapper::Aces;
  throw InputError(std::string(source), std::string(text), "unknown tone mapper (expected linear, reinhard or aces)");
}

glm::vec3 toneMapReinhard(const glm::vec3& x) { return x / (1.0f + x); }

glm::vec3 toneMapAces(const glm::vec3& x) {
  constexpr float a = 2.51f, b = 0.03f, c = 2.43f, d = 0.59f, e = 0.14f;
  return glm::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0f, 1.0f);
}

float linearToSrgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

glm::vec3 toDisplay(const glm::vec3& radiance, float exposure_ev, ToneMapper mapper) {
  glm::vec3 x = glm::max(radiance, glm::vec3(0.0f)) * std::exp2(exposure_ev);
  switch (mapper) {
    case ToneMapper::Reinhard: x = toneMapReinhard(x); break;
    case ToneMapper::Aces: x = toneMapAces(x); break;
    case ToneMapper::Linear: break;
  }
  return {linearToSrgb(x.x), linearToSrgb(x.y), linearToSrgb(x.z)};
}

}  // namespace eik
