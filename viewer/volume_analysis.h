// What the viewer learns from a volume before it marches rays through it (no GL): the box where
// something happens (empty-space skipping), the homogeneous bricks a ray may cross in one step,
// whether the material touches the box (sharp faces) and the box where σa > 0. SceneRenderer
// hands the results to shaders/viewer/object.glsl as uniforms, a texture and the SHARP_FACES
// define. All boxes are in the volume's own coordinates.
#pragma once

#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/interfaces.h"
#include "core/volume.h"

namespace eik {

// The box (in the volume's own coordinates) of the voxels where something happens: n ≠ 1, ∇n ≠ 0,
// absorption, emission, scattering or an opaque embedding; one voxel of margin for the trilinear
// filter. Outside it a ray goes straight and gathers nothing (empty-space skipping). Returns false
// when the volume is empty throughout.
bool activeRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi);

// Bricks of kBrickVoxels³ voxels where the medium is homogeneous: n constant and ∇n ≈ 0, σa
// constant, no emission, scattering or opaque embedding, over the brick and kBrickMargin voxels
// around it (the trilinear filter and the last step's reach). A ray crossing such a brick goes
// straight, with T·exp(−σa·L): it crosses it in one step (thesis §6.3 leaves the step size free;
// the thesis asks for skipping the interior of homogeneous glass). 1 = homogeneous, 0 = march.
// Bricks x fastest, brick_dims = ⌈dims / kBrickVoxels⌉. Needs the ior and ior_grad fields.
constexpr int kBrickVoxels = 4;
constexpr int kBrickMargin = 2;
std::vector<float> homogeneousBricks(const Volume& volume, glm::ivec3& brick_dims);

// Whether the material touches the box: n ≠ 1 in a voxel of one of its faces. Such faces are sharp
// interfaces (object.glsl, SHARP_FACES), as smoothing never saw the air beyond them. Needs ior.
bool materialTouchesBox(const Volume& volume);

// The box (volume coordinates) of the voxels with σa > 0, one voxel of margin; false when none.
// Rays fetch σa only inside it (a second texture fetch a step is what absorption costs).
bool absorbingRegion(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi);

// The medium of each material of a volume with sharp interfaces (air, then each slot of `table`),
// where it is one constant throughout the material: σa, and the scattering albedo ω̂ and g. A ray
// between sharp surfaces then knows them from the material it is in (object.glsl, MEDIUM_SIGMA_A
// and MEDIUM_SCATTER), fetching nothing, and the material's σa and ω̂ end exactly at its surface
// instead of blending over the voxel beside it. "Throughout" is read from the voxels at least
// kMediumDepthVoxels from every slot surface, where compositing blends nothing in
// (voxelize/composite.h mixes regions by coverage only within a voxel of their surfaces); a
// material with no such voxel (a wall thinner than two voxels), or whose voxels there disagree (two
// objects of one n and different σa share a slot; smoke in the air), makes the field vary.
// Opaque slots stop rays and are not looked at.
constexpr double kMediumDepthVoxels = kDeepVoxels;
struct MaterialMedium {
  glm::dvec3 sigma_a{0.0};
  glm::dvec2 scatter{0.0};  // albedo ω̂, Henyey–Greenstein g
};
struct SlotMedia {
  bool sigma_a_constant = false;      // σa is one constant in every material
  bool scatter_constant = false;      // ω̂ and g likewise
  std::vector<MaterialMedium> media;  // [0] air (outside air_box where there is one), [1 + k] slot k
  std::optional<AirMedium> air_box;   // with both constants: the air's are these inside the box
};
// Both false for a volume without sharp interfaces. A field the volume lacks is constant (0).
// Where the air alone varies, as a box of smoke (core/interfaces.h airMediumBox), both are true
// with air_box set: the march takes the air's medium over the share of each step inside the box
// (object.glsl, AIR_BOX).
SlotMedia slotMedia(const Volume& volume, const InterfaceTable& table);

}  // namespace eik
