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
#pragma once

#include <glm/glm.hpp>

#include "core/scene.h"
#include "core/volume.h"
#include "lightsim/simulator.h"

namespace eik {

struct BakeFrame {
  glm::dmat3 rotation{1.0};  // the bake frame's axes in the world (R)
  glm::dvec3 origin{0.0};    // the bake frame's origin in the world (T)
  double scale = 1.0;        // the object's uniform scale s

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

// A bake made in the bake frame, back in the volume's own coordinates: each receiver map's point,
// origin and pitch ÷ s (its irradiance, W/m², stays), and a point light's position ÷ s.
void bakeToVolumeFrame(BakeResult& result, LightSpec& light, double scale);

}  // namespace eik
