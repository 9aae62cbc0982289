// The exact tracer's map laid over a bake's receiver map (header only): for the tests and tools that
// hold both. The tracer itself (exact_optics.h) knows nothing of core's ReceiverMap.
#pragma once

#include <cstddef>

#include "core/receiver_map.h"
#include "tests/reference/exact_optics.h"

namespace eik::reference {

// Makes `receiver`'s square map the texels of `map` (pitch, axes, origin relative to
// receiver.center, which should be map.point); map.texels.x texels a side.
inline void binLikeMap(const ReceiverMap& map, Receiver& receiver) {
  receiver.map_texels = map.texels.x;
  receiver.map_pitch = map.pitch;
  receiver.map_u = map.u;
  receiver.map_v = map.v;
  receiver.map_origin_given = true;
  receiver.map_origin = map.origin;
}

// The tally's map as planar irradiance (flux over texel area) on `map`'s lattice, grey.
inline ReceiverMap irradianceLikeMap(const ReceiverMap& map, const ReceiverTally& tally) {
  ReceiverMap exact = map.geometry();
  exact.components = 1;
  exact.irradiance.resize(map.texelCount());
  for (std::size_t t = 0; t < map.texelCount(); ++t)
    exact.irradiance[t] = static_cast<float>(tally.map_flux[t] / (map.pitch * map.pitch));
  return exact;
}

}  // namespace eik::reference
