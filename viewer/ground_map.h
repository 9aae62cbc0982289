// The scene's ground map: what every object's receiver map (core/receiver_map.h) changes on the
// ground — its map there less the direct light it was baked with (its shadow, its caustic) — summed
// on one lattice in the ground's plane, so that the ground is shaded with one lookup however many
// objects stand on it (shaders/viewer/raymarch.frag groundRadiance, GROUND_MAP). SceneRenderer
// makes it for a scene where two or more objects have a receiver map; with one, that map is read
// directly. The sum is the one the shader made object by object (receiverChange in
// shaders/viewer/object.glsl): the same bilinear lookup of each map and the same direct light,
// evaluated at the lattice's texel centres.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "core/receiver_map.h"

namespace eik {

// One object's receiver map, with its irradiance, in the object's volume space.
struct ReceiverLayer {
  const ReceiverMap* map = nullptr;
  glm::dmat4 to_volume{1.0};  // world → the object's volume space
  glm::dmat4 to_world{1.0};
  // The light the map was baked with, in volume space: w = 0 a directional light's direction of
  // travel and its irradiance; w = 1 a point light's position and its intensity.
  glm::dvec4 light_pos{0.0, -1.0, 0.0, 0.0};
  glm::dvec3 light_power{0.0};
  // A spot light's cone (core/scene.h spotAttenuation): its axis and cos θ_outer, and
  // 1/(cos θ_inner − cos θ_outer); 0: not a spot.
  glm::dvec4 light_spot{0.0};
  double light_spot_scale = 0.0;
  // The receiver texture the viewer made of the map (shadow_edge.h receiverTexels: rgb the map with
  // the direct light its geometric shadow takes added back and the other lights' direct light taken
  // off, a the shadow clearance), or null: the map itself.
  const std::vector<float>* texels = nullptr;
  // The other lights the map was baked with (a scene's lights summed: the manifest's "lights" after
  // the first), in volume space, as light_pos … light_spot_scale are: their direct light is taken
  // off the map too.
  struct Light {
    glm::dvec4 pos{0.0, -1.0, 0.0, 0.0};
    glm::dvec3 power{0.0};
    glm::dvec4 spot{0.0};
    double spot_scale = 0.0;
  };
  std::vector<Light> other_lights;
};

struct GroundMap {
  glm::dvec3 point{0.0}, u{1.0, 0.0, 0.0}, v{0.0, 0.0, 1.0};  // world: the ground's point and in-plane axes
  glm::dvec2 origin{0.0};  // (u, v) of the lattice's corner relative to `point`
  double pitch = 0.0;      // texel edge, world units
  glm::ivec2 texels{0};
  std::vector<float> rgba;  // per texel, u fastest: Σ changes (rgb, W/m²), a = 1 where a map reaches, else 0

  glm::dvec2 size() const { return glm::dvec2(texels) * pitch; }
};

// Planar irradiance at x (volume space) on a surface of normal N from the light of `layer`,
// unoccluded: E·cos θ, or I·cos θ/r² (raymarch.frag lightIrradiance).
glm::dvec3 bakedDirectIrradiance(const ReceiverLayer& layer, const glm::dvec3& x, const glm::dvec3& normal);
// The same from one of its other lights.
glm::dvec3 directIrradiance(const ReceiverLayer::Light& light, const glm::dvec3& x, const glm::dvec3& normal);
// The other lights' together.
glm::dvec3 otherLightsIrradiance(const ReceiverLayer& layer, const glm::dvec3& x, const glm::dvec3& normal);

// The change `layer` makes at world point xw of its plane (object.glsl receiverChange): its map
// filtered bilinearly (texel centres, clamped at the edges, as the texture is) less the direct
// light (of every light it was baked with); with `texels`, that texture filtered so (the other
// lights already off), less the direct light twice where the filtered clearance is negative
// (shadow_edge.h). False where the map does not reach.
bool receiverChangeAt(const ReceiverLayer& layer, const glm::dvec3& xw, glm::dvec3& change);

// The ground map of `layers` on the plane through `point` with unit in-plane axes u, v: it covers
// the union of their maps' footprints; its pitch is the finest of theirs in world units (coarser
// only to stay within max_texels), and its lattice is that finest map's own where their axes agree,
// so that map is reproduced exactly. No layers: an empty map (no texels).
constexpr std::size_t kMaxGroundMapTexels = std::size_t(1) << 22;  // 64 MiB of RGBA32F
GroundMap combineReceiverMaps(const std::vector<ReceiverLayer>& layers, const glm::dvec3& point, const glm::dvec3& u,
                              const glm::dvec3& v, std::size_t max_texels = kMaxGroundMapTexels);

}  // namespace eik
