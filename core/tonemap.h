// HDR → display: exposure, tone mapping (Reinhard, an ACES fit), sRGB encoding.
#pragma once

#include <string_view>

#include <glm/glm.hpp>

namespace eik {

enum class ToneMapper { Linear, Reinhard, Aces };

// "linear" | "reinhard" | "aces"; InputError naming `source` otherwise.
ToneMapper parseToneMapper(std::string_view text, std::string_view source = "--tonemap");

// Reinhard et al. 2002, per channel: x / (1 + x).
glm::vec3 toneMapReinhard(const glm::vec3& x);
// Narkowicz's fit of the ACES filmic reference curve (2015), per channel, clamped to [0, 1].
glm::vec3 toneMapAces(const glm::vec3& x);
// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
float linearToSrgb(float linear);

// Linear radiance → display-referred sRGB in [0, 1]: scale by 2^exposure, tone map, encode.
glm::vec3 toDisplay(const glm::vec3& radiance, float exposure_ev, ToneMapper mapper);

}  // namespace eik
