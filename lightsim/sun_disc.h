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
// summing to the light's; a point or spot light with a radius, as `samples` points in its ball
// (ballLightPoints). A light without an angular size or a radius is itself, alone.
std::vector<LightSpec> sunDiscSamples(const LightSpec& light, int samples);

// A point or spot light of radius ρ (a ball whose surface shines evenly: every receiver sees a
// uniform disc of radius ρ facing it) as `samples` points in the ball, each with 1/K of the
// intensity, that look like that disc from every side at once: their radii have the density
// ∝ r²/sqrt(ρ² − r²), whose projection along any direction is uniform over the disc (the Abel
// transform of 1/sqrt(ρ² − r²) is constant). Stratified: r_i = ρ sin u_i at the quantiles (i + ½)/K
// of (u − sin u cos u)/(π/2), the directions at height z_i = 1 − 2·(the base-2 radical inverse of
// i + ½/K) and azimuth i·137.5°, so that radius, height and azimuth do not follow one another.
std::vector<glm::dvec3> ballLightPoints(double radius, int samples);

}  // namespace eik
