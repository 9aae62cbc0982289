// A wavefront corner meeting a sharp interface (ALGORITHM.md "Sharp interfaces"; core/interfaces.h):
// the discrete refraction of Ropinski et al. (2009) joined with the thesis' ray equation.
//
// In its material a corner follows the ray equation (Eq. 4.12/4.13: straight in a homogeneous
// material, curved in a graded one). When the step would take it into another material, it stops
// where it meets the interface: on the chord of the step, the first zero of the distance of a slot
// whose sign changed, located by interpolation and refined by regula falsi. There, with the normal
// ∇d of that slot and n on both sides (n₁ of the material it leaves, n₂ of the one it enters):
//  - into an opaque material: it stops (blocked);
//  - past the critical angle (n₁ sin θ₁ ≥ n₂): total internal reflection, it stays;
//  - else it refracts by Snell's law, w = n₂·t̂, and the exact unpolarised Fresnel R of that
//    crossing is recorded (the patch keeps (1 − R) of its flux, docs/physics.md).
// It then goes on for the rest of the step's time (a corner may cross several interfaces per step).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "lightsim/simulator.h"
#include "lightsim/wavefront.h"

namespace eik {

// What one corner met in one step.
struct CornerCrossings {
  int transmitted = 0;          // crossings by refraction
  int reflected = 0;            // total internal reflections
  bool blocked = false;         // stopped at an opaque surface
  double transmittance = 1.0;   // Π (1 − R) over its refractions
  int last_slot = -1;           // the slot whose surface it crossed last (−1: none)
  // ∫σa ds along its path, each piece with its material's σa (VolumeSampler::
  // absorptionPerMaterial(); 0 otherwise): the chord's length in each material it passed.
  glm::dvec3 optical_depth{0.0};
};

// The crossing of one interface along the chord a → b (a in material `from`): the fraction f of
// the chord, the slot k whose surface it is, and the material entered. False when the chord stays
// in `from`.
struct InterfaceHit {
  double fraction = 1.0;
  int slot = -1;
  int entered = -1;
};
bool findInterface(const VolumeSampler& sampler, const glm::dvec3& a, const glm::dvec3& b, int from, InterfaceHit& hit);

// findInterface asks the chord's end for its material first, so a chord that passes through a
// wall thinner than itself and ends in its own material meets nothing. A step's chord is therefore
// looked at in pieces of at most kChordPieceVoxels voxels (a straight step's default length: the
// ordinary steps stay one piece; a reflected wavefront's steps, kReflectedStepFactor times as
// long, and longer --straight-step ones are cut up), each asked in turn, nearest first.
constexpr double kChordPieceVoxels = 2.0;
// The pieces a chord of `length` is looked at in, h the voxel edge: ⌈length / (kChordPieceVoxels·h)⌉,
// with a little slack so that a chord of exactly that length (the ordinary straight step in
// air, up to rounding) stays one piece.
inline int chordPieces(double length, double h) {
  const double pieces = std::ceil(length / (kChordPieceVoxels * h) - 1e-6);
  return pieces > 1.0 ? static_cast<int>(std::min(pieces, 1024.0)) : 1;
}
// findInterface on a chord in chordPieces equal pieces; hit.fraction is of the whole chord.
bool findInterfaceOnChord(const VolumeSampler& sampler, const glm::dvec3& a, const glm::dvec3& b, int from,
                          InterfaceHit& hit);

// Snell's law and Fresnel at a surface with unit normal `normal` (either orientation) for a ray
// going along unit `d` from index n1 into n2: the new unit direction, and R (1: total internal
// reflection, the direction then being the mirror one).
struct Refraction {
  glm::dvec3 direction{0.0};
  double reflectance = 0.0;
  bool total = false;
};
Refraction refract(const glm::dvec3& d, const glm::dvec3& normal, double n1, double n2);

// The mirror direction of unit `d` at a surface with unit normal `normal`.
inline glm::dvec3 mirror(const glm::dvec3& d, const glm::dvec3& normal) {
  return d - 2.0 * glm::dot(d, normal) * normal;
}

// Advances corner (x, w) in material `medium` by the time step dt with `integrator`, crossing
// interfaces as above (at most kMaxCrossingsPerStep). `sample` is n and ∇n at x on entry and is
// left at the new x.
constexpr int kMaxCrossingsPerStep = 4;
CornerCrossings advanceCornerSharp(glm::dvec3& x, glm::dvec3& w, int& medium, glm::dvec4& sample, double dt,
                                   Integrator integrator, const VolumeSampler& sampler);

// The wavefront Fresnel reflection sends back at an interface every corner of `transmitted` has
// crossed (ALGORITHM.md "Bounces"): each corner is traced back along its ray to the interface it
// crossed last (within `reach` world units, searched in pieces of two voxels, nearest first), the
// incident direction recovered by Snell's law in
// reverse, mirrored, and the corner moved as far along the mirror ray, in the time it has spent
// since the crossing, as the transmitted one went ahead. Flux, depth and A₀ are the caller's. False
// when a corner finds no interface behind it (then no reflection is followed).
bool reflectedPatch(const Patch& transmitted, const VolumeSampler& sampler, double reach, Patch& reflected);

}  // namespace eik
