// A scene's objects baked under their placements (`lightsim SCENE.json -o OUT_DIR`, docs/programs.md
// "A whole scene"): each object's bake runs in its volume's own axes at world scale, with the
// scene's light and ground carried into them, so that a turned, moved or scaled object is lit as it
// stands in the scene and its ground map lies under it.
//
// The bake frame of an object placed by world = T · R · s (docs/scene-format.md "Placement of an
// object") is p_bake = s · p_volume, world = T · R · p_bake. Lengths there are world lengths, so
// what is per world unit (σa, the receiver's half extent, irradiance in W/m², the bake's step in
// voxels of the scaled grid) needs no conversion; the volume's own lengths scale: the grid's box
// and the interfaces' signed distances (and band) by s, ∇n by 1/s. Refraction is unchanged by a
// uniform scale, so the same rays bend the same way, only s times as long.
//
// An object scaled by different factors along its axes is first taken in as a volume of its own
// (takeInAxisScale): the volume at world scale along each axis, on voxels as long as the scale
// makes them, placed by T · R alone. Programs do that where they read a scene's object, so that
// everything after it (the bake frame, the chain from box to box, the viewer's march) sees an
// object of uniform scale 1.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene.h"
#include "core/volume.h"
#include "lightsim/simulator.h"
#include "lightsim/wavefront.h"

namespace eik {

struct BakeFrame {
  glm::dmat3 rotation{1.0};  // the bake frame's axes in the world (R)
  glm::dvec3 origin{0.0};    // the bake frame's origin in the world (T)
  double scale = 1.0;        // the object's uniform scale s

  // std::invalid_argument for an object scaled differently along its axes (takeInAxisScale first).
  static BakeFrame of(const SceneObjectSpec& object);
  // From a placement matrix translate · rotation · uniform scale (objectToWorld's).
  static BakeFrame of(const glm::dmat4& object_to_world);
  // A light or a receiver plane given in the world, in the bake frame.
  LightSpec light(const LightSpec& world) const;
  ReceiverSpec receiver(const ReceiverSpec& world) const;
};

// The volume as its bake frame sees it (above): the grid's box × s, `interfaces` and the table's
// band × s, `ior_grad` ÷ s; every other field as it is. `scale` 1 copies the volume unchanged.
Volume volumeAtWorldScale(const Volume& volume, double scale);

// The volume scaled by S = diag(sx, sy, sz) about its origin, p' = S·p: the grid's box × S (its
// voxels S times as long per axis), ∇n ÷ S per component (n(S⁻¹p') differentiated), `light_dir`
// along S·d (renormalised), the interfaces' signed distances and band × min(s): a distance field
// stretched unevenly is no distance any more, but its zero set (the surface) and its gradient's
// direction (the normal, S⁻¹·∇d) are exact, which is all that crossings read, and × min(s) keeps
// every value a lower bound of the true distance (the band's "at least this far" stays true).
// Receiver maps baked with the volume follow when the scale is the same along their plane (their
// lattice stays square); `dropped` receives the names of those that cannot. For equal factors this
// is volumeAtWorldScale. Fields other programs wrote stay as they are.
Volume volumeAtWorldScale(const Volume& volume, const glm::dvec3& scale, std::vector<std::string>* dropped = nullptr);

// An object of a scene scaled differently along its axes, taken in as the volume at world scale
// along each axis (above) placed with scale 1; false, and nothing changed, for a uniform scale.
// `warn` is told of each receiver map left out (a baked ground that cannot follow the scale).
bool takeInAxisScale(Volume& volume, SceneObjectSpec& object,
                     const std::function<void(const std::string& map)>& warn = {});

// A bake made in the bake frame, back in the volume's own coordinates: each receiver map's point,
// origin and pitch ÷ s (its irradiance, W/m², stays), and a point light's position ÷ s.
void bakeToVolumeFrame(BakeResult& result, LightSpec& light, double scale);

// Light from object to object (docs/programs.md "A whole scene", lightsim/ALGORITHM.md "From box
// to box"). The objects are baked one after another in the order the light meets them: a sun's,
// by the nearest corner of each box along the light; a point light's, by the distance to each box.
// Each object's bake
//  - leaves out the light's cells whose ray met an earlier object's box before its own (the light
//    that earlier object took), and
//  - takes in, as initial patches, the patches that left earlier objects' boxes towards its box
//    (nearer along their rays than the ground and any other later box), flown in a straight line
//    (air) to half a voxel before its box;
// so a shadow falls on what stands behind an object, and a caustic an object throws goes on
// through the next. Each object's receiver map is then made to hold the direct light D plus its
// own change to the ground, given the light it got:
//   map = D + G(its light through it) − G(its light going straight),
// correctMap below; the sum D + Σ (map_k − D) that the viewer draws on the ground is then the
// light that went through all the objects in turn (exact for light that crosses each box once in
// the chain's order). Light sent back towards an earlier object, and objects whose boxes overlap
// (whose light is baked as if the other were not there), are not followed: the chain runs once.
class SceneLightChain {
 public:
  struct Object {
    BakeFrame frame;
    glm::dvec3 lo{0.0}, hi{0.0};  // its propagation box (wavefront.h propagationBox) in its bake frame
    double h = 0.0;               // its voxel edge at world scale
  };
  // `world_light` and `ground` (nullopt: none) in the world; the order is the one `order_light`
  // (default: world_light) meets the boxes in (a soft sun's directions share the sun's order).
  SceneLightChain(std::vector<Object> objects, const LightSpec& world_light, std::optional<ReceiverSpec> ground,
                  std::optional<LightSpec> order_light = std::nullopt);

