// A directional light with an angular size (the sun's disc, 0.53°): soft shadows
// (docs/physics.md "The sun's disc"). The bake follows the light from `samples` directions spread
// evenly over the disc (a sunflower: r_i = ρ·sqrt((i + ½)/K), φ_i = i·137.5°, ρ the disc's angular
// radius), each carrying 1/K of the irradiance, and sums the runs; so a shadow's edge fades over the
// penumbra the disc casts (its width the occluder's distance times the disc's angle) in K steps,
// which the azimuths of the sunflower blur.
#pragma once

#include <vector>

#include "lightsim/simulator.h"

namespace eik {

// The default number of directions for a light with an angular size.
constexpr int kDefaultSunSamples = 16;

// The light as `samples` point-like lights over its disc (angular_diameter_deg 0 each), their power
// summing to the light's. A light without an angular size (or not directional) is itself, alone.
std::vector<LightSpec> sunDiscSamples(const LightSpec& light, int samples);

}  // namespace eik
