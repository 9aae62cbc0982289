// Sharp shadow edges on the ground (docs/physics.md "Receivers", "The shadow's edge").
//
// A receiver map holds each texel's mean irradiance, so where an object's shadow crosses a texel
// the map holds a mix of light and shadow, and the bilinear lookup of the ground spreads the
// shadow's edge over two texels (at 64³ the 0.9–1 ring of the sphere's shadow read 22 % too
// bright in the viewer for that alone). The edge of the geometric shadow is known far more
// precisely than a texel: it is where the straight ray from the ground to a directional light
// grazes the object's sharp surfaces. So the viewer splits the map into the direct light, cut by
// the shadow at the pixel, and the rest, which is smooth across the edge:
//
//   clearance  c(p) = min over the ray from texel centre p toward the light of the union's signed
//              distance (the interfaces field, trilinear as lightsim and the viewer read it):
//              positive, the ray's distance from the object; negative, the ray passes inside it.
//              It changes sign at the edge and is linear across it (exactly so for a sphere under
//              a vertical sun: c = ρ − R both sides), so its bilinear lookup puts the edge at the
//              pixel, not the texel.
//   lit(x)     1 where the bilinear c at x is ≥ 0, else 0; s the fraction of a texel that is lit
//              (8×8 points of that bilinear c in the texel).
//   texture    rgb = E_map + D·(1 − s), a = c: the texel with the direct light D its shadowed part
//              lacks added back. The shader (object.glsl receiverChange@) takes the ground's change
//              as rgb − D·(2 − lit): in the light rgb − D (the old change where s = 1), in the
//              shadow rgb − 2D = E_map − D (s = 0). Only texels the edge crosses change.
//
// Directional lights and volumes with sharp interfaces only; otherwise c = +1 everywhere and the
// texture is the map as it was (a point light's shadow keeps its texel-wide edge).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/receiver_map.h"
#include "core/volume.h"
#include "viewer/ground_map.h"

namespace eik {

// c at every texel centre of `map` (volume space, u fastest), world units, for the light
// travelling along `direction` (volume space). Texels whose ray misses the grid's box, or runs
// farther than the interface band from every surface, get the band (or more). Empty when the
// volume has no `interfaces` field.
std::vector<float> shadowClearance(const Volume& volume, const ReceiverMap& map, const glm::dvec3& direction);

// The ground's receiver texture of `layer` (its map, the light it was baked with) as RGBA per
// texel, given its clearance (empty: none, a = 1 and rgb the map), less the direct light of the
// layer's other lights at each texel centre (so that the shader takes off only the first light's).
std::vector<float> receiverTexels(const ReceiverLayer& layer, const std::vector<float>& clearance);
// The same as half floats (core/half_float.h), what the viewer uploads (RGBA16F): half the memory
// of a texture sampled once a ground hit, within 2⁻¹¹ of each value (the shadow's edge, where the
// bilinear c crosses 0, moves by far less than a texel: c's relative precision is the same near 0).
// Where greyReceiverTexels, R and A alone (RG16F), R = G = B: a quarter of RGBA32F's memory.
std::vector<std::uint16_t> receiverTexelsHalf(const ReceiverLayer& layer, const std::vector<float>& clearance);
// Whether every texel's R, G and B are equal: a grey map (ReceiverMap::makeGrey) baked with grey
// lights only (the light added back under the shadow and the other lights taken off are grey too).
bool greyReceiverTexels(const ReceiverLayer& layer);

}  // namespace eik