  // The objects in the order they are baked (indices into the constructor's list).
  const std::vector<std::size_t>& order() const { return order_; }
  // Do the two objects' boxes overlap (then neither shades or lights the other)?
  bool overlap(std::size_t a, std::size_t b) const;

  // The hooks of object k's bake (SimulationOptions::initial_patches, on_leave), k being the next
  // object of order(): what earlier objects shade and send, and (when objects follow) what it sends
  // on. Objects must be baked in order().
  void attach(std::size_t k, SimulationOptions& options);
  // After object k's bake (in its bake frame): its receiver map made D + its own change, by the
  // straight light of the cells it left out (added) and of the patches it took in (taken away).
  void correctMap(std::size_t k, BakeResult& result);
  // What object k took in (its initial patches from earlier objects) and left out, in number and
  // flux (W, RGB), for the report.
  struct Exchange {
    std::size_t taken_in = 0, left_out = 0, passed = 0;  // passed: sent here, too dim to take in
    glm::dvec3 flux_in{0.0}, flux_left_out{0.0}, flux_passed{0.0};
    Exchange& operator+=(const Exchange& o);  // over spectral bands
  };
  // A patch sent on whose irradiance is under this fraction of the light's brightest on the box
  // (wavefront.h brightestIrradiance) passes the box unchanged: where a wavefront that dim lights
  // an object, what the object does to it changes the ground by under 1 % of the light's
  // irradiance. Measured on the museum: at 10⁻³ the light the sphere and the logo block send
  // sideways reached the next objects as 6 700 patches (0.06 W in all, against some 10 W of sun
  // on them), which split and cost 1.5 M more patch-steps (+25 %); at 10⁻² 1 300 patches (0.05 W)
  // are taken in and the scene costs 6 % more patch-steps than the four objects baked alone.
  static constexpr double kDimHandOn = 1e-2;
  const Exchange& exchange(std::size_t k) const { return exchange_[k]; }

 private:
  // The entry and exit parameters of the line origin + t·dir through object k's box, in the world;
  // false when it misses.
  bool lineThroughBox(std::size_t k, const glm::dvec3& origin, const glm::dvec3& dir, double& t_near,
                      double& t_far) const;
  std::vector<Object> objects_;
  LightSpec light_;  // in the world
  std::optional<ReceiverSpec> ground_;
  std::vector<std::size_t> order_;
  std::vector<std::size_t> rank_;              // rank_[k]: k's place in order_
  std::vector<std::vector<Patch>> inbox_;      // patches sent to each object, in the world
  std::vector<std::vector<Patch>> left_out_;   // each object's left-out cells, in its bake frame
  std::vector<std::vector<Patch>> taken_in_;   // …and the patches it took in, as flown into its box
  std::vector<Exchange> exchange_;
};

}  // namespace eik
